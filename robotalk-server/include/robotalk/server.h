// The RoboTalk server: serves one or more robots, each bound to a driver, on
// one transport (LCM by default; docs/protocol.md, docs/architecture.md).
//
// Threads: one ServerDaemon (receives and decodes packages, keeps the client
// sessions, admits commands, sends replies and state, announces, runs the
// watchdogs) and one RobotDaemon per robot (owns the driver, executes
// commands at their start times). Start() launches them; Stop() or the
// destructor stops every robot's motion and joins them.
#pragma once

#include "robotalk/clock.h"
#include "robotalk/command.h"
#include "robotalk/driver.h"
#include "robotalk/transport.h"

#include <map>
#include <memory>
#include <string>
#include <vector>

namespace robotalk {

/// One robot to serve: `--robot NAME=DRIVER:URDF[,key=value...]`.
struct RobotSpec {
  std::string name;
  std::string driver;
  std::string urdf_path;
  std::map<std::string, std::string> options;

  /// Parses "pioneer=kinematic:models/p.urdf,period_ms=5". Throws Error naming what is wrong.
  static RobotSpec Parse(const std::string& text);
};

/// The default of --max-sessions (ServerOptions::max_sessions).
inline constexpr std::size_t kDefaultMaxSessions = 1024;
/// The default of --max-sessions-per-robot (ServerOptions::max_sessions_per_robot).
inline constexpr std::size_t kDefaultMaxSessionsPerRobot = 256;
/// The defaults of --session-timeout, --max-queue, --max-future and
/// --max-late (ServerOptions); the session layer's own options start from
/// the same values.
inline constexpr Duration kDefaultSessionTimeout = std::chrono::seconds(2);
inline constexpr std::size_t kDefaultMaxQueue = 10000;
inline constexpr Duration kDefaultMaxFuture = std::chrono::hours(1);
/// --max-late for servo commands: 0.1 s, drake-franka-driver's --expire_sec
/// default (docs/server.md, Deadlines says why).
inline constexpr Duration kDefaultMaxLate = std::chrono::milliseconds(100);

/// A mobile base's acceleration limit for SETSPEED ramps (the SETSPEED frames
/// of interpolated packages; docs/server.md, "Base speed ramps"). The
/// defaults are a Clearpath Husky's, as its diff_drive_controller ships them.
struct BaseAccelerationLimit {
  double linear = 3.0;   ///< m/s², of the planar speed (> 0)
  double angular = 6.0;  ///< rad/s², of the yaw rate (> 0)
};

struct ServerOptions {
  /// LCM provider URL; "" uses LCM's default (or $LCM_DEFAULT_URL).
  std::string lcm_url;
  /// A client session silent for this long expires; the robot is stopped if it moved it.
  Duration session_timeout = kDefaultSessionTimeout;
  /// Most commands one client may have queued.
  size_t max_queue = kDefaultMaxQueue;
  /// Most commands all clients may have queued in the whole server; each
  /// robot gets an equal part, half of it as every client's guaranteed
  /// share (docs/protocol.md, Bounds).
  size_t max_queued_total = 65536;
  /// Start times further ahead than this, or further in the past, are
  /// refused with ERROR.
  Duration max_future = kDefaultMaxFuture;
  /// Deadlines (issue 23; docs/server.md, Deadlines): how late after its
  /// start time a timed servo command may still begin when its package gives
  /// no limit (`--max-late S`); Duration::max() = never. `robot_max_late`
  /// overrides it per robot name (`--max-late NAME=S`).
  Duration max_late = kDefaultMaxLate;
  std::map<std::string, Duration> robot_max_late;
  /// Link health (docs/server.md): stop what a session owns when its link
  /// passes a stop threshold (`--link-stop`; off by default).
  bool link_stop = false;
  /// A GOTO target farther than this from the world origin (m) is refused
  /// with ERROR naming both (robotalk::CommandLimits).
  double max_goto_distance = kDefaultMaxGotoDistance;
  /// The acceleration limit of every dof's trajectory (interpolated
  /// waypoints: time-scaling and the hold after the last one), rad/s² or
  /// m/s² (`--max-acceleration`; docs/protocol.md, Trajectories).
  double max_acceleration = 20.0;
  /// The base acceleration limit of SETSPEED ramps
  /// (`--max-base-acceleration LIN[,ANG]`); `robot_base_acceleration`
  /// overrides it per robot name (`--max-base-acceleration NAME=LIN[,ANG]`).
  BaseAccelerationLimit base_acceleration;
  std::map<std::string, BaseAccelerationLimit> robot_base_acceleration;
  /// Print one stderr line per executed command (diagnostics).
  bool log_executions = false;
  /// A driver call running longer than this is a driver fault: its command
  /// answers ERROR and the robot is held in panic (0 = no bound).
  Duration driver_call_bound = std::chrono::seconds(2);
  /// Most server log lines per second; the rest are counted and summarised.
  int log_lines_per_second = 20;
  /// The panic latch (docs/server.md): a file that keeps which robots are in
  /// panic, so a panic survives a restart. `panic_latch_path` names it; when
  /// that is "" and `state_dir` is not, it is the file for this server's LCM
  /// network in `state_dir` (created, mode 0700): "<state_dir>/panic-latch.
  /// udpm-239.255.76.67-7667". Both "" = no latch (robotalk-server's command
  /// line defaults `state_dir` to PanicLatch::DefaultStateDir(); only
  /// --no-panic-latch leaves both empty). The Server constructor throws
  /// Error naming the file or directory when it cannot be created or written.
  std::string panic_latch_path;
  std::string state_dir;
  /// Serve a robot even when another server announces the same name.
  bool allow_duplicate_robots = false;
  /// Keyed mode (docs/security.md): the server's secret key file and the
  /// access list of client keys and rights. Both or neither; neither = open
  /// mode (any process on the LAN may command the robots).
  std::string key_file;
  std::string clients_file;
  /// Most sessions (live and not yet used) in the whole server (`--max-sessions`).
  std::size_t max_sessions = kDefaultMaxSessions;
  /// Most clients one robot serves at once (`--max-sessions-per-robot`).
  std::size_t max_sessions_per_robot = kDefaultMaxSessionsPerRobot;
  /// 1 ns timer slack, a short final spin before each deadline and SCHED_FIFO
  /// for the server's threads where permitted (docs/server.md; costs CPU).
  /// ROBOTALK_PRECISE_TIMING=0 in the environment turns it off too.
  bool precise_timing = true;
  /// Period of the ROBOTALK/ANNOUNCE message. The default is the protocol's
  /// kAnnouncePeriod (channels.h, not installed; server_daemon_test checks
  /// they agree), which clients count their waits for an announcement in.
  Duration announce_period = std::chrono::seconds(1);
  /// The paper's congestion injector (§VI-B): after each received package the
  /// ServerDaemon pauses a random time uniform in [0, this]. 0 = off.
  Duration congestion_max_pause{0};
  /// Frames playback mode waits for before estimating its delay.
  std::size_t playback_min_frames = 5;
  double playback_fraction = 0.1;
  /// How playback's start is decided (docs/server.md, Playback): "adaptive"
  /// (at the first frame, from the worst recent delay; gaps may stretch by
  /// playback_stretch), "quick" (issue 11's quick start, fixed timing) or
  /// "paper" (the paper's estimate only, fixed timing).
  std::string playback_estimator = "adaptive";
  double playback_stretch = 0.10;
  /// Adaptive: a frame that comes after the latest time playback_stretch
  /// allows, or on a FIFO link less than a quarter of the delay spread before
  /// it, may have its gap play up to this much longer (a thin buffer;
  /// PlaybackEstimatorOptions::thin_stretch). 0 (the default: an option,
  /// docs/performance.md "Issue 23, tenth session") or at or below playback_stretch: off.
  double playback_thin_stretch = 0;
  /// Adaptive: a frame plays no sooner than this after it arrived (its
  /// hand-over to the RobotDaemon; PlaybackScheduleOptions::margin).
  Duration playback_margin = std::chrono::milliseconds(2);
  /// Adaptive: delays spread by more than 1.2 frame intervals get the queue
  /// start (a simulated queue of the sequence's frames) when on; off (the
  /// default): the paper's estimate.
  bool playback_queue_start = false;
  /// Adaptive: delays spread by more than 1.2 frame intervals on the link
  /// (the server kept up with its input) whose mean service the 10 %
  /// stretch can follow get the adaptive start at the first frame, and the
  /// gaps stretch until the buffer covers a simulated queue of the
  /// sequence's frames (PlaybackEstimatorOptions::follow_queue); off: the
  /// paper's estimate there. Under --playback-queue-start on, the queue start.
  bool playback_follow_queue = true;
  /// Adaptive: a connect-time package's wait behind the client's package
  /// sent just before it is left out of its delay where that brings the
  /// spread within the gate (PlaybackEstimatorOptions::burst_wait_discount).
  bool playback_burst_discount = true;
  /// Adaptive: wait for the first frame's second copy and then cover the
  /// earlier of two delays (PlaybackEstimatorOptions::copies_start; off by
  /// default: measured in docs/performance.md, issue 23's eleventh session).
  bool playback_copies_start = false;
  /// Adaptive: a retransmitted package's one-way delay (its resend wait
  /// included) counts in the delay history too (SessionOptions::playback_resent_delays;
  /// off, the default: left out).
  bool playback_resent_delays = false;
  /// One log line per playback start with what the estimator decided it from
  /// (PlaybackEstimator::Describe; --log-playback, diagnostics).
  bool log_playback = false;
  /// Adaptive: the start lies this many gaps' stretch (playback_stretch ×
  /// the frame interval each) below the worst delay it covers; the first
  /// gaps' stretch reaches it (PlaybackEstimatorOptions::start_lead). 0: the
  /// start covers it itself.
  double playback_start_lead = 1.0;
  /// Test fault injection on outgoing reply packages (seeded): probability
  /// that one is dropped, and that one is sent twice.
  double reply_drop_probability = 0.0;
  double reply_duplicate_probability = 0.0;
  std::uint64_t fault_seed = 1;
};

class Server {
 public:
  /// Creates every robot's driver from `registry` and serves them on LCM at
  /// `options.lcm_url`. Throws Error naming the robot and what failed
  /// (unknown driver, bad URDF, duplicate robot name, LCM URL).
  Server(ServerOptions options, const std::vector<RobotSpec>& robots, const DriverRegistry& registry,
         const Clock& clock);
  /// The same on a transport of the caller's (in-memory in tests); it must
  /// outlive the Server. `options.lcm_url` is ignored.
  Server(Transport& transport, ServerOptions options, const std::vector<RobotSpec>& robots,
         const DriverRegistry& registry, const Clock& clock);
  ~Server();
  Server(const Server&) = delete;
  Server& operator=(const Server&) = delete;

  void Start();
  /// Stops every robot (STOP), then the threads. Idempotent. A driver call
  /// that hangs is watched against `driver_call_bound` meanwhile (a fault,
  /// latched) and waited for until it has run twice the bound; its robot is
  /// then left without its STOP and named by not_stopped(). Its thread is
  /// detached and may still run should the call return: with not_stopped()
  /// not empty, the clock given to the constructor (and whatever the driver
  /// uses) must live until the process exits (robotalk-server exits at once).
  void Stop();
  /// The robots Stop() could not STOP (their driver call hung); empty before.
  std::vector<std::string> not_stopped() const;

  std::vector<std::string> robot_names() const;
  /// How many robots this server serves: fewer than robot_names() when
  /// another server already served some at start (one robot, one server;
  /// docs/server.md). 0: it serves nothing, and robotalk-server exits.
  /// Thread-safe.
  std::size_t serving() const;
  /// Why each refused robot is refused ("robot 'pioneer' is served by
  /// server ..."). Thread-safe.
  std::vector<std::string> refusals() const;

 private:
  class Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace robotalk
