// The interface a robot or simulator implements to be served by RoboTalk, and
// the registry of drivers by name. The server core does all networking,
// queuing, timing, STOP, halt and panic handling; a driver only moves the robot.
//
// What the server guarantees before each call (so a driver need not re-check):
// - Every method is called from one thread, the robot's RobotDaemon, never
//   concurrently: a driver needs no locking of its own.
// - Execute() receives only motion commands (JOINT_SETPOINT / JOINT_SPEED /
//   JOINT_FORCE / FRAME_SETPOINT / GOTO / SETSPEED): STOP arrives as Stop(),
//   the watchdog's stop of a vanished client's actuators as StopOnly(),
//   panic as Halt(), PANIC_RESET as Resume(). The command was checked against
//   model() (robotalk::CheckCommand): `target` is a valid joint (JOINT_*) or
//   control-frame (FRAME_SETPOINT) index, never a mimic follower, and the
//   joint or frame declares that servo type; `num_values` is the joint's dof
//   count, 7 for FRAME_SETPOINT, 3 for GOTO, 2 or 3 for SETSPEED; every value
//   is finite. Between Halt() and Resume() Execute() is never called.
// - `now` never goes backwards between calls.
//
// What a driver may do: answer a DriverResult (any signal; in_progress for a
// command that takes time), append Completions, or throw (any std::exception).
// A throw is contained by the server: the command answers ERROR naming the
// driver, the call and the message, the robot is halted (Halt(), itself
// guarded) and held in panic until PANIC_RESET, and every other robot keeps
// serving. A call that runs longer than the server's --driver-call-bound is
// treated the same way as soon as the bound passes (the call's late result is
// discarded).
//
// Real-time: the RobotDaemon is the real-time path. Execute(), Stop(), StopOnly(),
// Update() and ReadState() must not block on I/O for longer than a control
// period and should not allocate (the output vectors come preallocated;
// push_back within their capacity; messages of non-SUCCESS answers may
// allocate).
#pragma once

#include "robotalk/clock.h"
#include "robotalk/command.h"
#include "robotalk/robot_model.h"

#include <Eigen/Core>
#include <array>
#include <functional>
#include <map>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace robotalk {

/// A command checked against the model (CheckCommand) with its target resolved.
struct DriverCommand {
  CommandId id = 0;
  CommandType type = CommandType::kStop;
  int target = -1;  ///< joint index (JOINT_*), frame index (FRAME_SETPOINT), else -1
  int num_values = 0;
  std::array<double, 7> values{};  ///< the first num_values are used
};

/// What Execute() answers.
struct DriverResult {
  Signal signal = Signal::kSuccess;
  /// True when the command keeps running (a GOTO on its way): its final signal
  /// comes later as a Completion from Update() or Halt(); `signal` is ignored.
  bool in_progress = false;
  std::string message;  ///< why, for MODIFIED / NA / BUSY / INTERRUPTED / ERROR
};

/// The final outcome of a command that was in progress, or of one it pre-empted.
struct Completion {
  CommandId id = 0;
  Signal signal = Signal::kSuccess;
  std::string message;
};

/// Part of the robot for StopOnly(): what one client moved (the server's
/// watchdog stops it when that client vanishes). Views the server's own
/// storage, valid for the call only.
struct StopScope {
  /// Joint indices (RobotModel::joint), each at most once; only joints with
  /// dofs. A mimic follower may appear (it follows its leader whatever is
  /// done to it).
  std::span<const int> joints;
  /// The base (the first root), its speed and a task on it (a GOTO: it
  /// completes INTERRUPTED).
  bool base = false;
};

/// Where a joint should be at a time: a trajectory's sample (issue 22,
/// docs/drivers.md "Following a trajectory"). Views the server's storage,
/// valid for the call only; one value per dof of the joint each.
struct JointReference {
  int joint = -1;                        ///< RobotModel::joint index; never a mimic follower
  std::span<const double> position;      ///< rad | m, within the dof's limits
  std::span<const double> velocity;      ///< rad/s | m/s, within the velocity limit
  std::span<const double> acceleration;  ///< rad/s² | m/s², within the server's acceleration limit
};

/// Where the base's speed should be: a SETSPEED ramp's sample (issue 22,
/// docs/drivers.md "Following a base speed ramp"). The body twist of the
/// first root, as SETSPEED gives it.
struct BaseReference {
  double vx = 0.0;     ///< forward speed, m/s
  double vy = 0.0;     ///< lateral speed, m/s (0 unless a frame gave vx vy ω)
  double omega = 0.0;  ///< yaw rate, rad/s
  /// The twist's rate toward the ramp one period on (m/s², rad/s²), within
  /// the server's base acceleration limit: for a driver that interpolates
  /// within the period. The twist is the reference from now on.
  double ax = 0.0, ay = 0.0, alpha = 0.0;
  bool lateral = false;  ///< the frame gave vy (3 values): Track's default sends "vx vy ω", else "v ω"
};

/// The robot's measured state. Sized by the server from the model once.
struct RobotState {
  Eigen::VectorXd position;      ///< per dof (rad | m)
  Eigen::VectorXd velocity;      ///< per dof (rad/s | m/s)
  Eigen::VectorXd effort;        ///< per dof (N·m | N)
  std::vector<Pose> root_poses;  ///< per RobotModel::roots() entry, in the world
  double base_v = 0.0;           ///< forward speed of the first root, m/s
  double base_omega = 0.0;       ///< yaw rate of the first root, rad/s
  double base_vy = 0.0;          ///< lateral speed of the first root (body frame), m/s
  bool moving = false;           ///< any actuator or the base is commanded to move
};

class Driver {
 public:
  virtual ~Driver() = default;

  /// The robot this driver moves.
  virtual const RobotModel& model() const = 0;
  /// Period at which the RobotDaemon calls Update().
  virtual Duration period() const = 0;

  /// Starts the motion `command` at `now`. Instant commands answer their
  /// final signal; commands that take time answer in_progress and complete
  /// later. A command this one pre-empts gets a Completion (INTERRUPTED) in
  /// `completed`. REQUIRES: the guarantees above (checked, motion, not halted).
  virtual DriverResult Execute(const DriverCommand& command, TimePoint now,
                               std::vector<Completion>& completed) = 0;
  /// STOP at `now`: every actuator and the base come to rest (and hold);
  /// every command in progress completes INTERRUPTED (appended). Also called
  /// by the server at shutdown (the last call a driver gets), when it gives
  /// up a robot another server serves, and after a Halt() that threw. (The
  /// watchdog calls StopOnly().)
  virtual void Stop(TimePoint now, std::vector<Completion>& interrupted) = 0;
  /// A STOP of part of the robot at `now`, which cannot be refused: the
  /// joints of `scope` come to rest and hold; with `scope.base` the base
  /// comes to rest and a task on it (a GOTO in progress) completes
  /// INTERRUPTED (appended). Everything else -- another client's joint, its
  /// GOTO -- runs on. Called by the server's watchdog for a vanished client.
  /// Default: Stop(now, interrupted), i.e. everything stops: stopping more
  /// than asked is safe, stopping less is not. A driver that overrides it
  /// must stop at least the scope, also while a task runs (a GOTO that
  /// refuses SETSPEED with BUSY must still be interrupted here).
  virtual void StopOnly(const StopScope& /*scope*/, TimePoint now, std::vector<Completion>& interrupted) {
    Stop(now, interrupted);
  }
  /// Follows `reference` from `now` on: called every control period, just
  /// before Update(now), for each joint whose trajectory is active (a
  /// JOINT_SETPOINT waypoint of an interpolated package), until the
  /// trajectory has come to rest. The server samples the trajectory; the
  /// driver tracks it (the kinematic driver exactly; the ODE driver with its
  /// servo and velocity feed-forward). Not called between Halt() and Resume().
  /// A non-SUCCESS/MODIFIED answer ends the joint's trajectory, its waypoints
  /// answered with it. Default: a JOINT_SETPOINT of the reference's position,
  /// which the driver chases as any set-point (so a driver that does not
  /// override this still moves through the waypoints, a period behind).
  virtual DriverResult Track(const JointReference& reference, TimePoint now,
                             std::vector<Completion>& completed);
  /// Drives the base at `reference` from `now` on: called every control
  /// period, just before Update(now), while a SETSPEED ramp is active (the
  /// timed SETSPEED frames of an interpolated package, which the server
  /// ramps within its base acceleration limit). After the last call the
  /// base keeps the last twist, as after a SETSPEED. Not called between
  /// Halt() and Resume(); STOP, panic, the watchdog, a GOTO and a step
  /// SETSPEED end the ramp first. A non-SUCCESS/MODIFIED answer ends the
  /// ramp (its frames answer INTERRUPTED naming the driver's reason); a
  /// MODIFIED one's message goes to the frame being approached. Default: a
  /// SETSPEED of the reference's twist ("v ω", or "vx vy ω" when
  /// `reference.lateral`), through Execute(), so a driver that does not
  /// override this drives the ramp as a staircase of one twist per period.
  virtual DriverResult TrackBase(const BaseReference& reference, TimePoint now,
                                 std::vector<Completion>& completed);
  /// Advances the robot to `now` (one period after the previous call);
  /// appends the completions of commands that finished.
  virtual void Update(TimePoint now, std::vector<Completion>& completed) = 0;
  /// Fills `state` (already sized for the model).
  virtual void ReadState(RobotState& state) const = 0;
  /// Panic (or a driver fault): stop every actuator at once. Every command in
  /// progress completes INTERRUPTED (appended). The server calls no Execute()
  /// until Resume().
  virtual void Halt(std::vector<Completion>& interrupted) = 0;
  /// Panic reset: the robot stays where it is; Execute() may follow.
  virtual void Resume() = 0;
  /// A condition the robot is in that must stop it, in words (e.g. "the robot
  /// has fallen (torso tilt 0.71 rad)"); "" = none. Asked after every
  /// Update(). The server treats a new one as a driver fault: the robot is
  /// halted and held in panic until PANIC_RESET, the STATE stream says panic,
  /// queries and refused commands name it. The same text again after a reset
  /// does not halt again. Default: none. The text must stay valid until the
  /// driver's next call: keep it in a member, so that asking every period
  /// never allocates (the RobotDaemon's loop does not).
  virtual std::string_view Fault() const { return {}; }
};

/// What a driver factory receives.
struct DriverConfig {
  std::string robot_name;
  std::string urdf_path;                       ///< the file the model came from
  std::map<std::string, std::string> options;  ///< driver-specific key=value options
};

/// Drivers by name ("kinematic", "ode"). Not thread-safe: fill it at start-up.
class DriverRegistry {
 public:
  using Factory = std::function<std::unique_ptr<Driver>(const DriverConfig&)>;

  void Register(const std::string& name, Factory factory);
  /// Throws Error "unknown driver 'x' (known: kinematic, ode)".
  std::unique_ptr<Driver> Create(const std::string& name, const DriverConfig& config) const;
  std::vector<std::string> names() const;

 private:
  std::map<std::string, Factory> factories_;
};

}  // namespace robotalk
