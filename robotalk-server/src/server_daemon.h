// The paper's ServerDaemon: one thread that receives every client package of
// the robots this server serves from the transport, decodes it (the codec is
// the only place that knows the wire), hands it to that robot's
// RobotSessions (sessions, admission), and sends what comes back: the
// immediate acknowledgement, the RobotDaemons' replies and state samples, the
// configuration message, and ROBOTALK/ANNOUNCE once a period (keyed mode:
// ANNOUNCE, CONFIG and STATE signed by the server's key, broadcast_signature.h).
// It also runs the session watchdog and the driver-call watchdog, and applies
// one robot, one server while it starts (OnAnnounce).
//
// Fewer hops (issue 11): a query answered on receipt from the RobotDaemon's
// published state (RobotSessions, query_snapshot.h) travels in the
// acknowledgement; a panic in a session is acknowledged before the
// RobotDaemon's lock is waited for (RobotDaemon::FinishPanic comes after; an
// open-mode panic outside any session is answered after it); the latch is
// written in one place, Drain, before anything that acknowledges the
// panic, its reset or a driver fault is sent; log lines are written to
// stderr at the end of an iteration, after every publish, never between a
// package's receipt and its acknowledgement.
//
// Thread safety: RunOnce() and everything it calls run on one thread (the one
// Start() launches, or a test's). Wake() may be called from any thread (the
// RobotDaemons call it when their outbox has something).
#pragma once

#include "fault_injector.h"
#include "panic_latch.h"
#include "robot_daemon.h"
#include "robot_sessions.h"
#include "robotalk/broadcast_signature.h"
#include "robotalk/channels.h"
#include "robotalk/clock.h"
#include "robotalk/log_limiter.h"
#include "robotalk/transport.h"
#include "server_log.h"
#include "session_table.h"

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <random>
#include <string>
#include <thread>
#include <vector>

namespace robotalk {

/// A token bucket: Take() succeeds at most `per_second` times a second on
/// average, in bursts of at most `per_second`. Pure (times from the caller).
class AnswerBudget {
 public:
  bool Take(TimePoint now, int per_second) {
    if (per_second <= 0) return false;
    const double full = per_second;
    if (last_ == TimePoint::min())
      tokens_ = full;
    else if (now > last_)
      tokens_ = std::min(full, tokens_ + ToSeconds(now - last_) * full);
    last_ = std::max(last_, now);
    if (tokens_ < 1.0) return false;
    tokens_ -= 1.0;
    return true;
  }

 private:
  double tokens_ = 0.0;
  TimePoint last_ = TimePoint::min();
};

struct ServerDaemonOptions {
  /// Period of the ROBOTALK/ANNOUNCE message.
  Duration announce_period = kAnnouncePeriod;
  /// How often silent sessions and overrunning driver calls are looked for.
  Duration watchdog_period = std::chrono::milliseconds(100);
  /// The paper's congestion injector (§VI-B): after each received package the
  /// ServerDaemon pauses a random time uniform in [0, this]. 0 = off.
  Duration congestion_max_pause{0};
  /// Test fault injection on outgoing reply packages (seeded).
  double reply_drop_probability = 0.0;
  double reply_duplicate_probability = 0.0;
  std::uint64_t fault_seed = 1;
  /// Most log lines per second; the rest are counted and summarised. A line
  /// repeated within `log_repeat_window` prints once, then one summary per
  /// window ("... (repeated 230 times in 10 s)"; log_limiter.h).
  int log_lines_per_second = 20;
  Duration log_repeat_window = std::chrono::seconds(10);
  /// The server's instance id in ANNOUNCE (random when 0).
  std::int64_t server_id = 0;
  /// The panic latch file (panic_latch.h); "" keeps no panic across restarts.
  std::string panic_latch_path;
  /// Serve a robot even when another server announces the same name (both
  /// would execute every command). Off: one robot, one server (see
  /// ServerDaemon::OnAnnounce).
  bool allow_duplicate_robots = false;
  /// One robot, one server is decided by the server that starts later, during
  /// this long after its first RunOnce: an ANNOUNCE of the same robot by a
  /// server that has served longer makes it refuse that robot. After the
  /// window an ANNOUNCE changes nothing (a forged one could otherwise disable
  /// a serving robot); a conflict is only logged. Must exceed the announce
  /// period of the other servers (1 s by default).
  Duration startup_window = std::chrono::seconds(2);
  /// Open or keyed mode, the session bounds (session_table.h).
  SessionTableOptions sessions;
  /// Announced so that clients on another layout say so (docs/protocol.md).
  TrafficLayout traffic_layout = TrafficLayout::kSingle;
  /// The thread Start() launches runs SCHED_FIFO at this priority when the
  /// process may (0 = never), below the RobotDaemons' (RobotDaemonOptions):
  /// on a machine busy with other processes (64 clients on 2 cores) the
  /// server keeps the CPU it needs instead of 1/65 of it. It only runs when a
  /// package or output is there (it sleeps in poll()). LCM's receive threads
  /// of its subscriptions are started at the same priority (see the
  /// constructor): under load they read every waiting datagram before the
  /// ServerDaemon runs, one wake-up for many packages. 0 = off
  /// (robotalk::Server: with the RobotDaemons' timing option).
  int fifo_priority = 5;
  /// Keyed mode: SESSION_UNKNOWN answers signed per second, at most (a burst
  /// of as many; answers to packages carrying a panic have a budget of their
  /// own of the same size). Each costs an Ed25519 signature (~25 µs), so a
  /// flood of packages naming made-up sessions would otherwise buy that much
  /// of this thread per datagram; beyond the budget a package is counted
  /// (`unknown_unanswered`) and not answered. 1,000 answers about four times
  /// the whole of a restarted server's sessions of one robot
  /// (`--max-sessions-per-robot`, 256) within a second, and a flood below
  /// that rate as before; both budgets full cost at most 2,000 signatures a
  /// second, ~3.9 % of a core (19.4 µs each, robotalk-flood-bench), a full
  /// burst ~39 ms of this thread. Open mode's answers are unsigned and unlimited.
  int unknown_answers_per_second = 1000;
};

class ServerDaemon {
 public:
  ServerDaemon(Transport& transport, const Clock& clock, ServerDaemonOptions options = {});
  ~ServerDaemon();
  ServerDaemon(const ServerDaemon&) = delete;
  ServerDaemon& operator=(const ServerDaemon&) = delete;

  /// Serves `daemon`'s robot. REQUIRES: before Start(); robot names unique.
  /// The ServerDaemon does not own the RobotDaemon (the Server does).
  void AddRobot(RobotDaemon& daemon, SessionOptions options);

  /// One iteration: waits at most `timeout` for a package or a RobotDaemon's
  /// output, handles what arrived, sends what is ready, and runs the
  /// watchdogs and ANNOUNCE when due.
  void RunOnce(Duration timeout);
  /// Sends whatever the RobotDaemons have produced (used at shutdown).
  void Flush();

  /// Runs RunOnce() on a thread until Stop().
  void Start();
  void Stop();
  /// Makes a waiting RunOnce() return at once. Thread-safe.
  void Wake();

  std::vector<std::string> robot_names() const;
  /// Why this server does not serve `robot` (another server does), or "".
  /// REQUIRES: the ServerDaemon's thread (or it is not running).
  std::string refused(const std::string& robot) const;
  /// How many of its robots this server serves (the others are refused).
  /// Thread-safe: robotalk-server exits when it reaches 0.
  std::size_t serving() const { return serving_.load(); }
  /// Why each refused robot is refused. Thread-safe.
  std::vector<std::string> refusals() const;
  std::int64_t server_id() const { return server_id_; }
  /// Packages dropped because their bytes could not be decoded at all.
  std::uint64_t malformed() const { return malformed_; }
  /// Keyed: packages naming no session left unanswered past the signed
  /// answers' budget (ServerDaemonOptions::unknown_answers_per_second).
  std::uint64_t unknown_unanswered() const { return unknown_unanswered_; }
  /// The server's session table (all robots' sessions).
  const SessionTable& sessions() const { return *table_; }

 private:
  struct Robot {
    RobotDaemon* daemon;
    std::unique_ptr<RobotSessions> sessions;
    std::vector<std::uint8_t> encoded_config;
    std::uint64_t config_hash;
    DaemonOutput output;
    std::string refused;            ///< non-empty: another server serves this robot; why we do not
    TimePoint next_conflict_log{};  ///< a conflicting ANNOUNCE after the start-up window: logged then
    std::uint64_t conflicts_unlogged = 0;
  };

  void OnRequest(const std::string& channel, std::span<const std::uint8_t> bytes);
  void OnHello(const std::string& channel, std::span<const std::uint8_t> bytes);
  // The session table's verdict on a decoded request; false when Handle must not run.
  // `now`: handled; `arrived`: reached the socket (ArrivalTime).
  bool Gate(Robot& robot, const std::string& name, Request& request, std::span<const std::uint8_t> bytes,
            TimePoint now, TimePoint arrived);
  // When the message being handled reached the socket (the transport's
  // receive stamp), on clock_: `now` less its age. `now` itself where that
  // cannot be told: a clock that does not run with the wall clock's seconds
  // (a ManualClock), a transport without a stamp, an age outside [0, 1 s]
  // (a wall-clock step).
  TimePoint ArrivalTime(TimePoint now) const;
  void OnAnnounce(std::span<const std::uint8_t> bytes);
  void Refuse(Robot& robot, const std::string& why);
  void LogConflict(Robot& robot, const std::string& other, Duration served);
  void Send(const std::string& robot, ReplyBatch& batch);
  // Takes and files the RobotDaemon's output (PumpOutput), writes the panic
  // latch (Persist) and the audit lines (--log-executions), then sends `ack`
  // (if any), the state samples and the replies.
  void Drain(Robot& robot, bool wait = true, ReplyBatch* ack = nullptr);
  void WriteLog();
  void ApplyPriority();
  void Announce(TimePoint now);
  void Watchdogs(TimePoint now);
  void Log(const std::string& line);
  void Persist(Robot& robot);

  Transport& transport_;
  const Clock& clock_;
  const ServerDaemonOptions options_;
  FaultInjector faults_;
  PanicLatch latch_;
  LogLimiter log_limiter_;  // per line and per second (log_limiter.h)
  std::map<std::string, std::string> latched_at_start_;
  std::map<std::string, Robot> robots_;
  std::unique_ptr<SessionTable> table_;
  std::optional<BroadcastSigner> signer_;  // keyed mode: signs ANNOUNCE, CONFIG and STATE
  std::unique_ptr<Subscription> subscription_;
  std::unique_ptr<Subscription> hello_subscription_;
  std::unique_ptr<Subscription> announce_subscription_;
  TimePoint started_ = TimePoint::min();  // first RunOnce
  std::vector<ReplyBatch> to_send_;
  std::mt19937_64 congestion_rng_;
  int event_fd_ = -1;
  std::int64_t server_id_ = 0;
  std::uint64_t malformed_ = 0;
  // Keyed: the signed SESSION_UNKNOWN answers' budgets (without and with a panic).
  AnswerBudget unknown_budget_;
  AnswerBudget unknown_panic_budget_;
  std::uint64_t unknown_unanswered_ = 0;
  std::atomic<std::size_t> serving_{0};
  mutable std::mutex refusals_mu_;
  std::vector<std::string> refusals_;  // GUARDED_BY(refusals_mu_)
  TimePoint next_announce_ = TimePoint::min();
  TimePoint next_watchdog_ = TimePoint::min();
  std::vector<std::string> log_pending_;  // written by WriteLog() after the publishes (audit lines before)
  LogWriter& log_writer_ = ServerLog();   // stderr; a stderr that takes nothing never stops this thread
  std::atomic<bool> running_{false};
  std::thread thread_;
};

}  // namespace robotalk
