#include "kinematic_driver.h"

#include "robotalk/driver_support.h"

#include "robotalk/error.h"
#include "robotalk/urdf_import.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <numbers>
#include <span>
#include <utility>

namespace robotalk {
namespace {

constexpr double kPi = std::numbers::pi;

using driver_support::Answer;
using driver_support::Num;
using driver_support::Quote;
using driver_support::Unit;

using driver_support::WrapAngle;

}  // namespace

// ---------------------------------------------------------------- options

KinematicDriverOptions KinematicDriverOptions::FromMap(const std::map<std::string, std::string>& options) {
  KinematicDriverOptions o;
  driver_support::OptionReader r("kinematic driver", options);
  constexpr driver_support::OptionReader::Range kPositive{.min = 0, .min_inclusive = false};
  r.Bool("merge_chains", &o.merge_chains);
  r.Milliseconds("period_ms", &o.period);
  r.Number("default_velocity", &o.default_velocity, kPositive, "a speed > 0 (rad/s or m/s)");
  r.Number("base_max_v", &o.base_max_v, kPositive, "a speed > 0 (m/s)");
  r.Number("base_max_omega", &o.base_max_omega, kPositive, "a yaw rate > 0 (rad/s)");
  r.Number("goto_tolerance", &o.goto_tolerance, kPositive, "a distance > 0 (m)");
  r.Finish();
  return o;
}

void KinematicDriverOptions::Validate() const {
  using driver_support::CheckPositive;
  driver_support::CheckPeriod("KinematicDriver", period);
  CheckPositive("KinematicDriver", "default_velocity", default_velocity);
  CheckPositive("KinematicDriver", "base_max_v", base_max_v);
  CheckPositive("KinematicDriver", "base_max_omega", base_max_omega);
  CheckPositive("KinematicDriver", "goto_tolerance", goto_tolerance);
}

// ---------------------------------------------------------------- construction

KinematicDriver::KinematicDriver(RobotModel model, const KinematicDriverOptions& options)
    : model_(std::move(model)), options_(options), dofs_(model_), ik_(model_) {
  options_.Validate();
  const int n = model_.num_dofs();
  for (Eigen::VectorXd* v : {&q_, &qd_, &effort_, &target_, &speed_, &vmax_}) v->setZero(n);
  mode_.assign(static_cast<size_t>(n), DofMode::kPosition);
  for (int i = 0; i < n; ++i) {
    vmax_[i] = std::isfinite(dofs_.velocity[i]) ? dofs_.velocity[i] : options_.default_velocity;
    q_[i] = std::clamp(0.0, dofs_.lower[i], dofs_.upper[i]);
  }
  ApplyMimics(model_, q_);
  target_ = q_;

  // The first root's model pose = planar part (x, y, yaw) * residual (height,
  // roll, pitch); the base moves the planar part only.
  const RootLink& root = model_.roots().front();
  base_type_ = root.base;
  const Eigen::Matrix3d r = root.pose_in_world.rotation.normalized().toRotationMatrix();
  theta_ = std::atan2(r(1, 0), r(0, 0));
  base_residual_ =
      Eigen::AngleAxisd(-theta_, Eigen::Vector3d::UnitZ()) * root.pose_in_world.rotation.normalized();
  x_ = root.pose_in_world.translation.x();
  y_ = root.pose_in_world.translation.y();
  z_ = root.pose_in_world.translation.z();
  root_world_.resize(model_.roots().size(), Eigen::Isometry3d::Identity());
  UpdateRootPoses();
}

void KinematicDriver::UpdateRootPoses() const {
  const auto roots = model_.roots();
  for (size_t i = 1; i < roots.size(); ++i) root_world_[i] = roots[i].pose_in_world.ToIsometry();
  Eigen::Isometry3d base = Eigen::Isometry3d::Identity();
  base.translation() << x_, y_, z_;
  base.linear() = (Eigen::AngleAxisd(theta_, Eigen::Vector3d::UnitZ()) * base_residual_).toRotationMatrix();
  root_world_[0] = base;
}

// ---------------------------------------------------------------- time

void KinematicDriver::Update(TimePoint now, std::vector<Completion>& completed) { Advance(now, completed); }

void KinematicDriver::Advance(TimePoint now, std::vector<Completion>& completed) {
  if (!last_time_) {  // the first call only sets the time base
    last_time_ = now;
    return;
  }
  if (now <= *last_time_) return;  // no motion for a repeated (or earlier) time
  const double dt = ToSeconds(now - *last_time_);
  last_time_ = now;
  StepDofs(dt);
  StepBase(dt, completed);
}

void KinematicDriver::StepDofs(double dt) {
  const Eigen::Index n = q_.size();
  for (Eigen::Index i = 0; i < n; ++i) {
    if (dofs_.mimic_leader[static_cast<size_t>(i)] >= 0) continue;
    const double q0 = q_[i];
    if (mode_[static_cast<size_t>(i)] == DofMode::kReference) {  // no new reference: hold
      mode_[static_cast<size_t>(i)] = DofMode::kPosition;
      target_[i] = q0;
    }
    if (mode_[static_cast<size_t>(i)] == DofMode::kPosition) {
      const double d = target_[i] - q0;
      const double step = vmax_[i] * dt;
      if (std::abs(d) <= step) {
        q_[i] = target_[i];
      } else {
        q_[i] = q0 + std::copysign(step, d);
      }
    } else {
      double q1 = q0 + speed_[i] * dt;
      // A speed command stops at a position limit and holds there.
      if (q1 >= dofs_.upper[i] || q1 <= dofs_.lower[i]) {
        q1 = std::clamp(q1, dofs_.lower[i], dofs_.upper[i]);
        mode_[static_cast<size_t>(i)] = DofMode::kPosition;
        target_[i] = q1;
        speed_[i] = 0;
      }
      q_[i] = q1;
    }
    qd_[i] = (q_[i] - q0) / dt;
  }
  ApplyMimics(model_, q_);
  for (Eigen::Index i = 0; i < n; ++i) {
    const int leader = dofs_.mimic_leader[static_cast<size_t>(i)];
    if (leader >= 0) qd_[i] = dofs_.mimic_multiplier[static_cast<size_t>(i)] * qd_[leader];
  }
}

// ---------------------------------------------------------------- base

void KinematicDriver::IntegrateBase(double vx, double vy, double omega, double dt) {
  // Exact integration of a constant body twist: the body-frame displacement
  // is the integral of R(omega t) (vx, vy) over [0, dt].
  const double phi = omega * dt;
  double bx = vx * dt, by = vy * dt;
  if (std::abs(phi) > 1e-12) {
    const double s = std::sin(phi) / omega, c = (1 - std::cos(phi)) / omega;
    bx = s * vx - c * vy;
    by = c * vx + s * vy;
  }
  const double ct = std::cos(theta_), st = std::sin(theta_);
  x_ += ct * bx - st * by;
  y_ += st * bx + ct * by;
  theta_ = WrapAngle(theta_ + phi);
  v_ = vx;
  vy_ = vy;
  omega_ = omega;
}

void KinematicDriver::StepBase(double dt, std::vector<Completion>& completed) {
  switch (base_mode_) {
    case BaseMode::kIdle:
      v_ = vy_ = omega_ = 0;
      return;
    case BaseMode::kSpeed:
      IntegrateBase(cmd_vx_, cmd_vy_, cmd_omega_, dt);
      return;
    case BaseMode::kGoto:
      break;
  }
  // Turn toward the goal, drive to it, turn to the goal heading; every phase
  // at the maximum speed, the last step of each shortened so as not to
  // overshoot. One phase change may happen within a step (turn -> drive).
  const double tol = options_.goto_tolerance, wmax = options_.base_max_omega;
  const double dx = goal_x_ - x_, dy = goal_y_ - y_;
  const double dist = std::hypot(dx, dy);
  if (dist <= tol) goto_phase_ = GotoPhase::kFinalTurn;
  const double heading_error = WrapAngle(std::atan2(dy, dx) - theta_);
  if (goto_phase_ == GotoPhase::kDrive && std::abs(heading_error) > wmax * dt)
    goto_phase_ = GotoPhase::kTurnToGoal;
  if (goto_phase_ == GotoPhase::kTurnToGoal && std::abs(heading_error) <= wmax * dt)
    goto_phase_ = GotoPhase::kDrive;
  switch (goto_phase_) {
    case GotoPhase::kTurnToGoal:
      IntegrateBase(0, 0, std::copysign(wmax, heading_error), dt);
      break;
    case GotoPhase::kDrive:
      // Corrects the remaining heading error within the step (|error| <= wmax dt).
      IntegrateBase(std::min(options_.base_max_v, dist / dt), 0, heading_error / dt, dt);
      break;
    case GotoPhase::kFinalTurn: {
      const double e = WrapAngle(goal_theta_ - theta_);
      IntegrateBase(0, 0, std::clamp(e / dt, -wmax, wmax), dt);
      break;
    }
  }
  if (std::hypot(goal_x_ - x_, goal_y_ - y_) <= tol &&
      std::abs(WrapAngle(goal_theta_ - theta_)) <= kGotoHeadingTolerance) {
    completed.push_back(Completion{.id = goto_id_, .signal = Signal::kSuccess, .message = {}});
    base_mode_ = BaseMode::kIdle;
    v_ = vy_ = omega_ = 0;
  }
}

DriverResult KinematicDriver::SetSpeed(const DriverCommand& c) {
  if (c.num_values != 2 && c.num_values != 3) {
    return Answer(Signal::kError, "SETSPEED: expected 2 values (v omega) or 3 (vx vy omega), got " +
                                      std::to_string(c.num_values));
  }
  if (base_mode_ == BaseMode::kGoto) {
    return Answer(Signal::kBusy, "SETSPEED: GOTO in progress (command " + std::to_string(goto_id_) + ")");
  }
  const driver_support::BaseTwist t =
      driver_support::ShapeBaseSpeed(c, base_type_, options_.base_max_v, options_.base_max_omega);
  const double vx = t.vx, vy = t.vy, w = t.omega;
  const std::string& note = t.note;
  cmd_vx_ = vx;
  cmd_vy_ = vy;
  cmd_omega_ = w;
  base_mode_ = (vx == 0 && vy == 0 && w == 0) ? BaseMode::kIdle : BaseMode::kSpeed;
  return note.empty() ? Answer(Signal::kSuccess) : Answer(Signal::kModified, "SETSPEED: " + note);
}

DriverResult KinematicDriver::Goto(const DriverCommand& c) {
  if (c.num_values != 3) {
    return Answer(Signal::kError, "GOTO: expected 3 values (x y theta), got " + std::to_string(c.num_values));
  }
  if (base_mode_ == BaseMode::kGoto) {
    return Answer(Signal::kBusy, "GOTO: GOTO in progress (command " + std::to_string(goto_id_) + ")");
  }
  goal_x_ = c.values[0];
  goal_y_ = c.values[1];
  goal_theta_ = WrapAngle(c.values[2]);
  cmd_vx_ = cmd_vy_ = cmd_omega_ = 0;
  if (std::hypot(goal_x_ - x_, goal_y_ - y_) <= options_.goto_tolerance &&
      std::abs(WrapAngle(goal_theta_ - theta_)) <= kGotoHeadingTolerance) {
    base_mode_ = BaseMode::kIdle;  // already there
    return Answer(Signal::kSuccess);
  }
  base_mode_ = BaseMode::kGoto;
  goto_id_ = c.id;
  goto_phase_ = GotoPhase::kTurnToGoal;
  DriverResult r;
  r.in_progress = true;
  return r;
}

// ---------------------------------------------------------------- joints

DriverResult KinematicDriver::JointSetPoint(const DriverCommand& c) {
  const Joint& joint = model_.joint(c.target);
  std::string note;
  for (int k = 0; k < c.num_values; ++k) {
    const int i = model_.dof_offset(c.target) + k;
    const double want = c.values[static_cast<size_t>(k)];
    const double got = std::clamp(want, dofs_.lower[i], dofs_.upper[i]);
    if (got != want) {
      const char* unit = Unit(joint.dofs[static_cast<size_t>(k)].type);
      note += std::string(note.empty() ? "" : "; ") + "dof " + std::to_string(k) + ": " + Num(want) + " " +
              unit + " clamped to the " + (want > got ? "upper" : "lower") + " limit " + Num(got) + " " +
              unit;
    }
    mode_[static_cast<size_t>(i)] = DofMode::kPosition;
    target_[i] = got;
    speed_[i] = 0;
  }
  if (note.empty()) return Answer(Signal::kSuccess);
  return Answer(Signal::kModified, "JOINT_SETPOINT " + Quote(joint.name) + ": " + note);
}

DriverResult KinematicDriver::JointSpeed(const DriverCommand& c) {
  const Joint& joint = model_.joint(c.target);
  std::string note;
  for (int k = 0; k < c.num_values; ++k) {
    const int i = model_.dof_offset(c.target) + k;
    const Dof& dof = joint.dofs[static_cast<size_t>(k)];
    const double want = c.values[static_cast<size_t>(k)];
    const double limit = dof.limits.velocity;  // infinite: not clamped
    const double got = std::clamp(want, -limit, limit);
    if (got != want) {
      note += std::string(note.empty() ? "" : "; ") + "dof " + std::to_string(k) + ": " + Num(want) + " " +
              Unit(dof.type) + "/s clamped to the velocity limit " + Num(limit) + " " + Unit(dof.type) + "/s";
    }
    mode_[static_cast<size_t>(i)] = DofMode::kVelocity;
    speed_[i] = got;
  }
  if (note.empty()) return Answer(Signal::kSuccess);
  return Answer(Signal::kModified, "JOINT_SPEED " + Quote(joint.name) + ": " + note);
}

DriverResult KinematicDriver::FrameSetPoint(const DriverCommand& c) {
  if (auto refused = driver_support::CheckFrameSetPoint(model_, ik_, c)) return *refused;
  const Eigen::Vector3d goal_p = driver_support::FrameGoalPosition(c);
  const Eigen::Quaterniond goal_r = driver_support::FrameGoalOrientation(c);
  UpdateRootPoses();
  const InverseKinematics::Result r = ik_.Solve(c.target, goal_p, goal_r, q_, root_world_);
  const std::span<const std::uint8_t> mask = ik_.default_mask(c.target);
  const Eigen::VectorXd& best = ik_.solution();
  for (Eigen::Index i = 0; i < q_.size(); ++i) {
    if (!mask[static_cast<size_t>(i)]) continue;
    mode_[static_cast<size_t>(i)] = DofMode::kPosition;
    target_[i] = best[i];
    speed_[i] = 0;
  }
  return driver_support::AnswerFrameSetPoint(model_.frame(c.target).name, r);
}

// ---------------------------------------------------------------- commands

DriverResult KinematicDriver::Track(const JointReference& reference, TimePoint now,
                                    std::vector<Completion>& completed) {
  Advance(now, completed);
  const int first = model_.dof_offset(reference.joint);
  for (std::size_t k = 0; k < reference.position.size(); ++k) {
    const int i = first + static_cast<int>(k);
    q_[i] = std::clamp(reference.position[k], dofs_.lower[i], dofs_.upper[i]);
    qd_[i] = reference.velocity[k];
    target_[i] = q_[i];
    speed_[i] = 0;
    mode_[static_cast<size_t>(i)] = DofMode::kReference;
  }
  ApplyMimics(model_, q_);
  return Answer(Signal::kSuccess);
}

DriverResult KinematicDriver::TrackBase(const BaseReference& reference, TimePoint now,
                                        std::vector<Completion>& completed) {
  DriverResult result = Execute(driver_support::SetSpeedOf(reference), now, completed);
  if (result.signal == Signal::kSuccess || result.signal == Signal::kModified) {
    v_ = cmd_vx_;  // an ideal base: at the reference now, not one period later
    vy_ = cmd_vy_;
    omega_ = cmd_omega_;
  }
  return result;
}

DriverResult KinematicDriver::Execute(const DriverCommand& c, TimePoint now,
                                      std::vector<Completion>& completed) {
  // The server checked the command against the model (driver.h): a motion
  // command, a valid target of the right kind, its value count, finite values.
  Advance(now, completed);
  if (Traits(c.type).target == CommandTarget::kBase && !mobile_base()) {
    return Answer(Signal::kNa,
                  std::string(ToString(c.type)) + ": robot " + Quote(model_.name()) + " has a fixed base");
  }
  switch (c.type) {
    case CommandType::kJointSetPoint:
      return JointSetPoint(c);
    case CommandType::kJointSpeed:
      return JointSpeed(c);
    case CommandType::kJointForce:
      return Answer(Signal::kNa, "JOINT_FORCE " + Quote(model_.joint(c.target).name) +
                                     ": the kinematic driver simulates no dynamics");
    case CommandType::kFrameSetPoint:
      return FrameSetPoint(c);  // driver_support::CheckFrameSetPoint checks reachability
    case CommandType::kGoto:
      return Goto(c);
    case CommandType::kSetSpeed:
      return SetSpeed(c);
    default:  // a type this driver has no handler for (STOP and PANIC_RESET never come here)
      return driver_support::NotExecuted(c, "the kinematic driver");
  }
}

void KinematicDriver::Stop(TimePoint now, std::vector<Completion>& interrupted) {
  Advance(now, interrupted);
  StopAll("interrupted by STOP", interrupted);
}

void KinematicDriver::StopOnly(const StopScope& scope, TimePoint now, std::vector<Completion>& interrupted) {
  Advance(now, interrupted);
  if (scope.base) StopBase("interrupted by STOP", interrupted);
  for (const int j : scope.joints) {
    const int first = model_.dof_offset(j);
    const int n = static_cast<int>(model_.joint(j).dofs.size());
    for (int i = first; i < first + n; ++i) HoldDof(i);
  }
}

void KinematicDriver::StopBase(const char* why, std::vector<Completion>& completed) {
  if (base_mode_ == BaseMode::kGoto) {
    completed.push_back(
        Completion{.id = goto_id_, .signal = Signal::kInterrupted, .message = std::string("GOTO: ") + why});
  }
  base_mode_ = BaseMode::kIdle;
  cmd_vx_ = cmd_vy_ = cmd_omega_ = 0;
  v_ = vy_ = omega_ = 0;
}

void KinematicDriver::HoldDof(int i) {
  mode_[static_cast<size_t>(i)] = DofMode::kPosition;
  target_[i] = q_[i];
  speed_[i] = 0;
  qd_[i] = 0;
}

void KinematicDriver::StopAll(const char* why, std::vector<Completion>& completed) {
  StopBase(why, completed);
  for (int i = 0; i < static_cast<int>(q_.size()); ++i) HoldDof(i);
}

void KinematicDriver::Halt(std::vector<Completion>& interrupted) {
  StopAll("interrupted by panic", interrupted);
}

void KinematicDriver::Resume() {}

// ---------------------------------------------------------------- state

void KinematicDriver::ReadState(RobotState& state) const {
  state.position = q_;
  state.velocity = qd_;
  state.effort = effort_;
  UpdateRootPoses();
  if (state.root_poses.size() != root_world_.size()) state.root_poses.resize(root_world_.size());
  for (size_t i = 0; i < root_world_.size(); ++i) state.root_poses[i] = Pose::FromIsometry(root_world_[i]);
  state.base_v = v_;
  state.base_omega = omega_;
  state.base_vy = vy_;
  bool moving = base_mode_ != BaseMode::kIdle || v_ != 0 || vy_ != 0 || omega_ != 0;
  for (Eigen::Index i = 0; i < q_.size() && !moving; ++i) {
    if (dofs_.mimic_leader[static_cast<size_t>(i)] >= 0) continue;  // follows its leader
    moving = qd_[i] != 0 ||
             (mode_[static_cast<size_t>(i)] == DofMode::kPosition ? q_[i] != target_[i] : speed_[i] != 0);
  }
  state.moving = moving;
}

// ---------------------------------------------------------------- registry

void RegisterKinematicDriver(DriverRegistry& registry) {
  registry.Register("kinematic", [](const DriverConfig& config) -> std::unique_ptr<Driver> {
    const KinematicDriverOptions options = KinematicDriverOptions::FromMap(config.options);
    if (config.urdf_path.empty()) {
      throw Error("kinematic driver for robot '" + config.robot_name +
                  "': no URDF file (DriverConfig::urdf_path)");
    }
    UrdfImportOptions import;
    import.merge_massless_chains = options.merge_chains;
    import.robot_name = config.robot_name;
    UrdfImportResult result = LoadUrdfFile(config.urdf_path, import);
    return std::make_unique<KinematicDriver>(std::move(result.model), options);
  });
}

}  // namespace robotalk
