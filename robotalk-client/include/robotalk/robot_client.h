// RobotClient: the C++ client of a RoboTalk server over LCM (docs/client.md,
// docs/protocol.md; the paper's CRobotClient, §IV-B).
//
//   robotalk::RobotClient client;            // ClientOptions{} = LCM default URL
//   client.Connect("pioneer");               // CONFIG + clock sync
//   robotalk::Reply r = client.Goto(1.0, 0.0, 0.0);   // blocks until the final reply
//   auto pending = client.Send(cmd);         // non-blocking; pending.Wait(...) later
//
// A ReadDaemon thread files every reply in a return cache keyed by command
// id, processes acknowledgements, retransmits unacknowledged packages (same
// sequence; the server executes each command once) and sends a heartbeat when
// the client has sent nothing for `heartbeat_interval`.
//
// Thread safety: every method may be called from any thread concurrently.
// A PendingReply handle is not itself thread-safe; use one handle per thread.
//
// Errors: blocking calls throw TimeoutError (client_errors.h) when no final
// reply arrives in time, ClientError when the client is not usable (not
// connected, closing). A reply with a non-success signal is NOT an exception:
// inspect Reply::signal. An unexpected failure inside the ReadDaemon is stored
// and rethrown by the next blocking call.
#pragma once

#include "robotalk/client_errors.h"
#include "robotalk/clock.h"
#include "robotalk/command.h"
#include "robotalk/keys.h"
#include "robotalk/max_late.h"
#include "robotalk/robot_model.h"
#include "robotalk/state_sample.h"
#include "robotalk/trajectory.h"
#include "robotalk/transport.h"

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <stop_token>
#include <string>
#include <utility>
#include <vector>

namespace robotalk {

namespace client {
class ReturnCache;
}

/// ClientOptions::playback_copies: the copies decided from the link (twice
/// once it has lost a message and a retransmission would come too late).
inline constexpr int kPlaybackCopiesAuto = 0;

struct ClientOptions {
  /// LCM URL; "" = LCM's default (the LCM_DEFAULT_URL environment variable, or
  /// udpm://239.255.76.67:7667?ttl=0).
  std::string lcm_url;
  /// Use this transport instead of an LcmTransport on `lcm_url` (tests with a
  /// MemoryTransport, embedding, several clients on one LCM). It must outlive
  /// the client, and nobody else may call HandleFor() on it: the client's
  /// ReadDaemon dispatches ALL its subscriptions.
  Transport* transport = nullptr;
  /// The client's clock: retransmission, heartbeats, clock-sync samples and
  /// sequence pacing run on it. nullptr = the steady clock. It must outlive
  /// the client. Blocking calls still time out in real time.
  const Clock* clock = nullptr;
  /// The ReadDaemon sleeps until its next deadline (a resend, a heartbeat) or
  /// a message, but re-reads the clock at least this often in real time: how
  /// soon it notices that a ManualClock moved. Close()/destruction wakes it at
  /// once regardless.
  Duration max_idle_wait = std::chrono::milliseconds(50);
  /// Each blocking call waits at most this long for its final reply, counted
  /// from the later of the call and the command's start time.
  Duration timeout = std::chrono::seconds(5);
  /// Connect() gives up after this long (clock sync + configuration).
  Duration connect_timeout = std::chrono::seconds(5);
  /// First resend of an unacknowledged package after this; then ×backoff.
  Duration retransmit_interval = std::chrono::milliseconds(100);
  double retransmit_backoff = 2.0;
  /// Longest interval between resends of one package.
  Duration retransmit_max_interval = std::chrono::seconds(1);
  /// Stop resending a package the server has said nothing about for this long;
  /// its waiters fail with TimeoutError.
  Duration give_up_after = std::chrono::seconds(5);
  /// Deadline of every command this client sends (docs/server.md, Deadlines):
  /// how late after its start time it may still begin; past it the server
  /// answers INTERRUPTED "expired: ..." and does not execute it.
  /// kMaxLateServerDefault (the robot's --max-late for servo commands; a GOTO
  /// runs late), kMaxLateNever, or a limit (> 0). SequenceOptions::max_late
  /// overrides it for a sequence.
  Duration max_late = kMaxLateServerDefault;
  /// Playback redundancy (RFC 2198's idea, docs/protocol.md "Playback"): each
  /// MODE_PLAYBACK package leaves this many times at once (1 or 2; 1: once).
  /// The server runs and answers each frame once (a copy is a duplicate by
  /// sequence number); a frame whose first copy the network loses still
  /// arrives in time, instead of one retransmission timeout (>= 100 ms)
  /// later. Costs one more copy of every playback package (and of its ack).
  /// kPlaybackCopiesAuto (0): twice only while the link has lost a message
  /// in the last 60 s (the client's own count: fewer acks than copies sent;
  /// a spurious retransmission is not a loss) and the retransmission timeout
  /// exceeds the frame's headroom; once otherwise (docs/client.md).
  int playback_copies = kPlaybackCopiesAuto;
  /// An idle client sends an empty package this often (server session watchdog).
  Duration heartbeat_interval = std::chrono::milliseconds(250);
  /// CLOCK round trips at Connect(); the one with the smallest round trip wins.
  int clock_sync_rounds = 8;
  /// While connected, one more CLOCK round trip this often (zero: never), so
  /// the offset follows two hosts' clocks drifting apart: the best sample's
  /// error bound grows by 100 ppm of its age and a fresh sample with a
  /// tighter bound replaces it (docs/client.md, Clock synchronisation).
  Duration clock_refresh_interval = std::chrono::seconds(10);
  /// LCM receive-queue capacity of the client's subscriptions (messages),
  /// when the client creates its own LcmTransport.
  int lcm_queue_capacity = 10000;
  /// Answered but never collected replies kept at most (oldest evicted).
  std::size_t return_cache_capacity = 10000;
  /// The client id; 0 = random non-zero (std::random_device). With a key,
  /// one of the key's (robotalk::KeyedClientId; 0 = random low bits); another
  /// is refused with ClientError at construction.
  std::int64_t client_id = 0;

  // --- Fault injection, for tests: applied to every request package sent.
  double drop_probability = 0.0;       ///< package silently not sent
  double duplicate_probability = 0.0;  ///< package sent twice
  std::uint64_t fault_seed = 1;
  /// Keyed mode (docs/security.md): this client's secret key file. Empty:
  /// $ROBOTALK_KEY if set, else open mode.
  std::string key_file;
  /// Keyed mode: the server's public key file (.pub); when set, a server
  /// answering with another key is refused, the known-servers file is not
  /// used, and ListRobots lists only the robots this key announced.
  std::string server_key_file;
  /// Keyed mode without `server_key_file`: the known-servers file that pins
  /// each robot's server key on first use (docs/security.md, "Which server?").
  /// Empty: $ROBOTALK_KNOWN_SERVERS, else ~/.robotalk/known_servers.
  std::string known_servers_file;
};

/// Keyed mode: which server key a client trusts, and why (docs/security.md,
/// "Which server?"). Hello answers, STATE and CONFIG of any other key are refused.
struct TrustedServer {
  enum class Source {
    kNone,       ///< open mode, or no server trusted yet
    kExplicit,   ///< ClientOptions::server_key_file (--server-key)
    kPinned,     ///< pinned in the known-servers file before this client started
    kPinnedNow,  ///< first use: this client pinned it (say so to the user)
  };
  Source source = Source::kNone;
  std::string key;          ///< "ed25519:<64 hex>"
  std::string fingerprint;  ///< "rt:1a2b:3c4d:5e6f:7a8b"
  std::string file;         ///< the .pub file or the known-servers file
};

/// The handle of a non-blocking call. Movable, not copyable. Destroying it
/// without collecting the reply tells the client nobody waits for it (a late
/// reply is then dropped); the command still executes.
class PendingReply {
 public:
  PendingReply(PendingReply&&) noexcept;
  PendingReply& operator=(PendingReply&&) noexcept;
  PendingReply(const PendingReply&) = delete;
  PendingReply& operator=(const PendingReply&) = delete;
  ~PendingReply();

  CommandId id() const { return id_; }
  /// The reply if it has arrived (it stays available). Throws TimeoutError if
  /// the client gave up on it.
  std::optional<Reply> Poll();
  /// Waits at most `timeout` for the reply; throws TimeoutError.
  Reply Wait(Duration timeout);
  /// Waits at most `most` for the reply, waking at once when it arrives or
  /// when `stop` is requested; nullopt when `most` passed or `stop` came
  /// first. Throws as Poll() does when the client gave up on it.
  std::optional<Reply> WaitFor(Duration most, std::stop_token stop = {});

 private:
  friend class RobotClient;
  PendingReply(CommandId id, std::shared_ptr<client::ReturnCache> cache, std::string what);

  CommandId id_ = 0;
  std::shared_ptr<client::ReturnCache> cache_;
  std::string what_;  // "GOTO 12" for messages
  std::optional<Reply> reply_;
};

/// How a sequence of timed commands travels (paper §V, Table I). The same
/// commands work in every mode.
enum class CommandMode {
  kDirect,    ///< blocking handshake: each frame waits for its reply before the next goes
  kDelay,     ///< start = synchronised server clock + a chosen delay; non-blocking
  kPlayback,  ///< offsets only; the server estimates the delay; no clock sync needed
};
const char* ToString(CommandMode mode);
/// "direct", "delay", "playback"; nullopt otherwise.
std::optional<CommandMode> ParseCommandMode(const std::string& name);

/// One frame of a sequence: a command and when it should run, relative to the
/// sequence start (its own start_time is ignored).
struct TimedCommand {
  Duration offset{0};
  Command command;
  /// The interpolation of the package this frame travels in; nullopt: the
  /// sequence's (SequenceOptions::interpolation). Frames of different
  /// interpolations never share a package; a playback sequence has one.
  std::optional<Interpolation> interpolation;
};

struct SequenceOptions {
  CommandMode mode = CommandMode::kDelay;
  /// Delay mode: how far ahead of the synchronised server clock the sequence
  /// starts, i.e. the congestion it survives. 0 is allowed.
  Duration delay = std::chrono::seconds(1);
  /// Send each frame when its offset comes (a live stream, as a planner or a
  /// teleoperator produces it); false sends the whole sequence at once.
  bool paced = true;
  /// Frames per package when not paced (direct mode always sends one).
  std::size_t batch = 200;
  /// How the sequence's timed JOINT_SETPOINT / FRAME_SETPOINT frames join
  /// into each actuator's trajectory (docs/client.md, "Trajectories"): put on
  /// every package of the sequence. kStep (the default) is protocol 3's
  /// behaviour. Another one needs timed frames: delay or playback mode.
  Interpolation interpolation = Interpolation::kStep;
  /// Delay mode: the server time of offset 0; nullopt: the synchronised
  /// server clock when the sequence starts + `delay`.
  std::optional<TimePoint> start;
  /// The frames' deadline (ClientOptions::max_late's values); nullopt: ClientOptions::max_late.
  std::optional<Duration> max_late;
};

/// One waypoint of a trajectory (docs/client.md, "Trajectories").
struct TrajectoryPoint {
  /// When the actuator passes through it, after the trajectory's start;
  /// >= 0 and strictly increasing from point to point.
  Duration time_from_start{0};
  /// A joint: one position per dof (rad or m). A control frame: its pose in
  /// the world, x y z qw qx qy qz.
  std::vector<double> positions;
  /// Empty: chosen by the server (smooth through the points). Else one per
  /// dof; a frame: 6, vx vy vz wx wy wz in the world (m/s, rad/s).
  std::vector<double> velocities;
  /// Empty: chosen by the server (quintic uses them). Else as `velocities`, per s.
  std::vector<double> accelerations;
};

/// A joint's timed waypoints (JOINT_SETPOINT commands).
struct JointTrajectory {
  std::string joint;
  std::vector<TrajectoryPoint> points;
};

/// A control frame's timed waypoints (FRAME_SETPOINT commands), interpolated
/// in task space by the server.
struct FrameTrajectory {
  std::string frame;
  std::vector<TrajectoryPoint> points;
};

struct TrajectoryOptions {
  /// kDelay: the points run at `start` + time_from_start on the server clock;
  /// kPlayback: the server chooses the start (no clock sync needed). kDirect
  /// is refused: a direct command has no start time, so it is a step.
  CommandMode mode = CommandMode::kDelay;
  Interpolation interpolation = Interpolation::kCubic;
  /// Delay mode: the server time of time_from_start 0; nullopt: ServerNow() + `delay`.
  std::optional<TimePoint> start;
  Duration delay = std::chrono::milliseconds(100);
  /// The points' deadline (ClientOptions::max_late's values); nullopt: ClientOptions::max_late.
  std::optional<Duration> max_late;
};

/// How far a running sequence is (SequenceHooks::on_progress).
struct SequenceProgress {
  std::size_t answered = 0;  ///< frames whose reply is in
  std::size_t total = 0;
  Duration elapsed{0};   ///< since the sequence's offset 0 (delay mode: negative before it)
  Duration duration{0};  ///< the last frame's offset
};

/// What a caller watching a running sequence gets, and how it ends one early
/// (the robotalk CLI: replies printed as they come, a progress bar, Ctrl-C).
/// The callbacks run on the thread that called RunSequence.
struct SequenceHooks {
  /// Each frame's reply as it is collected: delay and playback in the order
  /// given, direct in offset order (the order they are sent).
  std::function<void(std::size_t index, const Reply& reply)> on_reply;
  /// Called about every `progress_every` while the sequence runs.
  std::function<void(const SequenceProgress& progress)> on_progress;
  Duration progress_every = std::chrono::milliseconds(50);
  /// A stop request ends RunSequence at once (no further frame sent or
  /// waited for; SequenceResult::stopped). It stops nothing on the robot:
  /// send STOP yourself; SequenceResult::queued lists what a delay sequence
  /// still has queued on the server.
  std::stop_token stop;
  /// Waits for each reply however long its command runs, as long as the
  /// server acknowledges the package (a dead server still ends the wait once
  /// the client gives up retransmitting), instead of at most
  /// ClientOptions::timeout after the frame's start.
  bool wait_until_given_up = false;
  /// A frame whose outcome is unknown (UnknownOutcomeError) is listed in
  /// SequenceResult::unknown_outcomes and the others are still waited for,
  /// instead of RunSequence throwing.
  bool collect_unknown_outcomes = false;
};

struct SequenceResult {
  /// One per frame, in the order given. A frame without a reply (stopped
  /// early, or of unknown outcome) keeps a default Reply with id 0.
  std::vector<Reply> replies;
  TimePoint first_sent{};                  ///< client clock, when the first frame left
  std::optional<TimePoint> server_start;   ///< server time of offset 0 (delay, playback)
  std::optional<Duration> playback_delay;  ///< playback: the delay the server chose after its first frame
  bool stopped = false;                    ///< SequenceHooks::stop ended it
  std::size_t frames_sent = 0;
  /// Stopped, delay mode: the server start time of every frame sent and not
  /// answered whose start had not come (it is still queued on the server).
  std::vector<TimePoint> queued;
  /// SequenceHooks::collect_unknown_outcomes: each frame of unknown outcome and why.
  std::vector<std::pair<std::size_t, std::string>> unknown_outcomes;
};

/// A robot offered by a server, from its announce message.
struct AnnouncedRobot {
  std::string name;
  std::string driver;
  std::uint64_t config_hash = 0;
  int total_dofs = 0;
  BaseType base_type = BaseType::kFixed;  ///< of its first root
  bool panic = false;
  int num_clients = 0;
  std::int64_t server_id = 0;
  std::string url_hint;
  /// A keyed server's key ("ed25519:<64 hex>"), which signed this
  /// announcement (verified); "" for an unsigned one (open mode). Compare it
  /// with a pin (known_servers.h): anyone can sign with a key of their own.
  std::string server_key;
};

/// The key of `options.server_key_file` (nullopt when none is set); throws
/// ClientError naming the file when it cannot be read.
std::optional<PublicKey> ExplicitServerKey(const ClientOptions& options);

/// The most robots ListRobots returns: a LAN's robots fit many times over,
/// while anyone on the bus can announce a thousand names per datagram.
inline constexpr std::size_t kMaxListedRobots = 1024;

/// Listens to ROBOTALK/ANNOUNCE for `listen` and returns every robot heard,
/// once per (server id, name), sorted by name. Servers announce once a second.
/// An announcement whose signature suffix does not verify is dropped; with
/// `options.server_key_file` set, so is every announcement that key did not
/// sign (before the bound below: others' names cannot crowd its robots out).
/// At most kMaxListedRobots, the first heard; each further (server id, name)
/// heard is counted in `*unlisted` (if given; a name heard twice counts twice)
/// so a caller can say the bus carries more names than it lists — a flood.
std::vector<AnnouncedRobot> ListRobots(const ClientOptions& options, Duration listen,
                                       std::size_t* unlisted = nullptr);

/// Client counters, for diagnostics and tests.
struct ClientStats {
  std::uint64_t packages_sent = 0;  ///< first sends (heartbeats and clock samples included)
  std::uint64_t retransmissions = 0;
  std::uint64_t heartbeats = 0;
  std::uint64_t replies_filed = 0;
  std::uint64_t replies_ignored = 0;     ///< duplicates, unknown ids
  std::uint64_t malformed_packages = 0;  ///< undecodable reply packages dropped
  std::uint64_t gave_up = 0;             ///< packages abandoned
  std::uint64_t sessions_opened = 0;     ///< hellos answered with a session
  std::uint64_t sessions_lost = 0;       ///< the server no longer knew the session (restart, expiry)
  std::uint64_t replies_refused = 0;     ///< keyed: replies whose MAC or (SESSION_UNKNOWN) signature failed
  /// Keyed: STATE and CONFIG messages dropped: unsigned, signed by another
  /// key or server instance, forged, or (STATE) not newer than the last one.
  std::uint64_t broadcasts_refused = 0;
  std::uint64_t servers_refused = 0;    ///< keyed: hello answers of a server key this client does not trust
  std::size_t configs_cached = 0;       ///< robot descriptions held (bounded: docs/client.md)
  std::size_t config_bytes_cached = 0;  ///< their encoded size
  // Added 2026-11-27, at the end so that the fields before keep their offsets.
  /// Playback redundancy: second copies of playback packages sent.
  std::uint64_t playback_copies = 0;
  /// Messages the link lost (either way), as the client counts them: a
  /// package's copies minus its acks, once every ack had time to come.
  std::uint64_t messages_lost = 0;
  /// Clock samples taken (CLOCK round trips that counted: Connect's, a
  /// restart's, and one every ClientOptions::clock_refresh_interval).
  std::uint64_t clock_samples = 0;
};

class RobotClient {
 public:
  /// Opens LCM and starts the ReadDaemon. Throws ClientError when LCM cannot
  /// be initialised.
  explicit RobotClient(ClientOptions options = {});
  /// Stops the ReadDaemon (joins it) and fails every pending wait with
  /// ClientError... as a TimeoutError-free "client closed" failure. Sends
  /// nothing: in particular, no STOP (the server's watchdog stops a robot
  /// whose client went quiet).
  ~RobotClient();
  RobotClient(const RobotClient&) = delete;
  RobotClient& operator=(const RobotClient&) = delete;
  RobotClient(RobotClient&&) = delete;
  RobotClient& operator=(RobotClient&&) = delete;

  /// Connects to `robot`: subscribes its REPLY channel, synchronises the
  /// clocks (`clock_sync_rounds` CLOCK queries) and loads its configuration
  /// (CONFIG query; the description is cached in memory by hash). Throws
  /// TimeoutError when the robot does not answer within `connect_timeout`,
  /// ClientError when already connected, ProtocolError/ModelError for a bad
  /// description.
  void Connect(const std::string& robot);
  bool connected() const;
  const std::string& robot() const;
  std::int64_t client_id() const;

  /// The connected robot's description. REQUIRES: connected.
  const RobotModel& model() const;
  /// Re-reads the configuration (CONFIG query) and returns it.
  const RobotModel& ReloadModel();

  // --- Clock -----------------------------------------------------------------
  /// Server clock now (estimated), and conversions of client <-> server time.
  TimePoint ServerNow() const;
  TimePoint ServerTime(TimePoint client_time) const;
  TimePoint ClientTime(TimePoint server_time) const;
  /// server − client, and the round trip of the sample it came from.
  Duration clock_offset() const;
  Duration clock_round_trip() const;
  /// Runs `rounds` more CLOCK round trips (keeps the best sample overall).
  void SyncClock(int rounds);

  // --- Blocking calls ----------------------------------------------------------
  /// Sends one command (the client assigns its id; `command.id` is ignored) and
  /// waits for its final reply. `start_time` is on the SERVER clock (use
  /// ServerNow() + delay); nullopt = now.
  Reply Execute(Command command);
  Reply Query(QueryType type, const std::string& target = "");
  Reply Query(robotalk::Query query);
  /// What became of command `id` of this client's current session (after an
  /// UnknownOutcomeError from giving up): its own final reply once it ended,
  /// BUSY while it waits or runs, NA when the session never received it;
  /// CommandStatusOf(reply, id) (robotalk/command_status.h) tells those from a command
  /// that ended BUSY or NA. A session lost to a server restart cannot be asked
  /// (docs/protocol.md, Sessions).
  Reply CommandStatus(CommandId id);
  /// The server's refusal counters (values; the message names them).
  Reply ServerCounters();

  // --- Non-blocking calls ----------------------------------------------------
  PendingReply Send(Command command);
  PendingReply SendQuery(robotalk::Query query);
  /// Several commands in ONE package (executed in start-time order by the
  /// server). `mode` is the package mode the server and a recording see
  /// (docs/protocol.md, Modes): kDelay for commands stamped ahead on the
  /// synchronised server clock, as a delay sequence sent piece by piece
  /// (`robotalk send --file`); kPlayback is RunSequence's only (it declares
  /// the sequence) and throws ClientError. Throws ClientError when the
  /// package would exceed ~60 KB, ProtocolError for an offset start time
  /// (StartTime::After).
  std::vector<PendingReply> SendBatch(std::vector<Command> commands, CommandMode mode = CommandMode::kDirect);

  // --- Command modes (docs/client.md, "Modes") ---------------------------------
  /// Sends `frames` in `options.mode` and waits for every reply (each at most
  /// ClientOptions::timeout after its start, unless `hooks` say otherwise);
  /// each wait wakes at once when its reply arrives. Returns the replies in
  /// the order given. Every package carries its frames' interpolation
  /// (TimedCommand::interpolation, else SequenceOptions::interpolation).
  /// Throws TimeoutError, UnknownOutcomeError, ClientError (also for an
  /// interpolation other than step in direct mode, or two in one playback
  /// sequence, before anything is sent).
  SequenceResult RunSequence(std::vector<TimedCommand> frames, const SequenceOptions& options,
                             const SequenceHooks& hooks = {});

  // --- Trajectories (docs/client.md, "Trajectories") -----------------------------
  /// Sends a joint's or a control frame's waypoints at once, every package
  /// carrying `options.interpolation` and each point's velocities and
  /// accelerations; non-blocking. Returns one PendingReply per point, in
  /// order: each is answered at its time (SUCCESS when the trajectory passes
  /// it, MODIFIED when time-scaled or clamped to a limit, INTERRUPTED when
  /// replaced). Points of a trajectory the server already runs splice into
  /// it (docs/protocol.md, Trajectories). Throws ClientError naming the point
  /// and the value for a bad argument (no points, a negative or not
  /// increasing time, a wrong number of positions, velocities or
  /// accelerations, NaN, an unknown joint or frame, mode kDirect), and when
  /// not connected; nothing is sent then.
  std::vector<PendingReply> SendTrajectory(const JointTrajectory& trajectory,
                                           const TrajectoryOptions& options = {});
  std::vector<PendingReply> SendTrajectory(const FrameTrajectory& trajectory,
                                           const TrajectoryOptions& options = {});
  /// The same, blocking: waits for every point's reply as RunSequence does
  /// (`hooks` as there). Throws as SendTrajectory and RunSequence do.
  SequenceResult RunTrajectory(const JointTrajectory& trajectory, const TrajectoryOptions& options = {},
                               const SequenceHooks& hooks = {});
  SequenceResult RunTrajectory(const FrameTrajectory& trajectory, const TrajectoryOptions& options = {},
                               const SequenceHooks& hooks = {});

  /// Broadcast mode: asks the server to publish the robot's state every
  /// `period` on ROBOTALK/<robot>/STATE (one stream per robot, shared with
  /// every other subscriber, at the shortest period anyone asked for) and
  /// calls `on_sample` with each sample, on the ReadDaemon thread (keep it
  /// short). Returns the period the stream runs at. Calling it again changes
  /// the period and the callback.
  /// A sample that does not decode or validate (wrong dof count, NaN, ...) is
  /// counted in ClientStats::malformed_packages and not passed on.
  Duration StartStateStream(Duration period, std::function<void(const StateSample&)> on_sample);
  /// Cancels this client's stream request (the stream goes on while others want it).
  void StopStateStream();

  // --- Panic -----------------------------------------------------------------
  /// Sends a panic package and waits for its acknowledgement (TimeoutError
  /// after `timeout`). Every command of every client is refused until
  /// ResetPanic(). Throws PanicRefusedError when the server answered that it
  /// did not take it; keyed, a session the server no longer knows (a restart)
  /// is no refusal: it says hello and sends the panic again until `timeout`.
  void Panic();
  /// PANIC_RESET; returns its reply.
  Reply ResetPanic();

  // --- Convenience (blocking; `start` on the server clock) ---------------------
  Reply SetJoint(const std::string& joint, std::vector<double> positions,
                 std::optional<TimePoint> start = std::nullopt);
  Reply JointSpeed(const std::string& joint, std::vector<double> velocities,
                   std::optional<TimePoint> start = std::nullopt);
  Reply Goto(double x, double y, double theta, std::optional<TimePoint> start = std::nullopt);
  Reply SetSpeed(double v, double omega, std::optional<TimePoint> start = std::nullopt);
  Reply Stop(std::optional<TimePoint> start = std::nullopt);
  /// JOINT_STATE of every dof (or one joint): positions, velocities, efforts.
  Reply JointState(const std::string& joint = "");
  /// BASE_POSE: x y θ v ω.
  Reply BasePose();

  ClientStats stats() const;
  const ClientOptions& options() const;
  /// Keyed mode: the server key this client trusts and why (after Connect).
  TrustedServer trusted_server() const;

 private:
  std::vector<PendingReply> SendFrames(std::vector<TimedCommand> frames, const TrajectoryOptions& options);
  class Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace robotalk
