// Private to drivers/ode_sim: OdeDriver's implementation class, shared by
// ode_driver.cpp (construction, stepping, state) and ode_commands.cpp (the
// command handlers). Its parts: the world (ode_world.h), the joint servos
// (joint_servos.h) and the base, a strategy chosen at construction
// (base_controller.h). Every member is private; OdeDriver reads it through
// the accessors. Threading and allocation as in ode_driver.h: one thread,
// buffers allocated in the constructor.
#pragma once

#include "base_controller.h"
#include "joint_servos.h"
#include "ode_driver.h"
#include "ode_world.h"
#include "robotalk/inverse_kinematics.h"

#include <Eigen/Geometry>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace robotalk {

namespace ode_detail {
/// The model as an ode driver sees it: the option "base" applied to its first root.
RobotModel DriverModel(RobotModel model, const OdeDriverOptions& options);

/// The ODE world an ode driver builds, and the base controller that prepared
/// it (not attached yet; OdeDriver's constructor attaches it).
struct DriverWorld {
  std::unique_ptr<BaseController> base;
  std::unique_ptr<OdeWorld> world;
  std::vector<CollisionShape> shapes;  ///< as the base prepared them
};
/// REQUIRES: `model` from DriverModel, `options` validated, `q0` the servos'
/// start pose. robotalk-ode-bench steps this world bare, against the driver.
DriverWorld BuildDriverWorld(const RobotModel& model, const OdeDriverOptions& options,
                             const Eigen::VectorXd& q0, std::vector<CollisionShape> shapes);
}  // namespace ode_detail

class OdeDriver::Impl {
 public:
  Impl(RobotModel model, const OdeDriverOptions& options, std::vector<CollisionShape> shapes);

  DriverResult Execute(const DriverCommand& c, TimePoint now, std::vector<Completion>& completed);
  DriverResult Track(const JointReference& reference, TimePoint now, std::vector<Completion>& completed);
  DriverResult TrackBase(const BaseReference& reference, TimePoint now, std::vector<Completion>& completed);
  void Stop(TimePoint now, std::vector<Completion>& interrupted);
  void StopOnly(const StopScope& scope, TimePoint now, std::vector<Completion>& interrupted);
  void Halt(std::vector<Completion>& interrupted) { StopAll("interrupted by panic", interrupted); }
  /// Steps up to `now`; `limit`: at most max_catchup_ms of steps (the rest is dropped).
  void Advance(TimePoint now, bool limit, std::vector<Completion>& completed);
  /// `n` steps now; the first sets the time base to 0 if nothing did.
  void Step(int n, std::vector<Completion>& completed);
  void ReadState(RobotState& state) const;

  const RobotModel& model() const { return model_; }
  Duration period() const { return options_.period; }
  TimePoint sim_time() const { return origin_.value_or(TimePoint{}) + dropped_ + steps_ * step_; }
  Duration dropped_time() const { return dropped_; }
  std::string_view fault() const { return base_->fault(); }
  std::optional<walking::WalkStatus> walk_status() const { return base_->walk_status(); }
  const ode_detail::OdeWorld& world() const { return *world_; }
  void Push(const Eigen::Vector3d& force, Duration duration) {
    push_ = force;
    push_steps_ = duration / step_;
  }

 private:
  void StopAll(const char* why, std::vector<Completion>& completed);
  DriverResult JointCommand(const DriverCommand& c);
  DriverResult FrameSetPoint(const DriverCommand& c);

  RobotModel model_;
  OdeDriverOptions options_;
  Duration step_{};
  std::optional<TimePoint> origin_;  // simulated time of step 0
  std::int64_t steps_ = 0;
  Duration dropped_{0};
  ode_detail::JointServos servos_;
  std::unique_ptr<ode_detail::OdeWorld> world_;
  std::unique_ptr<ode_detail::BaseController> base_;  // binds world_ and servos_
  // FRAME_SETPOINT: the solver (its default masks say which dofs move) and
  // the measured root poses it starts from, one per RobotModel::roots() entry.
  InverseKinematics ik_;
  std::vector<Eigen::Isometry3d> root_poses_;
  Eigen::Vector3d push_ = Eigen::Vector3d::Zero();  // PushForTesting: the force, for push_steps_ more steps
  std::int64_t push_steps_ = 0;
};

}  // namespace robotalk
