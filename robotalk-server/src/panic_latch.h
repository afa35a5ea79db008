// The panic latch on disk: which robots are in panic, and why, so a panic
// survives a server restart (issue 19: it is on by default; a restarted
// server had forgotten a latched PANIC). A small text file, a line
// "robot<TAB>reason" per robot in panic, replaced atomically (write to a
// temporary file, fsync, rename) before the panic is acknowledged.
//
// Scope. robotalk-server keeps one file per LCM network in its state
// directory (LatchFileFor: "<state dir>/panic-latch.udpm-239.255.76.67-7667"),
// so servers on different networks, or tests with their own state
// directories, never latch each other. Several servers may share one file
// (different robots on one network): every change re-reads the file under an
// exclusive flock() of "<file>.lock" and rewrites it with only that robot's
// line changed.
//
// Thread safety: none; the ServerDaemon (and the Server at start-up) use it.
#pragma once

#include <map>
#include <string>

namespace robotalk {

class PanicLatch {
 public:
  /// `path` = "" keeps nothing on disk (every call is a no-op). Otherwise
  /// opens (creating) "<path>.lock" at once, so an unwritable place is found
  /// at start-up: throws Error naming the file and the system's reason.
  explicit PanicLatch(std::string path);
  ~PanicLatch();
  PanicLatch(const PanicLatch&) = delete;
  PanicLatch& operator=(const PanicLatch&) = delete;

  /// Reads the file: robot -> reason. A missing file is an empty latch.
  /// Throws Error naming the file and line when it cannot be read or parsed.
  std::map<std::string, std::string> Load();
  /// Records / removes a robot's panic and rewrites the file (other robots'
  /// lines as the file has them now). Throws Error naming the file when it
  /// cannot be written.
  void Set(const std::string& robot, const std::string& reason);
  void Clear(const std::string& robot);

  bool enabled() const { return !path_.empty(); }
  /// Whether this latch set `robot` (or found it latched by Load()).
  bool latched(const std::string& robot) const { return latched_.count(robot) > 0; }
  const std::string& path() const { return path_; }

  /// Where robotalk-server keeps its state by default: $ROBOTALK_STATE_DIR;
  /// else /var/lib/robotalk for root; else $XDG_STATE_HOME/robotalk; else
  /// $HOME/.local/state/robotalk. Throws Error when none can be formed (no
  /// HOME).
  static std::string DefaultStateDir();
  /// The latch file for the network `url` in `state_dir`: the URL's scheme,
  /// address and port, its options dropped (ttl, recv_buf_size, traffic do
  /// not change the network) ("udpm://239.255.76.67:7667?ttl=0" ->
  /// "<dir>/panic-latch.udpm-239.255.76.67-7667").
  static std::string LatchFileFor(const std::string& state_dir, const std::string& url);
  /// Creates `dir` and its missing parents (mode 0700). Throws Error naming
  /// the directory and the reason.
  static void MakeStateDir(const std::string& dir);

 private:
  // Re-reads the file into latched_ (holding the lock), applies `change`, writes.
  template <typename F>
  void Change(F&& change);
  std::map<std::string, std::string> Read() const;
  void Write() const;

  std::string path_;
  int lock_fd_ = -1;
  std::map<std::string, std::string> latched_;
};

}  // namespace robotalk
