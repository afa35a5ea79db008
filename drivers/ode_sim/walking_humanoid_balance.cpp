// The walking controller's balance feedback: the measured centre of
// pressure and centre of mass, the DCM stabilizer and step adjustment
// (stabilizer=true), the push recovery's hook (push_recovery=true), and the
// walk status that reports them. See walking_humanoid.h.
#include "walking_humanoid.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <span>

namespace robotalk::ode_detail {

using walking::Pose2;
using walking::Side;

void WalkingHumanoid::MeasureContacts() {
  Eigen::Vector3d moment = Eigen::Vector3d::Zero();
  std::array<Eigen::Vector2d, 2> foot_moment{Eigen::Vector2d::Zero(), Eigen::Vector2d::Zero()};
  double fz = 0;
  foot_force_[0] = foot_force_[1] = 0;
  foot_contacts_[0] = foot_contacts_[1] = 0;
  foot_peak_force_[0] = foot_peak_force_[1] = 0;
  for (const ContactPoint& c : world_->contacts()) {
    for (int s = 0; s < 2; ++s) {
      if (c.link != feet_[static_cast<size_t>(s)]) continue;
      foot_force_[s] += c.force.z();
      foot_peak_force_[s] = std::max(foot_peak_force_[s], c.force.z());
      foot_moment[static_cast<size_t>(s)] += c.force.z() * c.position.head<2>();
      ++foot_contacts_[s];
    }
    fz += c.force.z();
    moment += c.force.z() * c.position;
  }
  zmp_valid_ = fz > 1e-6;
  if (zmp_valid_) zmp_measured_ = moment.head<2>() / fz;
  // Each sole's centre of pressure, in the world and in the foot's frame
  // (its ankle point on the ground, its yaw: walking/foot_damping.h).
  for (size_t s = 0; s < 2; ++s) {
    walking::FootWrench& w = foot_wrench_[s];
    w.force = foot_force_[s];
    if (w.force <= 1e-6) continue;
    foot_cop_[s] = foot_moment[s] / w.force;
    const Pose2 f = MeasuredFoot(static_cast<Side>(s));
    const Eigen::Vector2d d = foot_cop_[s] - f.xy();
    const double c = std::cos(f.theta), sn = std::sin(f.theta);
    w.cop = {c * d.x() + sn * d.y(), -sn * d.x() + c * d.y()};
  }
}

// Foot damping (options.foot_damping; walking/foot_damping.h): the ZMP the
// walker wants (the stabilizer's command when it runs, else the plan's) is
// split between the feet the plan has on the ground; each foot's ankle roll
// and pitch yield to its CoP error: the sole's target turns about the ankle
// (soles are the IK's targets). The split is kept for the status also
// without the option.
void WalkingHumanoid::DampFeet(std::array<Eigen::Isometry3d, 2>* soles) {
  constexpr double kMargin = 0.01;  // m inside the sole, as the stabilizer's
  const std::array<Pose2, 2> feet{pattern_.foot(Side::kLeft), pattern_.foot(Side::kRight)};
  const std::array<bool, 2> down{pattern_.foot_height(Side::kLeft) <= 0,
                                 pattern_.foot_height(Side::kRight) <= 0};
  const bool command = stabilizing_;
  const walking::SoleRect sole{g_.foot_front, g_.foot_back, g_.foot_half_width};
  foot_targets_ =
      walking::DistributeZmp(command ? balance_.zmp : pattern_.zmp_ref(), feet, down, sole, kMargin);
  if (push_forces_ && tick_ >= settle_ticks_) {  // push_balance's forces: the soles' heights
    const double h =
        PushHolding()
            ? push_forces_->Update(foot_targets_.share, {foot_force_[0], foot_force_[1]}, down[0] && down[1])
            : push_forces_->Relax();
    (*soles)[0].translation().z() += 0.5 * h;
    (*soles)[1].translation().z() -= 0.5 * h;
  }
  if (!foot_damping_ || tick_ < settle_ticks_) return;
  // push_balance's damping: only while a push's stop holds, then back to flat.
  const bool damp = damp_feet_ || (push_damping_ && PushHolding());
  for (size_t s = 0; s < 2; ++s) {
    const int i = static_cast<int>(s);
    const Eigen::Vector2d a =
        damp ? foot_damping_->Update(i, foot_targets_.cop[s], foot_wrench_[s]) : foot_damping_->Relax(i);
    // Turn about the ankle (the sole target sits -z below it in the foot's frame).
    const double up = -soles_[s].z;
    Eigen::Isometry3d& t = (*soles)[s];
    t = t * Eigen::Translation3d(0, 0, up) * Eigen::AngleAxisd(a.x(), Eigen::Vector3d::UnitX()) *
        Eigen::AngleAxisd(a.y(), Eigen::Vector3d::UnitY()) * Eigen::Translation3d(0, 0, -up);
  }
}

// The measured CoM (the model's kinematics at the measured joints and root)
// and its velocity (differenced, low-passed over kComFilter), the measured
// CoP, into the plan frame; the stabilizer's ZMP command becomes the CoM
// reference's offset (walking/dcm_stabilizer.h). Off during the start-up.
void WalkingHumanoid::Balance() {
  constexpr double kComFilter = 0.01;  // s
  const Eigen::Vector3d com = world_->LinkPose(model_.roots().front().link) * ik_.ComInPelvis(world_->q());
  const Eigen::Vector2d xy = com.head<2>();
  if (tick_ <= 1) com_world_prev_ = xy;
  com_velocity_ += ((xy - com_world_prev_) / step_ - com_velocity_) * std::min(1.0, step_ / kComFilter);
  com_world_prev_ = xy;
  if (com_estimate_) com_estimate_->Update(xy, zmp_valid_ ? &zmp_measured_ : nullptr);
  stabilizing_ = false;
  if (tick_ < settle_ticks_) return;
  const double c = std::cos(plan_to_world_.theta), s = std::sin(plan_to_world_.theta);
  const Eigen::Vector2d v(c * com_velocity_.x() + s * com_velocity_.y(),
                          -s * com_velocity_.x() + c * com_velocity_.y());
  const Eigen::Vector2d at = ToPlan({xy.x(), xy.y(), 0}).xy();
  if (recovery_) {
    // Estimated (DcmEstimator), read from the support foot (the feet slip
    // and turn), put on its plan.
    const Side sup = pattern_.support_side();
    const Pose2 to = pattern_.foot(sup), from = MeasuredFoot(sup);
    if (recovery_->Update(pattern_, walking::Relocate(from, to, com_estimate_->com()),
                          walking::Relocate(from, to, com_estimate_->com_velocity(), true)))
      com_offset_->Reset();
  }
  // push_balance's stabilizer: only while a push's stop holds, then the
  // CoM offset returns to the plan over kRelax. And the other way round: with
  // stabilizer=true, while a push's stop holds the stabilizer stands down (its
  // offset returns to the plan over kRelax, no step adjustment) and the push
  // recovery's stop, which re-plans from the measured state, is the only
  // feedback; the stabilizer resumes with the walk. Measured: run through the
  // stop and the stand, the offset swung between its bounds (+-5 cm, 1.6 Hz,
  // torso tilt 0.1 rad), which the push detector read as further pushes (a
  // stop held on, a second stop after the resume), and the pushed GOTO fell
  // (docs/ode_sim.md, "Why a pushed GOTO fell with the stabilizer").
  constexpr double kRelax = 0.5;  // s
  const bool run = stabilize_ ? !PushHolding() : push_stabilizer_ && PushHolding();
  if (!run) {
    if (push_stabilizer_ || stabilize_) com_offset_->Relax(step_, kRelax);
    return;
  }
  stabilizing_ = true;
  const Eigen::Vector2d cop = ToPlan({zmp_measured_.x(), zmp_measured_.y(), 0}).xy();
  std::array<Eigen::Vector2d, 16> support;
  const int n = pattern_.SupportPolygon(support);
  balance_ = dcm_->Update(at, v, pattern_.com(), pattern_.com_velocity(), pattern_.zmp_ref(),
                          std::span(support.data(), static_cast<size_t>(n)), pattern_.time_to_landing());
  com_offset_->Update(balance_, at, pattern_.com(), pattern_.zmp_ref(), zmp_valid_ ? &cop : nullptr, step_);
}

// The event-driven stop (options.push_stop_wait; walking/push_recovery.h,
// stop_wait): while a push's stop holds, a step lifts only once the foot it
// leaves the weight on carries it and the measured DCM is inside that sole
// (both measured: the foot's contact force, its pose, the estimator's DCM),
// at most push_stop_wait s late; the plan then goes on from the measured CoM
// state, read from that foot and put on its plan. Before pattern_.Tick().
void WalkingHumanoid::GateLift() {
  if (recovery_->params().stop_wait <= 0 || !PushHolding()) return;  // off (the default): nothing measured
  const walking::Footstep* lift = pattern_.lifting_next();
  const walking::Footstep* land = lift ? nullptr : pattern_.landing_next();
  if (lift == nullptr && land == nullptr) return;
  const Side stance = lift ? walking::Other(lift->side) : land->side;  // the foot that stays, or lands
  const Pose2 measured = MeasuredFoot(stance), plan = pattern_.foot(stance);
  const double force = foot_force_[static_cast<int>(stance)];
  const bool ready =
      lift ? walking::LiftReady(measured, g_, com_estimate_->dcm(), force, weight_, recovery_->params())
           : walking::LandReady(force, weight_, recovery_->params());
  if (recovery_->GateLift(pattern_, ready, walking::Relocate(measured, plan, com_estimate_->com()),
                          walking::Relocate(measured, plan, com_estimate_->com_velocity(), true)))
    com_offset_->Reset();
}

// Step adjustment: while the ankles cannot hold the DCM (the stabilizer's
// ZMP saturated) the foot in the air is moved toward where the DCM will be
// at its touch-down, at most kAdjustRate fast (its swing stays smooth) and
// not in the last kLateAdjust s of its swing; the last target is kept.
void WalkingHumanoid::AdjustStep() {
  constexpr double kAdjustRate = 1.0;           // m/s
  constexpr double kLateAdjust = 0.15;          // s
  if (!adjust_steps_ || !stabilizing_) return;  // off in the start-up and while a push's stop holds
  if (pattern_.started_steps() != adjusted_step_) {
    adjusted_step_ = pattern_.started_steps();
    step_target_.setZero();
    step_applied_.setZero();
  }
  if (pattern_.time_to_landing() <= kLateAdjust) return;
  if (balance_.saturated && balance_.step_offset.norm() > 0) step_target_ = balance_.step_offset;
  const double r = kAdjustRate * step_;
  const Eigen::Vector2d next = step_applied_ + (step_target_ - step_applied_).cwiseMax(-r).cwiseMin(r);
  if ((next - step_applied_).norm() > 1e-12) {
    step_applied_ = pattern_.AdjustLanding(next, g_.foot_separation + 2 * g_.step_forward + 0.05);
  }
}

walking::WalkStatus WalkingHumanoid::status() const {
  walking::WalkStatus s;
  s.stepping = !pattern_.standing();
  s.fallen = fallen_;
  s.tilt = tilt_;
  s.steps_taken = pattern_.started_steps();
  s.recoveries = recovery_ ? recovery_->regenerations() : 0;
  s.push_stops = recovery_ ? recovery_->stops() : 0;
  s.push_captures = recovery_ ? recovery_->captures() : 0;
  s.push_timings = recovery_ ? recovery_->timings() : 0;
  s.push_waited = recovery_ ? recovery_->waited() : 0;
  if (recovery_) s.push_impulse = com_estimate_->impulse();
  s.push_holding = PushHolding();
  const Pose2 com = ToWorld({pattern_.com().x(), pattern_.com().y(), 0});
  s.com_plan = com.xy();
  const Eigen::Vector2d z = pattern_.zmp_ref();
  s.zmp_ref = ToWorld({z.x(), z.y(), 0}).xy();
  for (int i = 0; i < 2; ++i) {
    s.foot[i] = ToWorld(pattern_.foot(static_cast<Side>(i)));
    s.foot_height[i] = pattern_.foot_height(static_cast<Side>(i));
  }
  s.pelvis = MeasuredPelvis();
  s.zmp = zmp_measured_;
  s.tracking_error = tracking_error_;
  for (int i = 0; i < 2; ++i) {
    s.foot_force[i] = foot_force_[i];
    s.foot_contacts[i] = foot_contacts_[i];
    s.foot_peak_force[i] = foot_peak_force_[i];
  }
  for (int i = 0; i < 2; ++i) {
    const Eigen::Isometry3d f = world_->LinkPose(feet_[static_cast<size_t>(i)]);
    s.foot_measured[i] = MeasuredFoot(static_cast<Side>(i));
    s.foot_tilt[i] = std::acos(std::clamp(f.linear()(2, 2), -1.0, 1.0));
    const Sole& sole = soles_[static_cast<size_t>(i)];
    s.foot_low[i] = 1e9;
    for (const double x : {sole.front, -sole.back}) {
      for (const double y : {sole.left, -sole.right})
        s.foot_low[i] = std::min(s.foot_low[i], (f * Eigen::Vector3d(x, y, sole.z)).z());
    }
    // Roll and pitch in the foot's yaw frame.
    const Eigen::Matrix3d r =
        Eigen::AngleAxisd(-s.foot_measured[i].theta, Eigen::Vector3d::UnitZ()).toRotationMatrix() *
        f.linear();
    s.foot_roll[i] = std::atan2(r(2, 1), r(2, 2));
    s.foot_pitch[i] = std::asin(std::clamp(-r(2, 0), -1.0, 1.0));
    s.foot_cop[i] = foot_cop_[static_cast<size_t>(i)];
    s.foot_cop_ref[i] = s.foot_measured[i].Apply(foot_targets_.cop[static_cast<size_t>(i)].x(),
                                                 foot_targets_.cop[static_cast<size_t>(i)].y());
    if (foot_damping_) s.ankle_offset[i] = foot_damping_->offset(i);
  }
  s.com = world_->LinkPose(model_.roots().front().link) * ik_.ComInPelvis(world_->q());
  if (stabilizing_) {
    s.dcm = ToWorld({balance_.dcm.x(), balance_.dcm.y(), 0}).xy();
    s.dcm_ref = ToWorld({balance_.dcm_ref.x(), balance_.dcm_ref.y(), 0}).xy();
    s.zmp_command = ToWorld({balance_.zmp.x(), balance_.zmp.y(), 0}).xy();
    s.saturated = balance_.saturated;
  }
  if (push_forces_) s.force_difference = push_forces_->height();
  // push_balance's stabilizer returns it to the plan after the hold.
  s.com_offset =
      Pose2{0, 0, plan_to_world_.theta}.Apply(com_offset_->offset().x(), com_offset_->offset().y());
  return s;
}

}  // namespace robotalk::ode_detail
