// ConnectScheduler: connects to the robots announced on the bus, for the
// programs that serve every robot announced (robotalk-web's RobotTracker,
// robotalk-ros2). Anyone on the bus can announce any name (one ANNOUNCE
// datagram; a keyed server signs with its own key, and anyone can make one),
// and a connect waits for an answer up to its timeout, so the names and the
// connects are bounded:
//   - a table of at most `max_names` names. When it is full, a new name takes
//     the place of one that is neither served nor connecting and whose
//     connects failed or that fell silent (not announced for
//     `silent_after`): a silent one first, then the one that failed most,
//     then the one announced longest ago. With none such the new name is
//     refused (until one is forgotten or can be pushed out). A name served,
//     connecting, or heard and not tried yet is never pushed out, so a forger
//     re-announcing `max_names` names no server answers for cannot keep a real
//     robot out, nor push out one that is served.
//   - each connect runs on a thread of its own, at most `max_connecting` at
//     once (each RobotClient holds LCM sockets, and LCM's select() aborts the
//     process past descriptor 1,024); one that is not answered delays no
//     other.
//   - a name's first attempt waits `first_timeout` for an answer (a server on
//     the LAN answers in milliseconds); each failure doubles that up to
//     `max_timeout`, and waits `first_backoff`, doubled up to `max_backoff`,
//     before the next try (counted from the end of the failed one).
//   - names not tried yet (or served before and lost) go first, in the order
//     they came; then the retries, the longest due first.
//   - a name not announced for `silent_after` is not tried (it is not there);
//     one not announced for `silent_after` + `forget_after` that is neither
//     served nor connecting is forgotten.
//
// What "served" means is the caller's: a connect that returns is served until
// the caller says Lost() (robotalk-web: its server stopped announcing it or
// restarted; robotalk-ros2 bridges a robot until it exits).
//
// Time comes from `options.clock` (a ManualClock in tests); the connects are
// real threads, whose outcome is recorded when the connect function returns.
//
// Thread safety: every method may be called from any thread; the scheduler's
// own mutex is never held while calling the connect or failure function, so
// they may take the caller's locks, and the caller may hold its own lock
// while calling the scheduler. The destructor waits for the connects in
// flight (each up to its timeout): do not hold a lock they take while
// destroying it.
#pragma once

#include "robotalk/clock.h"

#include <cstdint>
#include <functional>
#include <list>
#include <map>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

namespace robotalk {

struct ConnectSchedulerOptions {
  std::size_t max_names = 256;
  std::size_t max_connecting = 32;
  Duration first_timeout = std::chrono::seconds(1);
  Duration max_timeout = std::chrono::seconds(4);
  Duration first_backoff = std::chrono::seconds(2);
  Duration max_backoff = std::chrono::seconds(64);
  Duration silent_after = std::chrono::seconds(3);
  Duration forget_after = std::chrono::seconds(60);
  /// nullptr = the steady clock. It must outlive the scheduler.
  const Clock* clock = nullptr;
};

class ConnectScheduler {
 public:
  /// Connects `name`, waiting at most `timeout` for an answer; on a thread of
  /// its own. Returns when served; throws (a std::exception) when it failed.
  using ConnectFn = std::function<void(const std::string& name, Duration timeout)>;
  /// Called on the connect's thread after a failed attempt: why, and how long
  /// until the next one.
  using FailedFn = std::function<void(const std::string& name, const std::string& error, Duration retry_in)>;

  explicit ConnectScheduler(ConnectFn connect, FailedFn failed = {}, ConnectSchedulerOptions options = {});
  ~ConnectScheduler();
  ConnectScheduler(const ConnectScheduler&) = delete;
  ConnectScheduler& operator=(const ConnectScheduler&) = delete;

  enum class Heard {
    kKnown,    ///< in the table already (its announce time is now)
    kAdded,    ///< new in the table (and `evicted` says whom it pushed out, if anyone)
    kRefused,  ///< the table is full and no name can give its place
  };
  /// `name` was announced now. When a name was pushed out for it, it is
  /// written to `evicted` (else `evicted` is cleared).
  Heard Announce(const std::string& name, std::string* evicted = nullptr);

  /// Starts the connects that are due (never more than max_connecting in
  /// flight), joins the threads of those that ended, and forgets the names
  /// that went silent long ago. Returns the names forgotten. Call it often
  /// (every loop of the caller). A connect that ends also starts the next
  /// one due at once, without waiting for Poll().
  std::vector<std::string> Poll();

  /// The caller no longer serves `name` (it dropped its client): it is tried
  /// again at once (as a name not tried yet), if it is announced. Called while
  /// its connect is in flight, that connect counts as lost too when it returns.
  void Lost(const std::string& name);

  struct State {
    bool served = false;
    bool connecting = false;  ///< its connect is in flight
    bool silent = false;      ///< not announced for silent_after
    int failures = 0;         ///< failed connects since it was last served (or added)
  };
  /// nullopt when `name` is not in the table.
  std::optional<State> Find(const std::string& name) const;

  struct Counts {
    std::size_t names = 0;       ///< in the table
    std::size_t connecting = 0;  ///< connects in flight
  };
  Counts counts() const;

 private:
  struct Name {
    TimePoint heard{};
    TimePoint due{};          // the next attempt may start then
    std::uint64_t order = 0;  // ties of `due`: first come, first tried
    int failures = 0;
    bool served = false;
    bool connecting = false;
    bool lost = false;  // Lost() while connecting
  };
  struct Worker {
    std::thread thread;
    bool finished = false;  // GUARDED_BY(mu_): the thread is ending and may be joined
  };

  bool Silent(const Name& n, TimePoint now) const;
  Duration Timeout(int failures) const;
  Duration Backoff(int failures) const;
  bool Evict(TimePoint now, std::string* evicted);  // REQUIRES: mu_
  void StartDue(TimePoint now);                     // REQUIRES: mu_
  void Run(std::list<Worker>::iterator self, const std::string& name, Duration timeout);

  const ConnectFn connect_;
  const FailedFn failed_;
  const ConnectSchedulerOptions options_;
  SteadyClock steady_clock_;
  const Clock& clock_;
  mutable std::mutex mu_;
  std::map<std::string, Name> names_;  // GUARDED_BY(mu_), at most max_names
  std::list<Worker> workers_;          // GUARDED_BY(mu_)
  std::size_t in_flight_ = 0;          // GUARDED_BY(mu_)
  std::uint64_t next_order_ = 0;       // GUARDED_BY(mu_)
  bool stopping_ = false;              // GUARDED_BY(mu_)
};

}  // namespace robotalk
