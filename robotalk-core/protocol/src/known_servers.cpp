// The known-servers pin file (known_servers.h; docs/security.md).
#include "robotalk/known_servers.h"

#include "file_trust.h"
#include "robotalk/channels.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <sstream>

namespace robotalk {
namespace {

constexpr off_t kMaxFileBytes = 1 << 20;  // a million bytes of pins is not a pin file

std::string Where(const std::filesystem::path& file) { return "known-servers file " + file.string(); }

// The file descriptor's file must be a regular file of this user that group
// and others cannot write, in directories nobody else may change: whoever
// writes it chooses the server the client obeys (file_trust.h, kPinned).
void CheckOwnership(int fd, const std::filesystem::path& file) {
  struct stat st {};
  if (::fstat(fd, &st) != 0) throw KeyError(Where(file) + ": cannot stat: " + std::strerror(errno));
  if (!S_ISREG(st.st_mode)) throw KeyError(Where(file) + ": not a regular file");
  if (std::string problem = FileTrustProblem(file, st, TrustedFile::kPinned); !problem.empty()) {
    throw KeyError(Where(file) + ": " + problem);
  }
}

int OpenChecked(const std::filesystem::path& file, int flags, mode_t mode) {
  const int fd = ::open(file.c_str(), flags | O_NOFOLLOW | O_CLOEXEC, mode);
  if (fd < 0 && errno == ELOOP) throw KeyError(Where(file) + ": is a symlink; give the real file");
  return fd;
}

}  // namespace

KnownServers KnownServers::Read(const std::filesystem::path& file) {
  KnownServers out;
  out.file_ = file;
  const int fd = OpenChecked(file, O_RDONLY, 0);
  if (fd < 0) {
    if (errno == ENOENT) return out;
    throw KeyError(Where(file) + ": cannot open: " + std::strerror(errno));
  }
  std::string text;
  try {
    CheckOwnership(fd, file);
    char buf[4096];
    for (ssize_t n; (n = ::read(fd, buf, sizeof buf)) != 0;) {
      if (n < 0 && errno == EINTR) continue;
      if (n < 0) throw KeyError(Where(file) + ": cannot read: " + std::strerror(errno));
      text.append(buf, static_cast<std::size_t>(n));
      if (text.size() > static_cast<std::size_t>(kMaxFileBytes))
        throw KeyError(Where(file) + ": larger than 1 MB");
    }
  } catch (...) {
    ::close(fd);
    throw;
  }
  ::close(fd);
  std::istringstream in(text);
  std::string line;
  for (int number = 1; std::getline(in, line); ++number) {
    const std::string at = file.string() + ":" + std::to_string(number) + ": ";
    std::istringstream words(line);
    ServerPin pin;
    std::string key, extra;
    if (!(words >> pin.robot) || pin.robot.starts_with('#')) continue;
    if (!(words >> pin.network >> key) || (words >> extra)) {
      throw KeyError(at + "expected '<robot> <network> ed25519:<64 hex>', got '" + line + "'");
    }
    if (const std::string why = RobotNameProblem(pin.robot); !why.empty()) {
      throw KeyError(at + "'" + pin.robot + "': " + why);
    }
    try {
      pin.key = PublicKey::Parse(key);
    } catch (const KeyError& e) {
      throw KeyError(at + e.what());
    }
    pin.line = number;
    if (const ServerPin* seen = out.Find(pin.robot, pin.network); seen != nullptr) {
      if (seen->key == pin.key) continue;
      throw KeyError(at + "robot '" + pin.robot + "' on " + pin.network + " is pinned to " +
                     pin.key.Fingerprint() + " here and to " + seen->key.Fingerprint() + " on line " +
                     std::to_string(seen->line) + "; delete the wrong line");
    }
    out.pins_.push_back(std::move(pin));
  }
  return out;
}

const ServerPin* KnownServers::Find(std::string_view robot, std::string_view network) const {
  for (const ServerPin& p : pins_) {
    if (p.robot == robot && p.network == network) return &p;
  }
  return nullptr;
}

void KnownServers::Append(const std::filesystem::path& file, const ServerPin& pin) {
  const std::filesystem::path dir = file.parent_path();
  if (!dir.empty() && ::mkdir(dir.c_str(), 0700) != 0 && errno != EEXIST) {
    throw KeyError(Where(file) + ": cannot create its directory: " + std::strerror(errno));
  }
  const int fd = OpenChecked(file, O_WRONLY | O_APPEND | O_CREAT, 0600);
  if (fd < 0) throw KeyError(Where(file) + ": cannot open for writing: " + std::strerror(errno));
  try {
    CheckOwnership(fd, file);
    const std::string line = pin.robot + " " + pin.network + " " + pin.key.ToString() + "\n";
    if (::write(fd, line.data(), line.size()) != static_cast<ssize_t>(line.size())) {
      throw KeyError(Where(file) + ": cannot write: " + std::strerror(errno));
    }
  } catch (...) {
    ::close(fd);
    throw;
  }
  ::close(fd);
}

std::string PinNetwork(std::string_view lcm_url) { return std::string(lcm_url.substr(0, lcm_url.find('?'))); }

std::filesystem::path DefaultKnownServersFile() {
  if (const char* env = std::getenv("ROBOTALK_KNOWN_SERVERS"); env != nullptr && *env != '\0') return env;
  if (const char* home = std::getenv("HOME"); home != nullptr && *home != '\0') {
    return std::filesystem::path(home) / ".robotalk" / "known_servers";
  }
  return {};
}

}  // namespace robotalk
