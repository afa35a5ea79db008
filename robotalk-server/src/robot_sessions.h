// The ServerDaemon's side of one robot: its clients' sessions (kept in the
// server's session table: duplicate detection, acknowledgements, the reply
// cache, expiry), admission (each command and
// query checked against the model, start times and queue limits checked,
// panic and PANIC_RESET acted on at once), playback buffering and its delay
// estimate, and the watchdog that expires silent sessions. Admitted items go
// to the RobotDaemon (Submit); its output comes back through File().
//
// Thread safety: none. One thread, the ServerDaemon, uses it; the only
// locks it takes are the RobotDaemon's short inbox/outbox locks. Parsing,
// checks and messages all happen here, outside any lock the RobotDaemon needs.
#pragma once

#include "expiry.h"
#include "link_health.h"
#include "robot_daemon.h"
#include "robotalk/request.h"
#include "robotalk/server.h"
#include "robotalk/state_sample.h"
#include "session.h"
#include "session_table.h"

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

namespace robotalk {

struct SessionOptions {
  /// A session that sends nothing for this long expires (watchdog).
  Duration session_timeout = kDefaultSessionTimeout;
  /// Most items one client may have waiting (queued and buffered playback frames).
  std::size_t max_queue = kDefaultMaxQueue;
  /// Start times further ahead than this, or further in the past, are refused.
  Duration max_future = kDefaultMaxFuture;
  /// What CheckCommand allows beyond the model (the GOTO bound).
  CommandLimits limits;
  /// When playback mode has seen enough frames to estimate its delay.
  PlaybackEstimatorOptions playback;
  /// A package link health calls a retransmission (its send time is its first
  /// copy's) stays out of the session's delay history (--playback-resent-delays
  /// off, the default); on: every package counts, as before issue 23's fifth session.
  bool playback_resent_delays = false;
  /// A log line per playback start: what the estimator decided it from (--log-playback).
  bool log_playback = false;
  /// Most client sessions this robot serves at once (--max-sessions-per-robot);
  /// a new client beyond is refused.
  std::size_t max_sessions_per_robot = kDefaultMaxSessionsPerRobot;
  /// Longest reply message kept and sent (bad input is never echoed in full).
  std::size_t max_message_bytes = 512;
  /// The server's refusal counters for the SERVER_COUNTERS query (name, value).
  std::function<std::vector<std::pair<const char*, double>>()> counters;
  /// Most items all clients of this robot may have waiting (queued and
  /// buffered playback frames; each costs QueuedItemBytes()). Half of it is
  /// every client's guaranteed share, max_robot_queue / (2 · max_sessions_per_robot)
  /// each, always admitted (within max_queue); the other half is shared:
  /// items past a client's share are admitted only while all clients' items
  /// are fewer than max_robot_queue / 2. So the robot never holds more than
  /// max_robot_queue, and clients flooding it cannot lock a new one out.
  std::size_t max_robot_queue = 65536;
  /// Most playback sequences one client may have unfinished at once.
  std::size_t max_playbacks = 16;
  /// Each session's reply cache.
  ReplyCache::Limits replies;
  /// Deadlines (expiry.h): the limit of a timed servo command whose package
  /// gives none (--max-late); Duration::max() = never.
  Duration max_late = kDefaultMaxLate;
  /// Each session's link health: its tolerances and thresholds.
  LinkHealthOptions link;
  /// Stop what a session owns when its link is past a stop threshold (--link-stop).
  bool link_stop = false;
};

/// What one waiting item costs at most wherever it waits -- a queued command
/// or query, a buffered playback frame with its estimator entry and its
/// timed-servo entry, a waypoint the trajectory tracker holds, a SETSPEED
/// frame the speed ramp holds (all count against the same item bounds) --
/// the containers' spare capacity included: the byte bound behind the item bounds.
std::size_t QueuedItemBytes();

/// What the ServerDaemon sends back at once for a received package.
struct ImmediateAnswer {
  ReplyBatch batch;             ///< ack + immediate replies; server_send filled by the sender
  bool send = true;             ///< false for packages that cannot be answered (no client id)
  bool publish_config = false;  ///< a CONFIG query asked for the configuration message
};

/// A client session the watchdog removed.
struct ExpiredSession {
  std::int64_t client_id = 0;
  std::size_t dropped_commands = 0;  ///< queued commands that will never run
  bool moved_robot = false;          ///< it owned actuators (they are stopped: Driver::StopOnly)
};

class RobotSessions {
 public:
  /// Keeps its sessions in the server's `table` (which must outlive it).
  RobotSessions(RobotDaemon& daemon, std::uint64_t config_hash, SessionOptions options, SessionTable& table);
  /// On its own (a simulation, a test): a table of its own, open mode; a
  /// package of a client without a session opens one.
  RobotSessions(RobotDaemon& daemon, std::uint64_t config_hash, SessionOptions options = {});

  /// Handles one decoded request, handled at `now` (the server clock) after
  /// it reached the socket at `arrived` (the transport's receive stamp on the
  /// server clock; ServerDaemon::ArrivalTime): `arrived` measures the link
  /// (link health's transits, the reply's server_receive for the client's
  /// clock); `now` judges what runs (start times, expiry, the session's
  /// liveness) and playback's delays (a frame can play only once handled).
  /// docs/protocol.md "Clocks".
  ImmediateAnswer Handle(const Request& request, TimePoint now, TimePoint arrived);
  /// The same handled when it arrived (a simulation, a test).
  ImmediateAnswer Handle(const Request& request, TimePoint now) { return Handle(request, now, now); }
  /// A retransmission the session table's window saw (open or keyed mode):
  /// acknowledges it with what is known of its items; runs nothing, opens
  /// and refreshes no session; counts it in the session's link health and
  /// records when it was handled in its delay history (AnswerCopy). `now`,
  /// `arrived`: as Handle.
  ImmediateAnswer Resend(const Request& request, TimePoint now, TimePoint arrived);
  /// Raises a panic on behalf of `client_id` (outside any session: open
  /// mode honours a panic from anyone).
  void RaisePanic(std::int64_t client_id, TimePoint now) { Panic(client_id, now); }
  /// Files the RobotDaemon's output (replies into the sessions' caches, the
  /// watchdog's bookkeeping) and the replies this layer produced outside
  /// Handle (a panic's flushed items); appends what to send, one batch per client.
  void File(DaemonOutput& output, std::vector<ReplyBatch>& to_send);
  /// Expires this robot's silent and never-used sessions (SessionTable::Expire);
  /// a STOP follows if one had moved the robot.
  std::vector<ExpiredSession> Expire(TimePoint now);
  /// Starts the playback sequences whose wait for frame 0's second copy ended
  /// by `now` (PlaybackSequence::decide_by); their delay replies are sent
  /// with the next File. Returns whether it started one.
  bool DecidePlaybacks(TimePoint now);
  /// When DecidePlaybacks has one to start next (nullopt: none waits).
  std::optional<TimePoint> NextPlaybackDecision() const;
  /// Lines for the server log (panic, reset), taken once.
  std::vector<std::string> TakeLog();

  /// Sessions this robot serves (SessionTable::active).
  std::size_t num_sessions() const { return table_.active(robot_id_); }
  /// This robot's number in the session table.
  int robot_id() const { return robot_id_; }
  /// Who last commanded each joint / the base (0 = nobody since the last STOP).
  std::int64_t joint_owner(int joint) const { return joint_owner_[static_cast<std::size_t>(joint)]; }
  std::int64_t base_owner() const { return base_owner_; }
  /// Packages refused before admission, by reason (sequence jump, server full, ...).
  std::uint64_t refused_packages() const { return refused_packages_; }
  /// Commands not executed past their deadline (expiry.h), all clients.
  std::uint64_t expired_commands() const { return expired_commands_; }
  /// The client that last moved the robot (0 = nobody since the last STOP).
  std::int64_t motion_owner() const { return motion_owner_; }
  /// The link health of `motion_owner()`'s session, for the state stream.
  LinkState MotionLink() const;
  /// A client's link figures (nullopt: no such session).
  std::optional<LinkFigures> link(std::int64_t client_id) const;
  /// Memory a client's session holds, as its bounds count it (0 when there
  /// is no such session).
  struct SessionMemory {
    std::size_t reply_cache = 0;           ///< ReplyCache::bytes(), at most replies.max_bytes
    std::size_t playbacks = 0;             ///< unfinished sequences and the ended list
    std::size_t waiting = 0;               ///< items queued or buffered, at most max_queue
    std::size_t waiting_bytes = 0;         ///< waiting × QueuedItemBytes()
    std::size_t unfinished_playbacks = 0;  ///< at most max_playbacks
    std::size_t timed_servos = 0;          ///< entries, one per waiting timed servo command
  };
  SessionMemory memory(std::int64_t client_id) const;

 private:
  RobotSessions(RobotDaemon& daemon, std::uint64_t config_hash, SessionOptions options,
                std::unique_ptr<SessionTable> own, SessionTable* table);
  Session& SessionFor(std::int64_t client_id, TimePoint now);
  ImmediateAnswer Refuse(const Request& request, TimePoint now, TimePoint arrived);
  void AdmitQuery(Session& s, const Query& q, TimePoint now, std::vector<Reply>& immediate,
                  bool& publish_config);
  Reply CommandStatus(const Session& s, const Query& q, TimePoint now) const;
  // Checks a command; returns it ready to queue, or answers it in `immediate`.
  // `max_late`: its package's (Request::max_late).
  std::optional<QueuedItem> Admit(Session& s, const Command& c, TimePoint now, std::vector<Reply>& immediate,
                                  bool playback, Duration max_late,
                                  Interpolation interpolation = Interpolation::kStep);
  /// `arrived`: when it reached the socket (the server's own lag, now − arrived, tells the
  /// estimator whether a queue beyond its gate is the server's: PlaybackEstimatorOptions::follow_queue).
  void AdmitPlayback(Session& s, const Request& request, TimePoint now, TimePoint arrived,
                     std::vector<Reply>& immediate);
  void Panic(std::int64_t client_id, TimePoint now, const std::string& sender = "");
  void Deliver(std::int64_t client_id, Reply reply);
  std::size_t Waiting(const Session& s) const;
  // Why `s` may not have one more item waiting, or "" (and it is counted).
  std::string QueueRefusal(const Session& s);
  // The answer to a retransmission of a package already seen.
  std::vector<Reply> Retransmitted(const Session& s, const Request& request, TimePoint now) const;
  // A copy of a package `s` saw (a retransmission, a duplicated datagram),
  // whether the session table's gate (Resend) or Handle caught it: never
  // executed again, answered with what is known (Retransmitted), counted by
  // the link's health and kept for playback's start (DelayHistory::AddCopy).
  std::vector<Reply> AnswerCopy(Session& s, const Request& request, TimePoint now, TimePoint arrived);
  void Start(Session& s, std::int64_t id, PlaybackSequence& seq, TimePoint now,
             std::vector<Reply>& immediate);
  void Own(const DaemonOutput::Executed& e);
  void Bound(Reply& reply) const;
  // True (and answered) when a timed servo command arrives after a
  // later-starting one of the same client on the same actuator has run.
  bool Superseded(Session& s, const QueuedItem& item, TimePoint now, std::vector<Reply>& immediate);
  void NoteServoAnswer(std::int64_t client_id, const Reply& reply);
  // Link health (robot_sessions_link.cpp): the SERVER_COUNTERS figures of a
  // session; the warnings and the --link-stop policy, every Expire() tick.
  void AppendLinkCounters(const Session& s, Reply& reply) const;
  void CheckLinks(TimePoint now);
  // Stops what `client` owns (Driver::StopOnly); returns whether it owned anything.
  bool StopOwned(std::int64_t client, const std::string& why);
  // Ends every unfinished playback sequence of `s` (a panic, --link-stop):
  // its buffered frames go to flushed_ (the caller answers them), a sequence
  // not started answers its delay reply INTERRUPTED "PLAYBACK n: ended by
  // <why> before it started", and its later frames are answered, never run.
  void EndPlaybacks(Session& s, Session::Ended ended, const std::string& why, TimePoint now);

  RobotDaemon& daemon_;
  const std::string robot_;
  const std::uint64_t config_hash_;
  const SessionOptions options_;
  std::unique_ptr<SessionTable> own_table_;  // used on its own only
  SessionTable& table_;
  const int robot_id_;
  std::map<std::int64_t, std::vector<Reply>> pending_;  // replies made outside Handle, by client
  std::vector<std::string> log_;
  // Playback sequences waiting for frame 0's second copy: client, playback id, until when.
  struct CopyWait {
    std::int64_t client_id, playback_id;
    TimePoint until;
  };
  std::vector<CopyWait> copy_waits_;
  // Whether `seq`, ready at its first frame, waits for that frame's second copy (copies_start).
  bool WaitForFrameCopy(const PlaybackSequence& seq, TimePoint now) const;
  // A second copy of a playback package: a waiting sequence's frame came twice (AnswerCopy).
  void OnPlaybackCopy(Session& s, const Request& r, TimePoint now, std::vector<Reply>& replies);
  std::vector<QueuedItem> flushed_;
  std::vector<std::int64_t> joint_owner_;  // per joint: the client that last commanded it
  std::int64_t base_owner_ = 0;
  std::uint64_t refused_packages_ = 0;
  std::uint64_t expired_commands_ = 0;
  std::int64_t motion_owner_ = 0;
  // Items waiting, the client's own and all clients': counted when a
  // package's first item asks (the RobotDaemon only takes items meanwhile),
  // then kept up to date as its items are admitted.
  struct QueueCount {
    bool known = false;
    std::size_t own = 0, total = 0;
  } count_;
};

}  // namespace robotalk
