#include "panic_latch.h"

#include "robotalk/error.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <fstream>

namespace robotalk {

PanicLatch::PanicLatch(std::string path) : path_(std::move(path)) {}

std::map<std::string, std::string> PanicLatch::Load() {
  latched_.clear();
  if (path_.empty()) return latched_;
  std::ifstream in(path_);
  if (!in) {
    if (errno == ENOENT) return latched_;
    throw Error("panic latch '" + path_ + "': cannot read it: " + std::strerror(errno));
  }
  std::string line;
  for (int n = 1; std::getline(in, line); ++n) {
    if (line.empty() || line[0] == '#') continue;
    const auto tab = line.find('\t');
    if (tab == std::string::npos || tab == 0) {
      throw Error("panic latch '" + path_ + "' line " + std::to_string(n) + ": expected robot<TAB>reason");
    }
    latched_[line.substr(0, tab)] = line.substr(tab + 1);
  }
  return latched_;
}

void PanicLatch::Set(const std::string& robot, const std::string& reason) {
  if (path_.empty()) return;
  std::string one_line = reason;
  for (char& c : one_line) {
    if (c == '\n' || c == '\t') c = ' ';
  }
  latched_[robot] = one_line.empty() ? "panic" : one_line;
  Write();
}

void PanicLatch::Clear(const std::string& robot) {
  if (path_.empty() || !latched_.erase(robot)) return;
  Write();
}

void PanicLatch::Write() const {
  const std::string tmp = path_ + ".tmp";
  std::string text =
      "# robotalk-server panic latch: robot<TAB>reason; delete a line only with the robot safe\n";
  for (const auto& [robot, reason] : latched_) text += robot + "\t" + reason + "\n";
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) throw Error("panic latch '" + tmp + "': cannot write it: " + std::strerror(errno));
  const bool ok =
      ::write(fd, text.data(), text.size()) == static_cast<ssize_t>(text.size()) && ::fsync(fd) == 0;
  const int saved = errno;
  ::close(fd);
  if (!ok || ::rename(tmp.c_str(), path_.c_str()) != 0) {
    throw Error("panic latch '" + path_ + "': cannot write it: " + std::strerror(ok ? errno : saved));
  }
}

}  // namespace robotalk
