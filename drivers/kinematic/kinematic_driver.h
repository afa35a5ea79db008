// The `kinematic` driver: an ideal, velocity-limited kinematic simulation of
// any RobotModel. Joints move toward their set-points at their velocity limit
// (or run at a commanded speed until a position limit); control-frame
// set-points are solved by InverseKinematics (damped least squares); a mobile
// first root (differential or holonomic) integrates SETSPEED exactly and
// drives to a GOTO goal with a turn-drive-turn controller. There are no
// dynamics: JOINT_FORCE answers NA. docs/drivers.md describes the behaviour.
//
// Threading contract (driver.h): every method is called from one thread, the
// server's RobotDaemon; the class has no locks and is not thread-safe. All
// per-dof buffers are allocated in the constructor: Update() and ReadState()
// do not allocate (ReadState() only if `state` was not sized for the model);
// Execute() allocates only to build a reply message (MODIFIED/NA/BUSY/...
// texts) and, for FRAME_SETPOINT, the Jacobian that Kinematics::FrameJacobian
// returns on each of at most kIkMaxIterations IK iterations.
//
// Copy/move: neither (the InverseKinematics member refers to the owned model).
#pragma once

#include "robotalk/dof_table.h"
#include "robotalk/driver.h"
#include "robotalk/inverse_kinematics.h"

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <chrono>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace robotalk {

/// Options of the kinematic driver. As key=value strings (DriverConfig::options)
/// they are parsed by FromMap().
struct KinematicDriverOptions {
  /// Period at which the RobotDaemon should call Update(). Key "period_ms", > 0.
  Duration period = std::chrono::milliseconds(10);
  /// Speed of dofs whose velocity limit is infinite, rad/s or m/s. Key "default_velocity", > 0.
  double default_velocity = 1.0;
  /// Largest base forward (or planar, for a holonomic base) speed, m/s. Key "base_max_v", > 0.
  double base_max_v = 0.7;
  /// Largest base yaw rate, rad/s. Key "base_max_omega", > 0.
  double base_max_omega = 2.0;
  /// A GOTO succeeds within this distance of its goal, m (and 0.01 rad). Key "goto_tolerance", > 0.
  double goto_tolerance = 0.01;
  /// Import option for the factory: merge massless chains into multi-dof
  /// joints (UrdfImportOptions::merge_massless_chains). Key "merge_chains",
  /// "true"/"false"/"1"/"0". Not used by the KinematicDriver constructor.
  bool merge_chains = false;

  /// Parses DriverConfig::options. Throws Error naming an unknown key (and the
  /// known ones) or a bad value, e.g.
  /// "kinematic driver: option period_ms='-3': expected a number > 0".
  static KinematicDriverOptions FromMap(const std::map<std::string, std::string>& options);
  /// Throws Error naming the first field that is out of range.
  void Validate() const;
};

class KinematicDriver final : public Driver {
 public:
  /// Takes the model; state starts at q = 0 clamped into the limits, the base
  /// at the first root's pose in the model. Throws Error for bad options.
  KinematicDriver(RobotModel model, const KinematicDriverOptions& options = {});
  KinematicDriver(const KinematicDriver&) = delete;
  KinematicDriver& operator=(const KinematicDriver&) = delete;

  const RobotModel& model() const override { return model_; }
  Duration period() const override { return options_.period; }

  /// Advances the simulation to `now` first (so a command takes effect at its
  /// own time, not at the next Update), then starts `command`.
  DriverResult Execute(const DriverCommand& command, TimePoint now,
                       std::vector<Completion>& completed) override;
  /// Puts the joint exactly where the reference says, at its velocity (an
  /// ideal tracker: the trajectory's error is zero by construction).
  DriverResult Track(const JointReference& reference, TimePoint now,
                     std::vector<Completion>& completed) override;
  /// Drives the base exactly at the reference's twist from `now` (as a
  /// SETSPEED: shaped to the base and its limits, BUSY during a GOTO, NA on
  /// a fixed base); its reported twist is the reference's at once.
  DriverResult TrackBase(const BaseReference& reference, TimePoint now,
                         std::vector<Completion>& completed) override;
  /// Integrates over the time since the previous Update()/Execute(); the first
  /// call only sets the time base. Appends a finished GOTO's completion.
  void Update(TimePoint now, std::vector<Completion>& completed) override;
  void ReadState(RobotState& state) const override;
  void Stop(TimePoint now, std::vector<Completion>& interrupted) override;
  /// The scope's joints hold where they are; with the base, the base stops
  /// and a GOTO in progress completes INTERRUPTED. Nothing else changes.
  void StopOnly(const StopScope& scope, TimePoint now, std::vector<Completion>& interrupted) override;
  void Halt(std::vector<Completion>& interrupted) override;
  void Resume() override;

  /// Cap on damped-least-squares iterations per FRAME_SETPOINT.
  static constexpr int kIkMaxIterations = InverseKinematics::kMaxIterations;
  /// A FRAME_SETPOINT is SUCCESS when the solution is this close (m, rad).
  static constexpr double kIkPositionTolerance = InverseKinematics::kPositionTolerance;
  static constexpr double kIkOrientationTolerance = InverseKinematics::kOrientationTolerance;
  /// A GOTO's final heading tolerance, rad.
  static constexpr double kGotoHeadingTolerance = 1e-2;

 private:
  // kReference: set by Track() for this instant; the next step holds there
  // unless Track() is called again.
  enum class DofMode : std::uint8_t { kPosition, kVelocity, kReference };
  enum class BaseMode : std::uint8_t { kIdle, kSpeed, kGoto };
  enum class GotoPhase : std::uint8_t { kTurnToGoal, kDrive, kFinalTurn };

  // Integrates every dof and the base over dt seconds.
  void Advance(TimePoint now, std::vector<Completion>& completed);
  void StepDofs(double dt);
  void StepBase(double dt, std::vector<Completion>& completed);
  // Moves the base by the body twist (vx, vy, omega) held for dt (exact).
  void IntegrateBase(double vx, double vy, double omega, double dt);
  // Stops every motion; an in-progress GOTO completes INTERRUPTED with `why`.
  void StopAll(const char* why, std::vector<Completion>& completed);
  // The base part of StopAll; HoldDof holds one dof where it is.
  void StopBase(const char* why, std::vector<Completion>& completed);
  void HoldDof(int i);

  DriverResult JointSetPoint(const DriverCommand& c);
  DriverResult JointSpeed(const DriverCommand& c);
  DriverResult FrameSetPoint(const DriverCommand& c);
  DriverResult SetSpeed(const DriverCommand& c);
  DriverResult Goto(const DriverCommand& c);
  // Current world pose of every root (base pose for the first) into root_world_.
  void UpdateRootPoses() const;
  bool mobile_base() const { return base_type_ != BaseType::kFixed; }

  RobotModel model_;
  KinematicDriverOptions options_;
  DofTable dofs_;         // per-dof limits and mimic couplings
  InverseKinematics ik_;  // FRAME_SETPOINT; its default masks say which dofs move

  // Per dof (size num_dofs), allocated in the constructor.
  Eigen::VectorXd q_, qd_, effort_, target_, speed_, vmax_;
  std::vector<DofMode> mode_;

  // Base (first root). x, y, theta: the root's planar pose in the world;
  // base_residual_ the rest of its model pose (height, roll, pitch).
  BaseType base_type_ = BaseType::kFixed;
  double x_ = 0, y_ = 0, theta_ = 0;
  double z_ = 0;
  Eigen::Quaterniond base_residual_ = Eigen::Quaterniond::Identity();
  BaseMode base_mode_ = BaseMode::kIdle;
  double cmd_vx_ = 0, cmd_vy_ = 0, cmd_omega_ = 0;  // SETSPEED, body frame
  double v_ = 0, vy_ = 0, omega_ = 0;               // last step's base twist
  CommandId goto_id_ = 0;
  double goal_x_ = 0, goal_y_ = 0, goal_theta_ = 0;
  GotoPhase goto_phase_ = GotoPhase::kTurnToGoal;
  mutable std::vector<Eigen::Isometry3d> root_world_;

  std::optional<TimePoint> last_time_;
};

/// Registers "kinematic": a factory that loads DriverConfig::urdf_path with
/// LoadUrdfFile (robot name from DriverConfig::robot_name when not empty) and
/// options parsed by KinematicDriverOptions::FromMap. The factory throws Error
/// (UrdfError for the file) naming what is wrong.
void RegisterKinematicDriver(DriverRegistry& registry);

}  // namespace robotalk
