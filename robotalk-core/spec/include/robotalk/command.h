// Commands, queries and replies as C++ values, and their checks against a
// robot model. Everything a command type means -- its name, wire code,
// target, value counts, servo type, what it owns -- is one row of
// kCommandTraits below; the codec, sequence files, the server's admission
// and ownership, the CLI and the drivers' dispatch read it
// (docs/architecture.md, "Adding a command"). Their wire forms are in
// docs/protocol.md.
#pragma once

#include "robotalk/clock.h"
#include "robotalk/robot_model.h"
#include "robotalk/signal.h"

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace robotalk {

using CommandId = std::int64_t;

/// A command type; its value is its wire code (command_t.lcm's constant of
/// the same name), and its row in kCommandTraits says what it means.
enum class CommandType : std::int8_t {
  kJointSetPoint = 1,  ///< target joint; one position per dof (rad | m)
  kJointSpeed = 2,     ///< target joint; one velocity per dof (rad/s | m/s)
  kJointForce = 3,     ///< target joint; one effort per dof (N·m | N)
  kFrameSetPoint = 4,  ///< target control frame; x y z qw qx qy qz in the world
  kGoto = 5,           ///< base: x y θ in the world (m, m, rad)
  kSetSpeed = 6,       ///< base: v ω, or vx vy ω (m/s, rad/s)
  kStop = 7,           ///< stop every motion
  kPanicReset = 8,     ///< leave the panic state
};

/// What a command addresses: Command::target names a joint or a control
/// frame, or is empty.
enum class CommandTarget : std::int8_t {
  kRobot,  ///< the whole robot (no target name)
  kBase,   ///< the mobile base of the first root link (no target name); NA on a fixed base
  kJoint,  ///< a joint by name: its dofs; owned by the commanding client
  kFrame,  ///< a control frame by name: the joints of its chain are owned
};

/// How the server runs a command.
enum class CommandKind : std::int8_t {
  /// Sets an actuator's reference until the next one; answered at once. A
  /// timed one that starts before a command of its client on the same
  /// actuator that already ran is superseded (INTERRUPTED).
  kServo,
  kTask,     ///< moves toward a goal; answered when it ends (GOTO)
  kStop,     ///< the driver's Stop(): every motion; ends every ownership
  kSession,  ///< acted on by the server when admitted; never queued nor sent to a driver
};

/// Command::values holds one value per dof of the target joint.
inline constexpr std::int8_t kValuesPerDof = -1;

/// Everything that depends on a command type. The consumers switch on these
/// fields, not on the type: a new type is a row here (and its constant in
/// command_t.lcm, and the drivers that execute it).
struct CommandTraits {
  CommandType type;
  const char* name;   ///< ToString(), the wire constant, the sequence-file word (any case)
  const char* alias;  ///< another accepted word, or nullptr
  CommandTarget target;
  CommandKind kind;
  ServoType servo;              ///< what the target joint or frame must accept; kNone for no check
  bool keeps_moving;            ///< moves on until stopped (a speed or force); the CLI's --hold
  std::int8_t min_values;       ///< kValuesPerDof, or a fixed count
  std::int8_t max_values;       ///< == min_values unless two counts are accepted
  const char* value_names;      ///< what min_values are ("x y theta"), for messages; "" for none
  const char* max_value_names;  ///< what max_values are when it differs; "" otherwise
};

inline constexpr auto kCommandTraits = std::to_array<CommandTraits>({
    // clang-format off
    // {type, name, alias, target, kind, servo, keeps_moving, min_values, max_values, value_names, max_value_names}
    {CommandType::kJointSetPoint, "JOINT_SETPOINT", nullptr,     CommandTarget::kJoint, CommandKind::kServo,   ServoType::kSetPoint, false, kValuesPerDof, kValuesPerDof, "", ""},
    {CommandType::kJointSpeed,    "JOINT_SPEED",    nullptr,     CommandTarget::kJoint, CommandKind::kServo,   ServoType::kSpeed,    true,  kValuesPerDof, kValuesPerDof, "", ""},
    {CommandType::kJointForce,    "JOINT_FORCE",    nullptr,     CommandTarget::kJoint, CommandKind::kServo,   ServoType::kForce,    true,  kValuesPerDof, kValuesPerDof, "", ""},
    {CommandType::kFrameSetPoint, "FRAME_SETPOINT", nullptr,     CommandTarget::kFrame, CommandKind::kServo,   ServoType::kSetPoint, false, 7, 7, "x y z qw qx qy qz", ""},
    {CommandType::kGoto,          "GOTO",           nullptr,     CommandTarget::kBase,  CommandKind::kTask,    ServoType::kNone,     false, 3, 3, "x y theta", ""},
    {CommandType::kSetSpeed,      "SETSPEED",       "SET_SPEED", CommandTarget::kBase,  CommandKind::kServo,   ServoType::kNone,     true,  2, 3, "v omega", "vx vy omega"},
    {CommandType::kStop,          "STOP",           nullptr,     CommandTarget::kRobot, CommandKind::kStop,    ServoType::kNone,     false, 0, 0, "", ""},
    {CommandType::kPanicReset,    "PANIC_RESET",    nullptr,     CommandTarget::kRobot, CommandKind::kSession, ServoType::kNone,     false, 0, 0, "", ""},
    // clang-format on
});

/// The row of wire code `code`, or nullptr for a code no command has.
constexpr const CommandTraits* FindCommandTraits(int code) {
  if (code < 1 || code > static_cast<int>(kCommandTraits.size())) return nullptr;
  return &kCommandTraits[static_cast<std::size_t>(code - 1)];
}
/// What Traits() answers for a value that is no command type (a cast in
/// C++; the codec refuses such a code): no target, never queued.
// clang-format off
inline constexpr CommandTraits kUnknownCommandTraits{
    CommandType{0}, "UNKNOWN_COMMAND", nullptr, CommandTarget::kRobot, CommandKind::kSession, ServoType::kNone,
    false, 0, 0, "", ""};
// clang-format on
/// The row of `t` (kUnknownCommandTraits for a value no row has).
constexpr const CommandTraits& Traits(CommandType t) {
  const CommandTraits* row = FindCommandTraits(static_cast<int>(t));
  return row ? *row : kUnknownCommandTraits;
}

/// The table is in wire-code order (so FindCommandTraits indexes it).
constexpr bool CommandTraitsInCodeOrder() {
  for (std::size_t i = 0; i < kCommandTraits.size(); ++i) {
    if (static_cast<std::size_t>(kCommandTraits[i].type) != i + 1) return false;
  }
  return true;
}
static_assert(CommandTraitsInCodeOrder(), "kCommandTraits: row i must hold the command with wire code i + 1");

/// Whether `n` values fit `t` for a target joint of `dofs` dofs.
constexpr bool ValueCountFits(const CommandTraits& t, std::size_t n, std::size_t dofs) {
  if (t.min_values == kValuesPerDof) return n == dofs;
  return n >= static_cast<std::size_t>(t.min_values) && n <= static_cast<std::size_t>(t.max_values);
}
/// The values `t` takes, for messages: "3 values (x y theta)", "2 values (v
/// omega) or 3 (vx vy omega)", "0 values", "one value per dof".
std::string ValueCountText(const CommandTraits& t);

enum class QueryType : std::int8_t {
  kConfig = 1,             ///< the robot description (published on the CONFIG channel)
  kJointState = 2,         ///< positions, velocities, efforts of every dof (or of one joint)
  kLinkPoses = 3,          ///< world pose of every link (or one): x y z qw qx qy qz each
  kFramePoses = 4,         ///< world pose of every control frame (or one)
  kBasePose = 5,           ///< x y θ v ω of the first root link
  kClock = 6,              ///< server time, for clock synchronisation
  kStateStream = 7,        ///< broadcast: robot_state_t on ROBOTALK/<robot>/STATE every `period`
  kStateStreamCancel = 8,  ///< ends this client's STATE_STREAM request
  kCommandStatus = 9,      ///< what became of command `about` in this session
  kServerCounters = 10,    ///< the server's refusal counters (values; message names them)
};

const char* ToString(CommandType t);
const char* ToString(QueryType t);
/// Parses the names printed by ToString ("JOINT_SETPOINT", "GOTO", ...), case-insensitive.
std::optional<CommandType> ParseCommandType(const std::string& name);
std::optional<QueryType> ParseQueryType(const std::string& name);

/// When a command starts: now, at a time on the SERVER clock, or after an
/// offset from the start of a playback sequence. On the wire (a command's
/// start_time_us, docs/protocol.md) these are 0, server-clock micros in a
/// DIRECT/DELAY package, and offset micros in a PLAYBACK package.
///
///   Command c{.type = CommandType::kGoto, .start_time = StartTime::At(client.ServerNow() + 2s), ...};
///
/// A TimePoint converts implicitly to At(t), std::nullopt to Now(), and a
/// std::optional<TimePoint> to either; an offset must be said: After(d).
class StartTime {
 public:
  enum class Kind : std::int8_t { kNow, kAt, kAfter };

  constexpr StartTime() = default;  ///< Now()
  constexpr StartTime(std::nullopt_t) {}
  constexpr StartTime(TimePoint t) : kind_(Kind::kAt), value_(t.time_since_epoch()) {}
  constexpr StartTime(std::optional<TimePoint> t) {
    if (t) *this = StartTime(*t);
  }

  static constexpr StartTime Now() { return StartTime(); }
  /// At `t` on the server clock (DIRECT and DELAY packages).
  static constexpr StartTime At(TimePoint t) { return StartTime(t); }
  /// `offset` after the sequence start (PLAYBACK packages). REQUIRES offset >= 0.
  static constexpr StartTime After(Duration offset) {
    StartTime s;
    s.kind_ = Kind::kAfter;
    s.value_ = offset;
    return s;
  }

  constexpr Kind kind() const { return kind_; }
  constexpr bool is_now() const { return kind_ == Kind::kNow; }
  constexpr bool is_at() const { return kind_ == Kind::kAt; }
  constexpr bool is_after() const { return kind_ == Kind::kAfter; }
  /// The server-clock time of At(); nullopt for the other kinds.
  constexpr std::optional<TimePoint> time() const {
    return is_at() ? std::optional<TimePoint>(TimePoint(value_)) : std::nullopt;
  }
  /// The offset of After(); nullopt for the other kinds.
  constexpr std::optional<Duration> offset() const {
    return is_after() ? std::optional<Duration>(value_) : std::nullopt;
  }
  /// Back to Now().
  constexpr void reset() { *this = StartTime(); }

  constexpr bool operator==(const StartTime&) const = default;

 private:
  Kind kind_ = Kind::kNow;
  Duration value_{0};
};

/// "now", "at 12.5 s", "after 0.3 s" (server-clock seconds), for messages.
std::string ToString(const StartTime& s);

/// How many velocity (or acceleration) values a waypoint of `t` carries for
/// a target joint of `dofs` dofs: one per dof (JOINT_SETPOINT), 6 for a
/// FRAME_SETPOINT (vx vy vz wx wy wz in the world), 0 for a command that is
/// never a waypoint.
constexpr std::size_t WaypointRateCount(CommandType t, std::size_t dofs) {
  if (t == CommandType::kJointSetPoint) return dofs;
  if (t == CommandType::kFrameSetPoint) return 6;
  return 0;
}

struct Command {
  CommandId id = 0;
  CommandType type = CommandType::kStop;
  StartTime start_time;
  std::string target;  ///< joint or control-frame name; empty for base / whole-robot commands
  std::vector<double> values;
  /// A waypoint's velocity and acceleration (JOINT_SETPOINT, FRAME_SETPOINT
  /// in an interpolated package): empty = chosen by the server's trajectory
  /// (trajectory.h); else WaypointRateCount values. A step package ignores them.
  std::vector<double> velocities;
  std::vector<double> accelerations;
};

struct Query {
  CommandId id = 0;
  QueryType type = QueryType::kJointState;
  std::string target;   ///< one joint / link / frame name, or empty for all
  Duration period{0};   ///< STATE_STREAM: the sampling period
  CommandId about = 0;  ///< COMMAND_STATUS: the command asked about
};

/// Shortest and longest broadcast periods a server accepts.
inline constexpr Duration kMinStreamPeriod = std::chrono::milliseconds(1);
inline constexpr Duration kMaxStreamPeriod = std::chrono::hours(1);

struct Reply {
  CommandId id = 0;
  Signal signal = Signal::kSuccess;
  std::string message;
  TimePoint exec_time{};
  Duration lateness{0};
  std::vector<double> values;
};

/// True for the commands that move the robot (servos and tasks: all but STOP and PANIC_RESET).
constexpr bool IsMotionCommand(CommandType t) {
  const CommandKind k = Traits(t).kind;
  return k == CommandKind::kServo || k == CommandKind::kTask;
}

/// The default of CommandLimits::max_goto_distance (m).
inline constexpr double kDefaultMaxGotoDistance = 100.0;

/// The largest magnitude of any number a command carries (a value, a
/// waypoint's velocity or acceleration): no robot's joint range, speed,
/// effort or pose coordinate comes near it, and within it a trajectory's or
/// a speed ramp's arithmetic cannot overflow (a finite 1e308 rad/s made the
/// plan NaN and halted the robot in panic). Beyond it CheckCommand refuses.
inline constexpr double kMaxCommandMagnitude = 1e9;

/// What a server allows beyond the model (robotalk-server's options).
struct CommandLimits {
  /// A GOTO target (x, y) farther than this from the world origin is refused
  /// with ERROR: the workspace of a base, in m (--max-goto-distance).
  double max_goto_distance = kDefaultMaxGotoDistance;
};

/// Checks a command against a model and the server's limits before it is
/// queued: nullopt when well-formed, else the refusal — kError for a
/// malformed request ("JOINT_SETPOINT: robot 'pioneer' has no joint named
/// 'nek'", "JOINT_SETPOINT 'pan_tilt': expected 2 values (one per dof), got
/// 3", "JOINT_SETPOINT 'pan_tilt': value 1 is NaN", "GOTO: target (1e+308,
/// 0) m is 1e+308 m from the world origin; the bound is 100 m",
/// "JOINT_SETPOINT 'elbow': velocity 0 is 1e+308, beyond ±1e+09"), kNa for a
/// servo type or base command the robot does not support. The one check for
/// every driver.
std::optional<Refusal> CheckCommand(const RobotModel& model, const Command& command,
                                    const CommandLimits& limits = {});

/// Same for queries (unknown target names, a STATE_STREAM period out of range): kError.
std::optional<Refusal> CheckQuery(const RobotModel& model, const Query& query);

}  // namespace robotalk
