// Whether a file that grants trust (a secret key, a pinned public key, the
// access list, the known-servers pin file) may be believed: who could have
// written it, or put another in its place. Private to robotalk-core
// (keys.cpp, access_list.cpp, known_servers.cpp).
#pragma once

#include <sys/stat.h>

#include <filesystem>
#include <string>

namespace robotalk {

enum class TrustedFile {
  kSecret,  ///< a secret key: owned by the caller; no group or other access at all
  kShared,  ///< an access list or a public key: owned by root or the caller; nobody else may write it
  kPinned,  ///< the known-servers pin file: owned by the caller; nobody else may write it
};

/// Opens `file` for reading, refusing a symbolic link (lstat, and O_NOFOLLOW)
/// and anything but a regular file. Returns the descriptor and fills `st`
/// (fstat of it), or returns -1 with `problem` set.
/// FileTrustProblem() then says whether its owner, mode and directories are
/// acceptable: "" or the problem, e.g. "owned by uid 1234, not by root or
/// this process's user (uid 0); run chown", "directory /srv/keys is
/// world-writable without the sticky bit: anyone may replace the file".
/// Every directory from the file's up to / is checked (owned by root or the
/// caller; not world-writable unless sticky, like /tmp).
int OpenTrustedFile(const std::filesystem::path& file, struct stat& st, std::string& problem);
std::string FileTrustProblem(const std::filesystem::path& file, const struct stat& st, TrustedFile kind);

}  // namespace robotalk
