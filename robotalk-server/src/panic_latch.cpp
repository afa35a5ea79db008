#include "panic_latch.h"

#include "robotalk/error.h"
#include "robotalk/known_servers.h"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <fstream>

namespace robotalk {
namespace {

std::string Reason() { return std::strerror(errno); }

// Holds an exclusive flock() for one read-modify-write.
class FileLock {
 public:
  FileLock(int fd, const std::string& path) : fd_(fd) {
    while (::flock(fd_, LOCK_EX) != 0) {
      if (errno != EINTR) throw Error("panic latch '" + path + "': cannot lock it: " + Reason());
    }
  }
  ~FileLock() { ::flock(fd_, LOCK_UN); }
  FileLock(const FileLock&) = delete;
  FileLock& operator=(const FileLock&) = delete;

 private:
  int fd_;
};

}  // namespace

PanicLatch::PanicLatch(std::string path) : path_(std::move(path)) {
  if (path_.empty()) return;
  const std::string lock = path_ + ".lock";
  lock_fd_ = ::open(lock.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0600);
  if (lock_fd_ < 0) {
    throw Error("panic latch '" + path_ + "': cannot create '" + lock + "': " + Reason() +
                " (choose another place with --state-dir DIR or --panic-latch FILE)");
  }
}

PanicLatch::~PanicLatch() {
  if (lock_fd_ >= 0) ::close(lock_fd_);
}

std::map<std::string, std::string> PanicLatch::Load() {
  if (path_.empty()) return {};
  FileLock lock(lock_fd_, path_);
  latched_ = Read();
  return latched_;
}

std::map<std::string, std::string> PanicLatch::Read() const {
  std::map<std::string, std::string> latched;
  std::ifstream in(path_);
  if (!in) {
    if (errno == ENOENT) return latched;
    throw Error("panic latch '" + path_ + "': cannot read it: " + Reason());
  }
  std::string line;
  for (int n = 1; std::getline(in, line); ++n) {
    if (line.empty() || line[0] == '#') continue;
    const auto tab = line.find('\t');
    if (tab == std::string::npos || tab == 0) {
      throw Error("panic latch '" + path_ + "' line " + std::to_string(n) + ": expected robot<TAB>reason");
    }
    latched[line.substr(0, tab)] = line.substr(tab + 1);
  }
  return latched;
}

template <typename F>
void PanicLatch::Change(F&& change) {
  FileLock lock(lock_fd_, path_);
  latched_ = Read();  // another server's robots as they are now
  if (change()) Write();
}

void PanicLatch::Set(const std::string& robot, const std::string& reason) {
  if (path_.empty()) return;
  std::string one_line = reason;
  for (char& c : one_line) {
    if (c == '\n' || c == '\t') c = ' ';
  }
  Change([&] {
    latched_[robot] = one_line.empty() ? "panic" : one_line;
    return true;
  });
}

void PanicLatch::Clear(const std::string& robot) {
  if (path_.empty()) return;
  Change([&] { return latched_.erase(robot) > 0; });
}

void PanicLatch::Write() const {
  const std::string tmp = path_ + ".tmp";
  std::string text =
      "# robotalk-server panic latch: robot<TAB>reason; delete a line only with the robot safe\n";
  for (const auto& [robot, reason] : latched_) text += robot + "\t" + reason + "\n";
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) throw Error("panic latch '" + tmp + "': cannot write it: " + Reason());
  const bool ok =
      ::write(fd, text.data(), text.size()) == static_cast<ssize_t>(text.size()) && ::fsync(fd) == 0;
  const int saved = errno;
  ::close(fd);
  if (!ok || ::rename(tmp.c_str(), path_.c_str()) != 0) {
    throw Error("panic latch '" + path_ + "': cannot write it: " + std::strerror(ok ? errno : saved));
  }
}

std::string PanicLatch::DefaultStateDir() {
  const auto env = [](const char* name) -> std::string {
    const char* v = std::getenv(name);
    return v != nullptr ? std::string(v) : std::string();
  };
  if (std::string dir = env("ROBOTALK_STATE_DIR"); !dir.empty()) return dir;
  if (::geteuid() == 0) return "/var/lib/robotalk";
  if (std::string xdg = env("XDG_STATE_HOME"); !xdg.empty() && xdg[0] == '/') return xdg + "/robotalk";
  if (std::string home = env("HOME"); !home.empty()) return home + "/.local/state/robotalk";
  throw Error(
      "no state directory for the panic latch: neither ROBOTALK_STATE_DIR, XDG_STATE_HOME nor HOME is set "
      "(give --state-dir DIR)");
}

std::string PanicLatch::LatchFileFor(const std::string& state_dir, const std::string& url) {
  std::string where = PinNetwork(url);  // the network, without its options
  if (const auto scheme = where.find("://"); scheme != std::string::npos) where.replace(scheme, 3, "-");
  while (!where.empty() && (where.back() == '/' || where.back() == '-')) where.pop_back();
  for (char& c : where) {
    const bool plain = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
                       c == '.' || c == '_' || c == '-';
    if (!plain) c = '-';
  }
  return state_dir + "/panic-latch." + (where.empty() ? std::string("default") : where);
}

void PanicLatch::MakeStateDir(const std::string& dir) {
  if (dir.empty()) throw Error("state directory: empty name");
  for (std::size_t slash = dir.find('/', 1);; slash = dir.find('/', slash + 1)) {
    const std::string part = dir.substr(0, slash);
    if (::mkdir(part.c_str(), 0700) != 0 && errno != EEXIST) {
      throw Error("state directory '" + dir + "': cannot create '" + part + "': " + Reason() +
                  " (give --state-dir DIR, or set ROBOTALK_STATE_DIR)");
    }
    if (slash == std::string::npos) break;
  }
  struct stat st {};
  if (::stat(dir.c_str(), &st) != 0 || !S_ISDIR(st.st_mode)) {
    throw Error("state directory '" + dir + "' is not a directory");
  }
  if (::access(dir.c_str(), W_OK | X_OK) != 0) {
    throw Error("state directory '" + dir + "' is not writable: " + Reason() +
                " (give --state-dir DIR, or set ROBOTALK_STATE_DIR)");
  }
}

}  // namespace robotalk
