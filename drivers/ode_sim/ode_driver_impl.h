// Private to drivers/ode_sim: OdeDriver's implementation class, shared by
// ode_driver.cpp (construction, stepping, controllers, state) and
// ode_commands.cpp (the command handlers), and the reply-message helpers.
// Threading and allocation as in ode_driver.h: one thread, buffers allocated
// in the constructor.
#pragma once

#include "base_controller.h"
#include "ode_driver.h"
#include "ode_world.h"
#include "robotalk/inverse_kinematics.h"
#include "walking_humanoid.h"

#include <Eigen/Geometry>
#include <cstdint>
#include "robotalk/driver_support.h"

#include <cstdio>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace robotalk {
namespace ode_detail {

using driver_support::Answer;
using driver_support::Num;
using driver_support::Quote;
using driver_support::Unit;

}  // namespace ode_detail

class OdeDriver::Impl {
 public:
  Impl(RobotModel model, const OdeDriverOptions& options, std::vector<CollisionShape> shapes);

  DriverResult Execute(const DriverCommand& c, TimePoint now, std::vector<Completion>& completed);
  void Stop(TimePoint now, std::vector<Completion>& interrupted);
  void StopOnly(const StopScope& scope, TimePoint now, std::vector<Completion>& interrupted);
  void Advance(TimePoint now, bool limit, std::vector<Completion>& completed);
  void Step(int n, std::vector<Completion>& completed);
  void ReadState(RobotState& state) const;
  void Halt(std::vector<Completion>& interrupted) { StopAll("interrupted by panic", interrupted); }
  void Resume() {}

  RobotModel model_;
  OdeDriverOptions options_;
  std::unique_ptr<ode_detail::OdeWorld> world_;
  Duration step_{};
  std::optional<TimePoint> origin_;  // simulated time of step 0
  std::int64_t steps_ = 0;
  Duration dropped_{0};

 private:
  enum class Mode : std::uint8_t { kPosition, kVelocity, kForce, kPassive, kMimic };
  enum class BaseKind : std::uint8_t { kFixed, kWheels, kKinematic };
  enum class BaseMode : std::uint8_t { kIdle, kSpeed, kGoto };

  void ControlStep(std::vector<Completion>& completed);
  void StopAll(const char* why, std::vector<Completion>& completed);
  // The base part of StopAll (the walk, a GOTO, the root's speed); HoldDof
  // stops one dof's motor and holds it.
  void StopBase(const char* why, std::vector<Completion>& completed);
  void HoldDof(Eigen::Index i);
  void SetWheels(double v, double omega);
  void BasePose(double* x, double* y, double* theta) const;
  void SetupWheels(const std::vector<CollisionShape>& shapes);
  void SetupGait();
  DriverResult JointCommand(const DriverCommand& c);
  DriverResult FrameSetPoint(const DriverCommand& c);
  DriverResult SetSpeed(const DriverCommand& c);
  DriverResult Goto(const DriverCommand& c);
  bool IsWheel(int joint) const {
    return base_kind_ == BaseKind::kWheels && (joint == wheel_joint_[0] || joint == wheel_joint_[1]);
  }

  // Per dof.
  std::vector<Mode> mode_;
  Eigen::VectorXd target_, speed_, force_, vmax_, fmax_, lower_, upper_;
  std::vector<int> leader_;  // mimic leader dof, or -1
  std::vector<double> mimic_k_, mimic_c_;

  // Base.
  BaseKind base_kind_ = BaseKind::kFixed;
  BaseMode base_mode_ = BaseMode::kIdle;
  int wheel_joint_[2] = {-1, -1};  // left, right
  int wheel_dof_[2] = {-1, -1};
  double wheel_sign_[2] = {1, 1};
  double wheel_radius_ = 0, wheel_separation_ = 0;
  double cmd_vx_ = 0, cmd_vy_ = 0, cmd_omega_ = 0;  // SETSPEED, body frame
  ode_detail::GotoController goto_;
  CommandId goto_id_ = 0;
  int gait_dof_[4] = {-1, -1, -1, -1};  // left hip, left knee, right hip, right knee
  double gait_phase_ = 0;

  // FRAME_SETPOINT: the solver (its default masks say which dofs move) and
  // the measured root poses it starts from, one per RobotModel::roots() entry.
  InverseKinematics ik_;
  std::vector<Eigen::Isometry3d> root_poses_;

 public:
  // --- walking hook: a floating humanoid with feet walks (walking_humanoid.h);
  // it owns the leg dofs and answers GOTO/SETSPEED/STOP/Halt. Null otherwise.
  std::unique_ptr<ode_detail::WalkingHumanoid> walker_;
  std::string walk_why_;  // why the model does not walk (walker_ null)
};

}  // namespace robotalk
