// OdeDriver's command handlers: Execute() and the joint, frame and base
// commands. The controllers that carry them out each step are in
// ode_driver.cpp; docs/ode_sim.md describes the behaviour.
#include "ode_driver_impl.h"

#include <algorithm>
#include <cmath>
#include <span>
#include <string>

namespace robotalk {

using ode_detail::Answer;
using ode_detail::GotoController;
using ode_detail::Num;
using ode_detail::Quote;
using ode_detail::Unit;

DriverResult OdeDriver::Impl::Execute(const DriverCommand& c, TimePoint now,
                                      std::vector<Completion>& completed) {
  // The server checked the command against the model (driver.h): a motion
  // command, a valid target of the right kind, its value count, finite values.
  Advance(now, true, completed);
  const char* name = ToString(c.type);
  switch (c.type) {
    case CommandType::kJointSetPoint:
    case CommandType::kJointSpeed:
    case CommandType::kJointForce:
      return JointCommand(c);
    case CommandType::kFrameSetPoint:
      return FrameSetPoint(c);  // driver_support::CheckFrameSetPoint checks reachability
    case CommandType::kGoto:
    case CommandType::kSetSpeed:
      if (base_kind_ == BaseKind::kFixed) {
        return Answer(Signal::kNa,
                      std::string(name) + ": robot " + Quote(model_.name()) + " has a fixed base");
      }
      return c.type == CommandType::kGoto ? Goto(c) : SetSpeed(c);
    case CommandType::kStop:
    case CommandType::kPanicReset:
      break;  // never sent to a driver (driver.h)
  }
  return Answer(Signal::kError, std::string(name) + " is not a motion command a driver executes");
}

void OdeDriver::Impl::Stop(TimePoint now, std::vector<Completion>& interrupted) {
  Advance(now, true, interrupted);
  StopAll("interrupted by STOP", interrupted);
}

// The watchdog's stop of what one client moved. The base (with a walking
// humanoid, its walk) stops when asked, or when a leg the walk drives is in
// the scope (stopping more than asked is safe). A wheel stays with the base's
// controller while another client's GOTO or SETSPEED drives it.
void OdeDriver::Impl::StopOnly(const StopScope& scope, TimePoint now, std::vector<Completion>& interrupted) {
  Advance(now, true, interrupted);
  bool base = scope.base;
  for (const int j : scope.joints) {
    const int first = model_.dof_offset(j);
    for (int k = 0; k < static_cast<int>(model_.joint(j).dofs.size()); ++k)
      base = base || (walker_ && walker_->Owns(first + k));
  }
  if (base) {
    StopBase("interrupted by STOP", interrupted);
    if (base_kind_ == BaseKind::kWheels)
      for (const int w : wheel_dof_) HoldDof(w);
  }
  for (const int j : scope.joints) {
    if (IsWheel(j) && base_mode_ != BaseMode::kIdle) continue;
    const int first = model_.dof_offset(j);
    for (int k = 0; k < static_cast<int>(model_.joint(j).dofs.size()); ++k) {
      if (walker_ && walker_->Owns(first + k)) continue;
      HoldDof(first + k);
    }
  }
}

DriverResult OdeDriver::Impl::JointCommand(const DriverCommand& c) {
  const std::string name = ToString(c.type);
  const robotalk::Joint& joint = model_.joint(c.target);  // checked by the server (driver.h)
  if (walker_ && !joint.dofs.empty() && walker_->Owns(model_.dof_offset(c.target))) {  // walking hook
    return Answer(Signal::kBusy,
                  name + " " + Quote(joint.name) + ": the leg is driven by the walking controller");
  }
  if (IsWheel(c.target)) {
    if (base_mode_ == BaseMode::kGoto) {
      return Answer(Signal::kBusy, name + " " + Quote(joint.name) +
                                       ": the wheel is driven by a GOTO in progress (command " +
                                       std::to_string(goto_id_) + ")");
    }
    base_mode_ = BaseMode::kIdle;  // a wheel command takes the wheels over from SETSPEED
    cmd_vx_ = cmd_vy_ = cmd_omega_ = 0;
  }
  std::string note;
  for (int k = 0; k < c.num_values; ++k) {
    const auto i = static_cast<Eigen::Index>(model_.dof_offset(c.target) + k);
    const Dof& dof = joint.dofs[static_cast<size_t>(k)];
    const double want = c.values[static_cast<size_t>(k)];
    double got = want;
    std::string unit = Unit(dof.type);
    const char* what = "";
    if (c.type == CommandType::kJointSetPoint) {
      got = std::clamp(want, lower_[i], upper_[i]);
      what = want > got ? "the upper limit" : "the lower limit";
      mode_[static_cast<size_t>(i)] = Mode::kPosition;
      target_[i] = got;
    } else if (c.type == CommandType::kJointSpeed) {
      got = std::clamp(want, -dof.limits.velocity, dof.limits.velocity);
      unit += "/s";
      what = "the velocity limit";
      mode_[static_cast<size_t>(i)] = Mode::kVelocity;
      speed_[i] = got;
    } else {
      got = std::clamp(want, -fmax_[i], fmax_[i]);
      unit = dof.type == DofType::kRevolute ? "N m" : "N";
      what = "the effort limit";
      mode_[static_cast<size_t>(i)] = Mode::kForce;
      force_[i] = got;
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
    if (!mask[static_cast<size_t>(i)]) continue;
    mode_[static_cast<size_t>(i)] = Mode::kPosition;
    target_[i] = best[i];
    speed_[i] = 0;
    force_[i] = 0;
  }
  return driver_support::AnswerFrameSetPoint(model_.frame(c.target).name, r);
}

DriverResult OdeDriver::Impl::SetSpeed(const DriverCommand& c) {
  if (c.num_values != 2 && c.num_values != 3) {
    return Answer(Signal::kError, "SETSPEED: expected 2 values (v omega) or 3 (vx vy omega), got " +
                                      std::to_string(c.num_values));
  }
  if (walker_) return walker_->SetSpeed(c);  // walking hook
  if (base_mode_ == BaseMode::kGoto) {
    return Answer(Signal::kBusy, "SETSPEED: GOTO in progress (command " + std::to_string(goto_id_) + ")");
  }
  driver_support::BaseTwist t = driver_support::ShapeBaseSpeed(c, model_.roots().front().base,
                                                               options_.base_max_v, options_.base_max_omega);
  double& vx = t.vx;
  double& vy = t.vy;
  double& w = t.omega;
  const auto add = [&t](const std::string& what) { t.Note(what); };
  if (base_kind_ == BaseKind::kWheels) {  // the wheels' own speed limit
    const double b = 0.5 * wheel_separation_;
    double k = 1;
    for (int s = 0; s < 2; ++s) {
      const double rate = std::abs((vx + (s == 0 ? -b : b) * w) / wheel_radius_);
      const double lim = vmax_[static_cast<Eigen::Index>(wheel_dof_[s])];
      if (rate > lim) k = std::min(k, lim / rate);
    }
    if (k < 1) {
      add("scaled by " + Num(k) + " to the wheels' velocity limit");
      vx *= k;
      w *= k;
    }
  } else {
    add("the root moves kinematically (" + std::string(ToString(model_.roots().front().base)) + " base)");
  }
  cmd_vx_ = vx;
  cmd_vy_ = vy;
  cmd_omega_ = w;
  base_mode_ = (vx == 0 && vy == 0 && w == 0) ? BaseMode::kIdle : BaseMode::kSpeed;
  if (base_kind_ == BaseKind::kWheels) SetWheels(vx, w);
  if (base_mode_ == BaseMode::kIdle)
    world_->SetRootVelocity(Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero());
  return t.note.empty() ? Answer(Signal::kSuccess) : Answer(Signal::kModified, "SETSPEED: " + t.note);
}

DriverResult OdeDriver::Impl::Goto(const DriverCommand& c) {
  if (c.num_values != 3) {
    return Answer(Signal::kError, "GOTO: expected 3 values (x y theta), got " + std::to_string(c.num_values));
  }
  if (walker_) return walker_->Goto(c);  // walking hook
  if (base_mode_ == BaseMode::kGoto) {
    return Answer(Signal::kBusy, "GOTO: GOTO in progress (command " + std::to_string(goto_id_) + ")");
  }
  GotoController::Gains g;
  g.max_v = options_.base_max_v;
  g.max_omega = options_.base_max_omega;
  g.tolerance = options_.goto_tolerance;
  g.heading_tolerance = options_.goto_heading_tolerance;
  goto_.Start(c.values[0], c.values[1], c.values[2], g);
  cmd_vx_ = cmd_vy_ = cmd_omega_ = 0;
  double x, y, th;
  BasePose(&x, &y, &th);
  goto_.Update(x, y, th);
  if (goto_.done()) {  // already there
    base_mode_ = BaseMode::kIdle;
    if (base_kind_ == BaseKind::kWheels) SetWheels(0, 0);
    return Answer(Signal::kSuccess);
  }
  goto_.Start(c.values[0], c.values[1], c.values[2], g);
  base_mode_ = BaseMode::kGoto;
  goto_id_ = c.id;
  DriverResult r;
  r.in_progress = true;
  return r;
}

}  // namespace robotalk
