// The interface a robot or simulator implements to be served by RoboTalk, and
// the registry of drivers by name. The server core does all networking,
// queuing, timing and panic handling; a driver only moves the robot.
//
// Threading contract: the server calls every method of a Driver from one
// thread, its RobotDaemon, so a driver needs no locking of its own. The
// RobotDaemon is the real-time path: Execute(), Update() and ReadState() must
// not block on I/O for longer than a control period and should not allocate
// (the output vectors come preallocated; push_back within their capacity).
#pragma once

#include "robotalk/clock.h"
#include "robotalk/command.h"
#include "robotalk/robot_model.h"

#include <Eigen/Core>
#include <array>
#include <functional>
#include <map>
#include <memory>
#include <string>
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

/// The robot's measured state. Sized by the server from the model once.
struct RobotState {
  Eigen::VectorXd position;      ///< per dof (rad | m)
  Eigen::VectorXd velocity;      ///< per dof (rad/s | m/s)
  Eigen::VectorXd effort;        ///< per dof (N·m | N)
  std::vector<Pose> root_poses;  ///< per RobotModel::roots() entry, in the world
  double base_v = 0.0;           ///< forward speed of the first root, m/s
  double base_omega = 0.0;       ///< yaw rate of the first root, rad/s
  bool moving = false;           ///< any actuator or the base is commanded to move
};

class Driver {
 public:
  virtual ~Driver() = default;

  /// The robot this driver moves.
  virtual const RobotModel& model() const = 0;
  /// Period at which the RobotDaemon calls Update().
  virtual Duration period() const = 0;

  /// Starts `command` at `now`. Instant commands answer their final signal;
  /// commands that take time answer in_progress and complete later. A command
  /// this one pre-empts gets a Completion (INTERRUPTED) in `completed`.
  virtual DriverResult Execute(const DriverCommand& command, TimePoint now,
                               std::vector<Completion>& completed) = 0;
  /// Advances the robot to `now` (one period after the previous call);
  /// appends the completions of commands that finished.
  virtual void Update(TimePoint now, std::vector<Completion>& completed) = 0;
  /// Fills `state` (already sized for the model).
  virtual void ReadState(RobotState& state) const = 0;
  /// Panic: stop every actuator at once and refuse motion until Resume().
  /// Every command in progress completes INTERRUPTED (appended).
  virtual void Halt(std::vector<Completion>& interrupted) = 0;
  /// Panic reset: accept commands again; the robot stays where it is.
  virtual void Resume() = 0;
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
