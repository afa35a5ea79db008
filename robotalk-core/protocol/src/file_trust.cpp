// Trust checks of key and access-list files (file_trust.h): the rules of
// OpenSSH's StrictModes, applied to RoboTalk's files.
#include "file_trust.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>

namespace robotalk {
namespace {

std::string Mode(mode_t mode) {
  char buf[8];
  std::snprintf(buf, sizeof buf, "%04o", static_cast<unsigned>(mode & 07777));
  return buf;
}

bool OwnerTrusted(uid_t owner) { return owner == 0 || owner == ::geteuid(); }

std::string OwnerProblem(uid_t owner, bool root_allowed) {
  return "owned by uid " + std::to_string(owner) + ", not by " + (root_allowed ? "root or " : "") +
         "this process's user (uid " + std::to_string(::geteuid()) + "); another user could change it";
}

}  // namespace

int OpenTrustedFile(const std::filesystem::path& file, struct stat& st, std::string& problem) {
  struct stat link {};
  if (::lstat(file.c_str(), &link) == 0 && S_ISLNK(link.st_mode)) {
    problem = "is a symbolic link; give the file itself (whoever controls the link chooses the file)";
    return -1;
  }
  const int fd = ::open(file.c_str(), O_RDONLY | O_CLOEXEC | O_NOFOLLOW);
  if (fd < 0) {
    problem = std::string("cannot open: ") + std::strerror(errno);
    return -1;
  }
  if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
    problem = "not a readable regular file";
    ::close(fd);
    return -1;
  }
  return fd;
}

std::string FileTrustProblem(const std::filesystem::path& file, const struct stat& st, TrustedFile kind) {
  const bool secret = kind == TrustedFile::kSecret;
  const bool callers_own = kind != TrustedFile::kShared;
  if (callers_own ? st.st_uid != ::geteuid() : !OwnerTrusted(st.st_uid))
    return OwnerProblem(st.st_uid, !callers_own);
  if (secret && (st.st_mode & 077) != 0) {
    return "mode " + Mode(st.st_mode) +
           ": the secret key must not be readable or writable by group or others; run chmod 600 " +
           file.string();
  }
  if (kind == TrustedFile::kPinned && (st.st_mode & 022) != 0) {
    return "mode " + Mode(st.st_mode) +
           " lets group or others write it, and so choose which server this client trusts; run chmod 600 " +
           file.string();
  }
  if (kind == TrustedFile::kShared && (st.st_mode & 022) != 0) {
    return "mode " + Mode(st.st_mode) +
           ": group or others may write it (and so grant themselves rights or change the key); run chmod "
           "go-w " +
           file.string();
  }
  std::error_code ec;
  std::filesystem::path dir = std::filesystem::absolute(file, ec).parent_path();
  for (;;) {
    struct stat d {};
    if (::stat(dir.c_str(), &d) != 0)
      return "directory " + dir.string() + ": cannot stat: " + std::strerror(errno);
    if (!OwnerTrusted(d.st_uid)) return "directory " + dir.string() + " is " + OwnerProblem(d.st_uid, true);
    if ((d.st_mode & S_IWOTH) != 0 && (d.st_mode & S_ISVTX) == 0) {
      return "directory " + dir.string() + " (mode " + Mode(d.st_mode) +
             ") is world-writable without the sticky bit: anyone may replace the file";
    }
    if (dir == dir.root_path() || dir.parent_path() == dir) break;
    dir = dir.parent_path();
  }
  return {};
}

}  // namespace robotalk
