// The ode driver's walking controller: see walking_humanoid.h.
#include "walking_humanoid.h"

#include "robotalk/driver_support.h"
#include "robotalk/error.h"
#include "walking/footstep_planner.h"
#include "walking/gait_limits.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <span>

namespace robotalk::ode_detail {

using driver_support::Answer;
using driver_support::Num;
using walking::Footstep;
using walking::Pose2;
using walking::Side;
using walking::Wrap;

namespace {

constexpr double kSettle = 1.0;       // s: from straight legs to the walking stance after start-up
constexpr double kRamp = 0.3;         // s: the servo targets fade from the start-up joints to the IK's
constexpr double kKneeDrop = 0.07;    // of the pelvis-to-sole height: how far the pelvis sinks to walk
constexpr int kPreviewEvery = 5;      // physics steps per preview sample (5 ms at 1 kHz)
constexpr int kQueuedSpeedSteps = 2;  // SETSPEED keeps this many steps planned ahead

// Bends the knees of a straight-legged q: at a straight knee the leg's
// Jacobian loses its vertical row and damped least squares never bends it.
void BendKnees(const RobotModel& m, std::span<const std::uint8_t> legs, Eigen::VectorXd& q) {
  for (int j = 0; j < static_cast<int>(m.joints().size()); ++j) {
    const Joint& joint = m.joint(j);
    if (joint.dofs.size() != 1 || !legs[static_cast<size_t>(m.dof_offset(j))]) continue;
    if (joint.name.find("knee") == std::string::npos && joint.name.find("kny") == std::string::npos) continue;
    const int i = m.dof_offset(j);
    const DofLimits& lim = joint.dofs[0].limits;
    if (std::abs(q[i]) < 0.2) q[i] = std::clamp(lim.upper > 0 ? 0.3 : -0.3, lim.lower, lim.upper);
  }
}

std::optional<int> FindAnyLink(const RobotModel& m, std::initializer_list<const char*> names) {
  for (const char* n : names) {
    if (auto l = m.FindLink(n)) return l;
  }
  return std::nullopt;
}

// The gait (options gait, step_length, ...; walking/gait_limits.h): derived
// from the leg, or the slow one (also where the leg cannot be measured), then overridden.
// *said: which gait and why, in words, for the driver's start-up line.
walking::GaitParams ChooseGait(const RobotModel& m, int foot, double sole_z, double pelvis_height,
                               const walking::GaitParams& base, const OdeDriverOptions& options,
                               std::string* said) {
  std::string why;
  const walking::LegGeometry leg = walking::MeasureLeg(m, foot, sole_z, pelvis_height, &why);
  const bool derived = options.gait == "fast" && why.empty();
  walking::GaitParams g = derived
                              ? walking::DeriveGait(leg, base, options.gravity > 0 ? options.gravity : 9.81)
                              : walking::SlowGait(base);
  if (derived) {
    *said = "gait from the leg (thigh " + Num(leg.thigh) + " m, shank " + Num(leg.shank) + " m, joints " +
            Num(leg.joint_speed) + " rad/s)";
  } else if (options.gait != "fast") {
    *said = "the slow gait (gait=" + options.gait + ")";
  } else {
    *said = "the slow gait: the leg cannot be measured: " + why;
  }
  const OdeDriverOptions::GaitOverrides& o = options.gait_overrides;
  for (auto [field, value] : {std::pair{&g.step_forward, o.step_length},
                              {&g.step_back, o.step_back},
                              {&g.step_side, o.step_side},
                              {&g.step_yaw, o.step_yaw},
                              {&g.single_support, o.single_support},
                              {&g.double_support, o.double_support},
                              {&g.step_height, o.step_height}}) {
    if (value > 0) *field = value;
  }
  if (o.step_yaw > 0) g.step_yaw_in = std::min(g.step_yaw_in, o.step_yaw);
  *said += ": steps " + Num(g.step_forward) + " m forward, " + Num(g.step_back) + " back, " +
           Num(g.step_side) + " sideways, " + Num(g.step_yaw) + " rad turning, every " +
           Num(g.single_support) + " + " + Num(g.double_support) + " s";
  return g;
}

Eigen::Isometry3d Planar(const Pose2& p, double z) {
  Eigen::Isometry3d x = Eigen::Isometry3d::Identity();
  x.translation() = Eigen::Vector3d(p.x, p.y, z);
  x.linear() = Eigen::AngleAxisd(p.theta, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  return x;
}

// a ⊕ b: b given in a's frame, in a's parent frame.
Pose2 Compose(const Pose2& a, const Pose2& b) {
  const Eigen::Vector2d p = a.Apply(b.x, b.y);
  return {p.x(), p.y(), Wrap(a.theta + b.theta)};
}
Pose2 Inverse(const Pose2& a) {
  const double c = std::cos(a.theta), s = std::sin(a.theta);
  return {-(c * a.x + s * a.y), -(-s * a.x + c * a.y), -a.theta};
}

}  // namespace

std::unique_ptr<WalkingHumanoid> WalkingHumanoid::Create(const RobotModel& model,
                                                         const std::vector<CollisionShape>& shapes,
                                                         const OdeDriverOptions& options, double step,
                                                         std::string* why) {
  const double gravity = options.gravity;
  if (model.roots().empty() || model.roots().front().base != BaseType::kFloating) {
    *why = "not a floating base";
    return nullptr;
  }
  const std::optional<int> l = FindAnyLink(model, {"left_foot", "l_foot", "LFoot", "l_ankle"});
  const std::optional<int> r = FindAnyLink(model, {"right_foot", "r_foot", "RFoot", "r_ankle"});
  if (!l || !r) {
    *why = "no feet named left_foot/right_foot, l_foot/r_foot, LFoot/RFoot or l_ankle/r_ankle (Romeo's)";
    return nullptr;
  }
  // The soles: a box per foot, or the bounding rectangle of the foot's
  // lowest contact points (collision_shapes.h, FindSole), which Prepare()
  // makes a box (kSoleBoxThickness) in place of the points.
  std::optional<Sole> sole[2];
  bool points[2] = {false, false};
  Kinematics kin(model);
  std::vector<Eigen::Isometry3d> roots(model.roots().size(), Eigen::Isometry3d::Identity());
  kin.Update(Eigen::VectorXd::Zero(model.num_dofs()), roots);
  for (int s = 0; s < 2; ++s) {
    const int foot = s == 0 ? *l : *r;
    const std::string& name = model.link(foot).name;
    sole[s] = FindSole(name, shapes, why);
    if (!sole[s]) return nullptr;
    points[s] = sole[s]->from_points;
    if (points[s]) sole[s] = FindSole(name, {sole[s]->Box(name, kSoleBoxThickness)}, why);
    const double up = kin.link_pose(foot).linear()(2, 2);
    if (up < std::cos(kMaxSoleTilt)) {
      *why = "foot '" + name + "' is not flat at the model's zero pose (its z axis " +
             Num(std::acos(std::clamp(up, -1.0, 1.0))) +
             " rad from vertical): its sole is not found from its shapes";
      return nullptr;
    }
  }
  walking::GaitParams g;
  // The footstep geometry is the smaller of the two soles (mirrored).
  g.foot_front = std::min(sole[0]->front, sole[1]->front);
  g.foot_back = std::min(sole[0]->back, sole[1]->back);
  g.foot_half_width = std::min({sole[0]->left, sole[0]->right, sole[1]->left, sole[1]->right});
  g.zmp_x = (g.foot_front - g.foot_back) / 2;
  const double sole_z = sole[0]->z;
  // Feet apart as in the model at q = 0; the pelvis sinks so that the knees bend.
  const Eigen::Vector3d lp = kin.link_pose(*l) * Eigen::Vector3d(0, 0, sole_z);
  const Eigen::Vector3d rp = kin.link_pose(*r) * Eigen::Vector3d(0, 0, sole[1]->z);
  g.foot_separation = lp.y() - rp.y();
  if (options.solver == "quickstep") {
    // Measured (docs/ode_sim.md, "Walking" and "Published humanoids"):
    // with quickstep's 50 iterations (and with 200) the simple humanoid fell
    // 4-5 s into its first GOTO; with 1000 it walked, but slower than
    // dWorldStep. Atlas (175 kg on 0.125 kg tali) cannot even stand on 50 or
    // 200: its joints sag 0.08-0.11 rad and it falls within 2 s; with 1000
    // it stands but falls in its second step. So no quickstep walking.
    throw Error(
        "OdeDriver: walk=true needs solver=step: a walking humanoid falls on quickstep "
        "(measured: the simple humanoid with 50 and with 200 iterations fell 4-5 s into its first GOTO; "
        "atlas sags and falls standing); "
        "drop solver=quickstep or walk=true");
  }
  auto w = std::unique_ptr<WalkingHumanoid>(
      new WalkingHumanoid(model, {*l, *r}, {sole_z, sole[1]->z}, g, gravity, step));
  w->pelvis_z_ = -lp.z() * (1 - kKneeDrop);
  w->soles_ = {*sole[0], *sole[1]};
  w->sole_from_points_ = {points[0], points[1]};
  // The stance: the CoM above the feet's ZMP points puts the pelvis at the stance centre.
  for (int it = 0; it < 3; ++it) {
    std::array<Eigen::Isometry3d, 2> soles{Planar(walking::FootAt({}, Side::kLeft, w->g_), 0),
                                           Planar(walking::FootAt({}, Side::kRight, w->g_), 0)};
    w->q_stance_.setZero();
    BendKnees(model, w->ik_.leg_mask(), w->q_stance_);
    w->ik_.Solve(Planar({}, w->pelvis_z_), soles, w->q_stance_);
    w->com_in_pelvis_ = w->ik_.ComInPelvis(w->q_stance_);
    w->g_.ankle_x = w->com_in_pelvis_.x() - w->g_.zmp_x;
  }
  w->g_.com_height = w->pelvis_z_ + w->com_in_pelvis_.z();
  w->g_ = ChooseGait(model, *l, sole_z, -lp.z() * (1 - kKneeDrop), w->g_, options, &w->gait_said_);
  w->sole_spring_ = SoleSpringFor(model.total_mass(), w->g_.com_height, gravity);
  w->pattern_ = walking::WalkPattern(w->g_, step, kPreviewEvery, gravity);
  w->stabilize_ = options.stabilizer;
  w->adjust_steps_ = options.stabilizer && options.step_adjustment;
  w->dcm_.emplace(w->g_.com_height, gravity);
  w->com_offset_.emplace(w->dcm_->omega());
  if (options.push_capture && !options.push_recovery) {
    throw Error("OdeDriver: push_capture=true needs push_recovery=true (the capture is how its stop steps)");
  }
  if (options.push_swing_reach > 0 && options.push_swing_reach != OdeDriverOptions{}.push_swing_reach &&
      !options.push_recovery) {  // (the default is accepted without it)
    throw Error(
        "OdeDriver: push_swing_reach needs push_recovery=true (it bounds the regeneration's landings)");
  }
  if (options.push_lift_reach > 0 && !options.push_recovery) {
    throw Error(
        "OdeDriver: push_lift_reach needs push_recovery=true (it bounds the regeneration's landings)");
  }
  if (options.push_stop_wait > 0 && !options.push_recovery) {
    throw Error("OdeDriver: push_stop_wait needs push_recovery=true (it gates the push recovery's stop)");
  }
  if (options.push_stop_land && !options.push_recovery) {
    throw Error("OdeDriver: push_stop_land needs push_recovery=true (it gates the push recovery's stop)");
  }
  if (options.push_stop_land && options.push_stop_wait <= 0) {
    throw Error(
        "OdeDriver: push_stop_land needs push_stop_wait > 0 (it is the event-driven stop's other wait)");
  }
  if (options.push_stop_feet != "move" && !options.push_recovery) {
    throw Error("OdeDriver: push_stop_feet=" + options.push_stop_feet +
                " needs push_recovery=true (it changes the push recovery's regeneration)");
  }
  if (options.push_step_timing != "off" && !options.push_recovery) {
    throw Error("OdeDriver: push_step_timing=" + options.push_step_timing +
                " needs push_recovery=true (it re-plans the push recovery's steps)");
  }
  if (options.push_balance != "off" && !options.push_recovery) {
    throw Error("OdeDriver: push_balance=" + options.push_balance +
                " needs push_recovery=true (it acts while the push recovery's stop holds)");
  }
  {  // parts checked by the option parser: off, both, or damping/stabilizer/forces joined by '+'
    const std::string& b = options.push_balance;
    const auto has = [&](const char* part) { return b.find(part) != std::string::npos; };
    w->push_damping_ = b == "both" || has("damping");
    w->push_stabilizer_ = b == "both" || has("stabilizer");
    if (has("forces")) {  // the loop's rate on the feet's sole springs (4 corners each)
      w->push_forces_.emplace(step, walking::ForceDifferenceFor(4 * w->sole_spring_.stiffness, kForceRate));
    }
  }
  walking::RecoveryParams recovery;
  recovery.capture_stop = options.push_capture;
  recovery.swing_reach = options.push_swing_reach;
  recovery.lift_reach = options.push_lift_reach;
  recovery.min_swing = options.push_min_swing;
  recovery.stop_wait = options.push_stop_wait;
  if (!options.push_stop_land) recovery.touch_share = 0;  // every landing "touched": no landing waits
  w->weight_ = model.total_mass() * gravity;
  using TimingMode = walking::RecoveryParams::TimingMode;
  recovery.step_timing = options.push_step_timing == "push"        ? TimingMode::kPush
                         : options.push_step_timing == "threshold" ? TimingMode::kThreshold
                         : options.push_step_timing == "always"    ? TimingMode::kAlways
                                                                   : TimingMode::kOff;
  using StopFeet = walking::RecoveryParams::StopFeet;
  recovery.stop_feet = options.push_stop_feet == "keep"    ? StopFeet::kKeep
                       : options.push_stop_feet == "still" ? StopFeet::kStill
                                                           : StopFeet::kMove;
  if (options.push_recovery) w->recovery_.emplace(w->dcm_->omega(), step, recovery);
  if (options.push_recovery) w->com_estimate_.emplace(w->dcm_->omega(), step);
  w->damp_feet_ = options.foot_damping;
  if (options.foot_damping ||
      w->push_damping_) {  // the admittance from the sole's springs (walking/foot_damping.h)
    walking::FootDampingGains fg;
    fg.admittance = walking::AdmittanceFor(w->sole_spring_.stiffness, w->g_.foot_front + w->g_.foot_back);
    w->foot_damping_.emplace(model.total_mass() * gravity, step, fg);
  }
  return w;
}

WalkingHumanoid::SoleSpring WalkingHumanoid::SoleSpringFor(double mass, double com_height, double gravity) {
  // The tuned model's rocking on the tuned sole (w0 wide): ω0² = k0 w0² /
  // (m0 h0²) − g0 / h0, damping ratio ζ0 = c0 w0² / (2 m0 h0² ω0). Kept on
  // that sole: k = m h² (ω0² + g / h) / w0², c scales by m h² / (m0 h0²).
  constexpr double kTunedGravity = 9.81;
  const double w0_sq = kSoleTunedWidth * kSoleTunedWidth;
  const double i0 = kSoleTunedMass * kSoleTunedComHeight * kSoleTunedComHeight;  // kg m²
  const double omega0_sq = kSoleStiffness * w0_sq / i0 - kTunedGravity / kSoleTunedComHeight;
  const double inertia = mass * com_height * com_height;
  const auto rounded = [](double scale) { return std::round(scale * 1000) / 1000; };
  SoleSpring s;
  s.stiffness =
      kSoleStiffness * rounded(inertia * (omega0_sq + gravity / com_height) / w0_sq / kSoleStiffness);
  s.damping = kSoleDamping * rounded(inertia / i0);
  return s;
}

WalkingHumanoid::WalkingHumanoid(const RobotModel& model, std::array<int, 2> feet,
                                 std::array<double, 2> sole_z, const walking::GaitParams& g, double gravity,
                                 double step)
    : model_(model),
      g_(g),
      pattern_(g, step, kPreviewEvery, gravity),
      ik_(model, feet, {Eigen::Vector3d(0, 0, sole_z[0]), Eigen::Vector3d(0, 0, sole_z[1])}),
      step_(step),
      feet_(feet) {
  const auto mask = ik_.leg_mask();
  owned_.assign(mask.begin(), mask.end());
  const int n = model.num_dofs();
  for (Eigen::VectorXd* v : {&q_ref_, &q_prev_, &q_start_, &q_stance_}) v->setZero(n);
}

void WalkingHumanoid::Prepare(OdeWorldOptions& world, std::vector<CollisionShape>& shapes) {
  world.place_on_ground = true;
  // A sole from contact points stands on its box: measured on atlas.urdf
  // (docs/ode_sim.md, "Published humanoids"), the box's four contacts walk
  // as well as the eight points and step 1.6x faster.
  for (int s = 0; s < 2; ++s) {
    if (!sole_from_points_[static_cast<size_t>(s)]) continue;
    const std::string& link = model_.link(feet_[static_cast<size_t>(s)]).name;
    const Sole& sole = soles_[static_cast<size_t>(s)];
    std::erase_if(shapes, [&](const CollisionShape& c) {
      return c.link == link && c.kind == CollisionShape::Kind::kSphere &&
             c.origin.translation.z() - c.size.x() <= sole.z + kSoleFlatness;
    });
    shapes.push_back(sole.Box(link, kSoleBoxThickness));
  }
}

void WalkingHumanoid::Attach(OdeWorld& world, JointServos& servos, const std::vector<CollisionShape>&) {
  world_ = &world;
  for (int f : feet_) world_->SetContactSpring(f, sole_spring_.stiffness, sole_spring_.damping);
  vmax_ = servos.vmax();
  fmax_ = servos.fmax();
  for (Eigen::Index i = 0; i < static_cast<Eigen::Index>(owned_.size()); ++i) {
    if (Owns(i)) servos.GiveToBase(i);
  }
  q_start_ = world_->q();
  q_ref_ = q_start_;
  BendKnees(model_, ik_.leg_mask(), q_ref_);  // the first solve starts bent; the servos follow from q_start_
  Eigen::Isometry3d pelvis;
  std::array<Eigen::Isometry3d, 2> soles;
  // The plan frame starts as the world, the stance around the feet where
  // they stand, the planned CoM at rest over them; DesiredPelvis() moves the
  // pelvis there from where it stands during the first kSettle s.
  plan_to_world_ = {};
  const Pose2 l = MeasuredFoot(Side::kLeft), r = MeasuredFoot(Side::kRight);
  Pose2 centre{0.5 * (l.x + r.x), 0.5 * (l.y + r.y), Wrap(r.theta + 0.5 * Wrap(l.theta - r.theta))};
  const Eigen::Vector2d mid = centre.Apply(-g_.ankle_x, 0);
  centre.x = mid.x();
  centre.y = mid.y();
  pattern_.Reset(centre, centre.Apply(g_.ankle_x + g_.zmp_x, 0));
  pelvis_start_ = MeasuredPelvis().xy();
  settle_ticks_ = std::llround(kSettle / step_);
  DesiredPelvis(&pelvis, &soles);
  ik_.Solve(pelvis, soles, q_ref_);
  q_prev_ = q_start_;
  ramp_ticks_ = std::max<std::int64_t>(1, std::llround(kRamp / step_));
}

Pose2 WalkingHumanoid::MeasuredPelvis() const { return RootPose2(*world_, model_); }

Pose2 WalkingHumanoid::ToPlan(const Pose2& world) const { return Compose(Inverse(plan_to_world_), world); }
Pose2 WalkingHumanoid::ToWorld(const Pose2& plan) const { return Compose(plan_to_world_, plan); }

// The plan frame is re-anchored so that the planned support foot (on the
// ground: the stance foot, or the left one in double support) is where the
// physics measures it. The feet do not move while they carry the robot, so
// this is the drift of the plan (slip) without the pelvis' tracking errors.
void WalkingHumanoid::MapFrames() {
  const Side sup = pattern_.support_side();
  plan_to_world_ = Compose(MeasuredFoot(sup), Inverse(pattern_.foot(sup)));
}

Pose2 WalkingHumanoid::MeasuredFoot(Side side) const {
  const Eigen::Isometry3d f = world_->LinkPose(feet_[static_cast<size_t>(side)]);
  return {f.translation().x(), f.translation().y(), std::atan2(f.linear()(1, 0), f.linear()(0, 0))};
}

void WalkingHumanoid::DesiredPelvis(Eigen::Isometry3d* pelvis,
                                    std::array<Eigen::Isometry3d, 2>* soles) const {
  const Pose2& l = pattern_.foot(Side::kLeft);
  const Pose2& r = pattern_.foot(Side::kRight);
  const double yaw = Wrap(r.theta + 0.5 * Wrap(l.theta - r.theta));
  const Eigen::Vector2d com =
      pattern_.com() + (com_offset_ ? com_offset_->offset() : Eigen::Vector2d::Zero());
  Pose2 p{0, 0, yaw};
  const Eigen::Vector2d off = p.Apply(com_in_pelvis_.x(), com_in_pelvis_.y());
  p.x = com.x() - off.x();
  p.y = com.y() - off.y();
  double z = pelvis_z_;
  if (tick_ < settle_ticks_) {  // sink and move over the feet smoothly from the straight-legged start
    const double s = static_cast<double>(tick_) / static_cast<double>(settle_ticks_);
    const double blend = 0.5 * (1 - std::cos(std::numbers::pi * s));
    const double z0 = pelvis_z_ / (1 - kKneeDrop) - 0.002;
    z = z0 + (pelvis_z_ - z0) * blend;
    p.x = pelvis_start_.x() + (p.x - pelvis_start_.x()) * blend;
    p.y = pelvis_start_.y() + (p.y - pelvis_start_.y()) * blend;
  }
  *pelvis = Planar(p, z);
  (*soles)[0] = Planar(l, pattern_.foot_height(Side::kLeft));
  (*soles)[1] = Planar(r, pattern_.foot_height(Side::kRight));
}

void WalkingHumanoid::PlanGoto() {
  MapFrames();
  const walking::WalkPattern::Splice from = pattern_.DropUnstarted();
  const Pose2 goal = ToPlan(goal_);
  const std::vector<walking::PlannedStep> plan =
      walking::PlanFootsteps(from.centre, goal, g_, 400, nullptr, from.side_free ? nullptr : &from.next);
  std::vector<Footstep> steps;
  std::vector<Pose2> centres;
  for (const walking::PlannedStep& p : plan) {
    steps.push_back(p.step);
    centres.push_back(p.centre);
  }
  pattern_.Append(steps, centres);
  replanned_at_ = pattern_.started_steps();
}

bool WalkingHumanoid::Drives(int joint) const {
  const int first = model_.dof_offset(joint);
  for (int k = 0; k < static_cast<int>(model_.joint(joint).dofs.size()); ++k) {
    if (Owns(first + k)) return true;
  }
  return false;
}

std::optional<DriverResult> WalkingHumanoid::Release(int joint, std::string_view command) {
  if (!Drives(joint)) return std::nullopt;
  return Answer(Signal::kBusy, std::string(command) + " " + driver_support::Quote(model_.joint(joint).name) +
                                   ": the leg is driven by the walking controller");
}

void WalkingHumanoid::StopOnly(const StopScope& scope, std::vector<Completion>& completed) {
  if (scope.base || std::any_of(scope.joints.begin(), scope.joints.end(), [&](int j) { return Drives(j); }))
    Stop("interrupted by STOP", completed);
}

bool WalkingHumanoid::moving() const {
  return !fallen_ && (!pattern_.standing() || tick_ < settle_ticks_ + ramp_ticks_);
}

DriverResult WalkingHumanoid::Goto(const DriverCommand& c) {
  if (auto bad = CheckBaseValues(c)) return *bad;
  if (fallen_)
    return Answer(Signal::kError, "GOTO: the robot has fallen (torso tilt " + Num(tilt_) + " rad)");
  if (mode_ == Mode::kGoto) {
    return Answer(Signal::kBusy,
                  "GOTO: a walk to a GOTO is in progress (command " + std::to_string(goto_id_) + ")");
  }
  goal_ = {c.values[0], c.values[1], Wrap(c.values[2])};
  const Pose2 at = MeasuredPelvis();
  if (pattern_.standing() && std::hypot(at.x - goal_.x, at.y - goal_.y) <= kTolerance &&
      std::abs(Wrap(at.theta - goal_.theta)) <= kHeadingTolerance) {
    return Answer(Signal::kSuccess);
  }
  mode_ = Mode::kGoto;
  goto_id_ = c.id;
  tries_ = 1;
  PlanGoto();
  DriverResult r;
  r.in_progress = true;
  return r;
}

DriverResult WalkingHumanoid::SetSpeed(const DriverCommand& c) {
  if (auto bad = CheckBaseValues(c)) return *bad;
  if (fallen_)
    return Answer(Signal::kError, "SETSPEED: the robot has fallen (torso tilt " + Num(tilt_) + " rad)");
  if (mode_ == Mode::kGoto) {
    return Answer(Signal::kBusy,
                  "SETSPEED: a walk to a GOTO is in progress (command " + std::to_string(goto_id_) + ")");
  }
  const double want[3] = {c.values[0], c.num_values == 3 ? c.values[1] : 0.0, c.values[c.num_values - 1]};
  const std::array<double, 3> clamped = walking::ClampSpeed(want[0], want[1], want[2], g_);
  const char* names[3] = {"v", "vy", "omega"};
  const char* units[3] = {"m/s", "m/s", "rad/s"};
  double got[3];
  std::string note;
  for (int i = 0; i < 3; ++i) {
    got[i] = clamped[static_cast<size_t>(i)];
    if (got[i] != want[i]) {
      note += std::string(note.empty() ? "" : "; ") + names[i] + " " + Num(want[i]) + " " + units[i] +
              " clamped to the gait's limit " + Num(got[i]) + " " + units[i];
    }
  }
  v_ = got[0];
  vy_ = got[1];
  omega_ = got[2];
  std::vector<Completion> none;
  if (v_ == 0 && vy_ == 0 && omega_ == 0) {
    Stop("", none);
  } else {
    mode_ = Mode::kSpeed;
    pattern_.DropUnstarted();
    KeepSpeedStepsQueued();
  }
  return note.empty() ? Answer(Signal::kSuccess) : Answer(Signal::kModified, "SETSPEED: " + note);
}

void WalkingHumanoid::KeepSpeedStepsQueued() {
  // Steps are planned far enough ahead that appending the next never cuts
  // into the preview's look-ahead (the walk goes on without a pause).
  const double ahead = g_.start_lead + kQueuedSpeedSteps * g_.step_period();
  while (pattern_.unstarted_steps() < kQueuedSpeedSteps || pattern_.planned_ahead() < ahead) {
    const walking::WalkPattern::Splice at = pattern_.AppendPoint();
    const Pose2 centre = at.centre;
    Side next = at.next;
    if (at.side_free) next = (vy_ < 0 || (vy_ == 0 && omega_ < 0)) ? Side::kRight : Side::kLeft;
    const double period = g_.step_period();
    const double dy = vy_ * 2 * period * (vy_ * walking::SideSign(next) > 0 ? 1.0 : 0.0);
    // A turn alternates steps toes apart (up to step_yaw) and together (up to step_yaw_in).
    const double turn = std::abs(omega_) * period, inward = std::min(turn, g_.step_yaw_in);
    const double yaw =
        std::copysign(omega_ * walking::SideSign(next) >= 0 ? 2 * turn - inward : inward, omega_);
    const Pose2 c = walking::StepBy(centre, v_ * period, dy, yaw, next, g_);
    pattern_.Append({Footstep{next, walking::FootAt(c, next, g_)}}, {c});
  }
}

void WalkingHumanoid::Stop(const std::string& why, std::vector<Completion>& completed) {
  if (mode_ == Mode::kGoto) {
    completed.push_back(
        Completion{.id = goto_id_, .signal = Signal::kInterrupted, .message = "GOTO: " + why});
  }
  mode_ = Mode::kIdle;
  v_ = vy_ = omega_ = 0;
  if (!fallen_) pattern_.StopSoon();
}

void WalkingHumanoid::FinishGoto(std::vector<Completion>& completed) {
  const Pose2 at = MeasuredPelvis();
  const double d = std::hypot(at.x - goal_.x, at.y - goal_.y);
  const double e = std::abs(Wrap(at.theta - goal_.theta));
  const bool precise = d <= kPrecision && e <= kHeadingPrecision;
  if (d <= kTolerance && e <= kHeadingTolerance && (precise || tries_ > kRetries)) {
    completed.push_back(Completion{.id = goto_id_, .signal = Signal::kSuccess, .message = {}});
    mode_ = Mode::kIdle;
    return;
  }
  if (tries_ <= kRetries) {
    ++tries_;
    PlanGoto();  // closed loop: walk again from the measured pose
    return;
  }
  completed.push_back(Completion{.id = goto_id_,
                                 .signal = Signal::kInterrupted,
                                 .message = "GOTO: stopped " + Num(d) + " m and " + Num(e) +
                                            " rad from the goal after " + std::to_string(tries_) + " plans"});
  mode_ = Mode::kIdle;
}

void WalkingHumanoid::Control(std::vector<Completion>& completed) {
  ++tick_;
  const Eigen::Isometry3d root = world_->LinkPose(model_.roots().front().link);
  tilt_ = std::acos(std::clamp(root.linear()(2, 2), -1.0, 1.0));
  const Eigen::VectorXd& q = world_->q();
  if (!fallen_ && tilt_ > kFallTilt) {
    fallen_ = true;
    char tilt[32];
    std::snprintf(tilt, sizeof tilt, "%.2f", tilt_);
    fall_ = std::string("the robot has fallen (torso tilt ") + tilt + " rad)";
    if (mode_ == Mode::kGoto) {
      completed.push_back(Completion{.id = goto_id_,
                                     .signal = Signal::kInterrupted,
                                     .message = "GOTO: the robot fell (torso tilt " + Num(tilt_) + " rad)"});
    }
    mode_ = Mode::kIdle;
  }
  if (fallen_) {  // limp would be safer for hardware; here the joints hold where they are
    for (Eigen::Index i = 0; i < q.size(); ++i) {
      if (Owns(i)) world_->SetMotor(static_cast<int>(i), 0, fmax_[i]);
    }
    return;
  }
  MeasureContacts();
  // push_recovery: a push stops the walk and the robot stands a while (walking/push_recovery.h).
  using Walk = walking::PushRecovery::Walk;
  const Walk walk =
      recovery_ && tick_ >= settle_ticks_ ? recovery_->Watch(pattern_, com_estimate_->impulse()) : Walk::kOn;
  if (mode_ == Mode::kGoto && walk == Walk::kResume) PlanGoto();
  if (mode_ == Mode::kSpeed && walk != Walk::kHold) KeepSpeedStepsQueued();
  if (recovery_ && tick_ >= settle_ticks_) GateLift();
  pattern_.Tick();
  Balance();
  AdjustStep();
  Eigen::Isometry3d pelvis;
  std::array<Eigen::Isometry3d, 2> soles;
  DesiredPelvis(&pelvis, &soles);
  DampFeet(&soles);
  ik_.Solve(pelvis, soles, q_ref_);
  com_in_pelvis_ = ik_.ComInPelvis(q_ref_);
  // The servos' targets: the IK's, faded in from the joints at start-up
  // (the first bent-knee solution is not where the straight legs stand).
  const double ramp = std::min(1.0, static_cast<double>(tick_) / static_cast<double>(ramp_ticks_));
  const double fade = 0.5 * (1 - std::cos(std::numbers::pi * ramp));
  tracking_error_ = 0;
  for (Eigen::Index i = 0; i < q.size(); ++i) {
    if (!Owns(i)) continue;
    const double target = q_start_[i] + fade * (q_ref_[i] - q_start_[i]);
    tracking_error_ = std::max(tracking_error_, std::abs(q_prev_[i] - q[i]));
    const double qd_ref = (target - q_prev_[i]) / step_;
    const double v = std::clamp(qd_ref + kKp * (target - q[i]), -vmax_[i], vmax_[i]);
    world_->SetMotor(static_cast<int>(i), v, fmax_[i]);
    q_prev_[i] = target;
  }
  if (mode_ == Mode::kGoto && walk != Walk::kHold && pattern_.settled(kSettled)) {
    FinishGoto(completed);
  } else if (mode_ == Mode::kGoto && pattern_.started_steps() - replanned_at_ >= kReplanSteps &&
             pattern_.unstarted_steps() > 2) {
    PlanGoto();  // the feet slip (most when turning): re-plan from the measured pose
  }
}

}  // namespace robotalk::ode_detail
