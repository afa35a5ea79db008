// OdeDriver's command handlers: Execute(), STOP, and the joint and frame
// commands; GOTO and SETSPEED go to the base (base_controller.h). The joint
// servos that carry them out each step are joint_servos.cpp;
// docs/ode_sim.md describes the behaviour.
#include "ode_driver_impl.h"

#include <algorithm>
#include <cmath>
#include <span>
#include <string>

namespace robotalk {

using driver_support::Answer;
using driver_support::Num;
using driver_support::Quote;
using driver_support::Unit;

DriverResult OdeDriver::Impl::Track(const JointReference& reference, TimePoint now,
                                    std::vector<Completion>& completed) {
  Advance(now, true, completed);
  const int first = model_.dof_offset(reference.joint);
  for (std::size_t k = 0; k < reference.position.size(); ++k) {
    const Eigen::Index i = first + static_cast<Eigen::Index>(k);
    if (servos_.base_driven(i)) {
      return {Signal::kNa, false,
              "joint '" + model_.joint(reference.joint).name + "' is driven by the walking controller"};
    }
  }
  for (std::size_t k = 0; k < reference.position.size(); ++k) {
    servos_.Reference(first + static_cast<Eigen::Index>(k), reference.position[k], reference.velocity[k],
                      reference.acceleration[k]);
  }
  return {};
}

DriverResult OdeDriver::Impl::TrackBase(const BaseReference& reference, TimePoint now,
                                        std::vector<Completion>& completed) {
  Advance(now, true, completed);
  return base_->TrackSpeed(reference);
}

DriverResult OdeDriver::Impl::Execute(const DriverCommand& c, TimePoint now,
                                      std::vector<Completion>& completed) {
  // The server checked the command against the model (driver.h): a motion
  // command, a valid target of the right kind, its value count, finite values.
  Advance(now, true, completed);
  switch (c.type) {
    case CommandType::kJointSetPoint:
    case CommandType::kJointSpeed:
    case CommandType::kJointForce:
      return JointCommand(c);  // the servo of the command's type (kCommandTraits)
    case CommandType::kFrameSetPoint:
      return FrameSetPoint(c);  // driver_support::CheckFrameSetPoint checks reachability
    case CommandType::kGoto:
      return base_->Goto(c);
    case CommandType::kSetSpeed:
      return base_->SetSpeed(c);
    default:  // a type this driver has no handler for (STOP and PANIC_RESET never come here)
      return driver_support::NotExecuted(c, "the ODE driver");
  }
}

void OdeDriver::Impl::Stop(TimePoint now, std::vector<Completion>& interrupted) {
  Advance(now, true, interrupted);
  StopAll("interrupted by STOP", interrupted);
}

// The watchdog's stop of what one client moved. The base decides whether the
// scope concerns it (the base; for a walking humanoid, also a leg its walk
// drives); a joint the base still drives afterwards (a wheel under another
// client's GOTO, a leg) stays with it.
void OdeDriver::Impl::StopOnly(const StopScope& scope, TimePoint now, std::vector<Completion>& interrupted) {
  Advance(now, true, interrupted);
  base_->StopOnly(scope, interrupted);
  for (const int j : scope.joints) {
    if (base_->Drives(j)) continue;
    const int first = model_.dof_offset(j);
    for (int k = 0; k < static_cast<int>(model_.joint(j).dofs.size()); ++k) servos_.Hold(first + k, *world_);
  }
}

DriverResult OdeDriver::Impl::JointCommand(const DriverCommand& c) {
  const std::string name = ToString(c.type);
  const ServoType servo = Traits(c.type).servo;
  const robotalk::Joint& joint = model_.joint(c.target);         // checked by the server (driver.h)
  if (auto busy = base_->Release(c.target, name)) return *busy;  // a wheel under a GOTO, a leg of a walk
  std::string note;
  for (int k = 0; k < c.num_values; ++k) {
    const auto i = static_cast<Eigen::Index>(model_.dof_offset(c.target) + k);
    const Dof& dof = joint.dofs[static_cast<size_t>(k)];
    const double want = c.values[static_cast<size_t>(k)];
    double got = want;
    std::string unit = Unit(dof.type);
    const char* what = "";
    if (servo == ServoType::kSetPoint) {
      got = std::clamp(want, servos_.lower(i), servos_.upper(i));
      what = want > got ? "the upper limit" : "the lower limit";
      servos_.SetPoint(i, got);
    } else if (servo == ServoType::kSpeed) {
      // The servo's limit: the model's, or default_velocity where that is infinite.
      got = std::clamp(want, -servos_.vmax()[i], servos_.vmax()[i]);
      unit += "/s";
      what = "the velocity limit";
      servos_.Speed(i, got);
    } else {
      got = std::clamp(want, -servos_.fmax()[i], servos_.fmax()[i]);
      unit = dof.type == DofType::kRevolute ? "N m" : "N";
      what = "the effort limit";
      servos_.Force(i, got);
    }
    if (got != want) {
      note += std::string(note.empty() ? "" : "; ") + "dof " + std::to_string(k) + ": " + Num(want) + " " +
              unit + " clamped to " + what + " " + Num(got) + " " + unit;
    }
  }
  if (note.empty()) return Answer(Signal::kSuccess);
  return Answer(Signal::kModified, name + " " + Quote(joint.name) + ": " + note);
}

// Solved from the measured joint positions and root poses, as the kinematic
// driver solves from its state; the solution becomes the set-points of the
// joints' position servos (ControlStep), which track it on physics.
DriverResult OdeDriver::Impl::FrameSetPoint(const DriverCommand& c) {
  if (auto refused = driver_support::CheckFrameSetPoint(model_, ik_, c)) return *refused;
  const Eigen::Vector3d goal_p = driver_support::FrameGoalPosition(c);
  const Eigen::Quaterniond goal_r = driver_support::FrameGoalOrientation(c);
  const auto roots = model_.roots();
  for (size_t i = 0; i < roots.size(); ++i) root_poses_[i] = world_->LinkPose(roots[i].link);
  const InverseKinematics::Result r = ik_.Solve(c.target, goal_p, goal_r, world_->q(), root_poses_);
  const std::span<const std::uint8_t> mask = ik_.default_mask(c.target);
  const Eigen::VectorXd& best = ik_.solution();
  for (Eigen::Index i = 0; i < best.size(); ++i) {
    if (mask[static_cast<size_t>(i)] && !servos_.base_driven(i)) servos_.SetPoint(i, best[i]);
  }
  return driver_support::AnswerFrameSetPoint(model_.frame(c.target).name, r);
}

}  // namespace robotalk
