// The panic latch on disk: which robots of this server are in panic, and
// why, so a panic survives a server restart (issue: a restarted server had
// forgotten a latched PANIC). One small text file per server, a line
// "robot<TAB>reason" per robot in panic, replaced atomically (write to a
// temporary file, fsync, rename) before the panic is acknowledged.
//
// Thread safety: none; the ServerDaemon (and the Server at start-up) use it.
#pragma once

#include <map>
#include <string>

namespace robotalk {

class PanicLatch {
 public:
  /// `path` = "" keeps nothing on disk (every call is a no-op).
  explicit PanicLatch(std::string path);

  /// Reads the file: robot -> reason. A missing file is an empty latch.
  /// Throws Error naming the file and line when it cannot be read or parsed.
  std::map<std::string, std::string> Load();
  /// Records / removes a robot's panic and rewrites the file. Throws Error
  /// naming the file when it cannot be written.
  void Set(const std::string& robot, const std::string& reason);
  void Clear(const std::string& robot);

  bool enabled() const { return !path_.empty(); }
  bool latched(const std::string& robot) const { return latched_.count(robot) > 0; }
  const std::string& path() const { return path_; }

 private:
  void Write() const;

  std::string path_;
  std::map<std::string, std::string> latched_;
};

}  // namespace robotalk
