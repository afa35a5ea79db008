// The gait from the model: see gait_limits.h.
#include "walking/gait_limits.h"

#include "walking/footstep_planner.h"

#include "robotalk/kinematics.h"
#include "robotalk/robot_model.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <vector>

namespace robotalk::walking {
namespace {

constexpr double kPi = std::numbers::pi;
// How much of each limit the gait uses (the rest is the servos' and the
// balance's margin). First choices, not tuned; docs/ode_sim.md has what they walk.
constexpr double kDoubleSupportTc = 0.75;  // double support, x Tc
constexpr double kSingleTc = 2.0;          // single support, x Tc
constexpr double kMaxStretch = 0.96;       // of thigh + shank: the straightest leg
constexpr double kJointSpeedUse = 0.8;     // of the slowest pitch joint's velocity limit
// The longest forward step, of thigh + shank. Measured, not derived: the
// simple humanoid's swing-rate step (0.22 m of a 0.6 m leg) walks; Atlas
// (0.8 m leg, 12 rad/s joints: only the reach bounds it) fell in its first
// goal on its reach-limited step and walks 20 goals at 0.29 m (docs/ode_sim.md).
constexpr double kMaxStepOfLeg = 0.37;
// The widest sideways step, of the sole's width (2 x foot_half_width).
// Measured, not derived: a sideways swing pushes the stance sole's centre of
// pressure to its edge (ODE traces: 5.9 of 6.0 cm on the simple humanoid at
// its 0.16 m step on a 0.12 m sole; both edges on Atlas at 0.23 m on its
// 0.125 m sole, which then rocked on its edge through the turning steps after
// it and fell; docs/ode_sim.md). The hip roll's step grows with the leg, the
// support with the sole: this is the simple humanoid's own ratio (0.16 / 0.12).
constexpr double kSideOfSole = 1.34;
constexpr double kSwingWindow = 0.8;        // of single support: the foot moves (walk_pattern.h)
constexpr double kBackFraction = 0.5;       // backward step, of the forward one
constexpr double kHipRollUse = 0.6;         // of the outward hip roll range
constexpr double kHipYawUse = 0.8;          // of the hip yaw range
constexpr double kSoleClearance = 0.01;     // m between the soles when turning
constexpr double kStepHeightOfLeg = 0.067;  // swing height, of thigh + shank
constexpr double kRound = 0.01;             // s and m: lengths rounded down, durations up to this

double RoundDown(double v) { return std::floor(v / kRound + 1e-9) * kRound; }
double RoundUp(double v) { return std::ceil(v / kRound - 1e-9) * kRound; }

std::array<Eigen::Vector2d, 4> Sole(const Pose2& f, const GaitParams& g) {
  return {f.Apply(g.foot_front, g.foot_half_width), f.Apply(-g.foot_back, g.foot_half_width),
          f.Apply(-g.foot_back, -g.foot_half_width), f.Apply(g.foot_front, -g.foot_half_width)};
}

double SegmentDistance(const Eigen::Vector2d& p, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  const Eigen::Vector2d ab = b - a;
  const double t = std::clamp((p - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0);
  return (a + t * ab - p).norm();
}

// The swing's peak hip pitch rate for a step of length `step` (m): the foot
// moves `step` relative to the hip on a cosine profile within the swing
// window of single support (twice that over the ground, less the pelvis' own
// travel), about a hip `hip_height` above it.
double SwingRate(double step, double single, double period, double hip_height) {
  const double peak = 0.5 * kPi * 2 * step / (kSwingWindow * single) - step / period;
  return peak / hip_height;
}

}  // namespace

double SoleClearance(const Pose2& a, const Pose2& b, const GaitParams& g) {
  const auto pa = Sole(a, g), pb = Sole(b, g);
  // Separating axes (the edge normals): overlap on every axis = penetration.
  double penetration = std::numeric_limits<double>::infinity();
  for (const auto* poly : {&pa, &pb}) {
    for (int i = 0; i < 4; ++i) {
      const Eigen::Vector2d e = (*poly)[(i + 1) % 4] - (*poly)[i];
      const Eigen::Vector2d n(-e.y(), e.x());
      const Eigen::Vector2d u = n.normalized();
      double amin = 1e9, amax = -1e9, bmin = 1e9, bmax = -1e9;
      for (const auto& p : pa) amin = std::min(amin, p.dot(u)), amax = std::max(amax, p.dot(u));
      for (const auto& p : pb) bmin = std::min(bmin, p.dot(u)), bmax = std::max(bmax, p.dot(u));
      penetration = std::min(penetration, std::min(amax - bmin, bmax - amin));
    }
  }
  if (penetration >= 0) return -penetration;
  double d = std::numeric_limits<double>::infinity();
  for (int i = 0; i < 4; ++i) {
    for (int j = 0; j < 4; ++j) {
      d = std::min(d, SegmentDistance(pa[i], pb[j], pb[(j + 1) % 4]));
      d = std::min(d, SegmentDistance(pb[i], pa[j], pa[(j + 1) % 4]));
    }
  }
  return d;
}

LegGeometry MeasureLeg(const RobotModel& model, int foot, double sole_z, double pelvis_height,
                       std::string* why) {
  why->clear();
  LegGeometry leg;
  const int root = model.roots().front().link;
  std::vector<int> chain;  // joints from the foot up
  for (int link = foot; link != root;) {
    int parent = -1;
    for (int j = 0; j < static_cast<int>(model.joints().size()); ++j) {
      if (model.joint(j).child_link == link) parent = j;
    }
    if (parent < 0) {
      *why = "the foot is not below the first root";
      return leg;
    }
    if (model.joint(parent).dofs.size() == 1) chain.push_back(parent);
    link = model.joint(parent).parent_link;
  }
  Kinematics kin(model);
  std::vector<Eigen::Isometry3d> roots(model.roots().size(), Eigen::Isometry3d::Identity());
  kin.Update(Eigen::VectorXd::Zero(model.num_dofs()), roots);
  struct Axis {
    Eigen::Vector3d at, axis;
    const DofLimits* lim;
  };
  std::vector<Axis> pitch, yaw, roll;
  for (int j : chain) {
    const Eigen::Isometry3d& x = kin.link_pose(model.joint(j).child_link);
    const Dof& d = model.joint(j).dofs[0];
    const Eigen::Vector3d a = x.linear() * d.axis;
    const Axis ax{x.translation(), a, &d.limits};
    if (std::abs(a.y()) > 0.9) pitch.push_back(ax);
    if (std::abs(a.z()) > 0.9) yaw.push_back(ax);
    if (std::abs(a.x()) > 0.9) roll.push_back(ax);
  }
  if (pitch.size() < 3) {
    *why = "the leg has fewer than three pitch joints (hip, knee, ankle)";
    return leg;
  }
  // chain runs foot -> hip: the ankle pitch first, the hip pitch last.
  const Eigen::Vector3d ankle = pitch.front().at, hip = pitch.back().at;
  const Axis* knee = nullptr;
  double best = -1;
  for (size_t i = 1; i + 1 < pitch.size(); ++i) {
    const double d = std::min((pitch[i].at - ankle).norm(), (pitch[i].at - hip).norm());
    if (d > best) best = d, knee = &pitch[i];
  }
  leg.thigh = (hip - knee->at).norm();
  leg.shank = (knee->at - ankle).norm();
  const Eigen::Vector3d root_at = kin.link_pose(root).translation();
  // The pelvis `pelvis_height` above the sole; the hip (hip - root) below it.
  leg.hip_height = pelvis_height + (hip.z() - root_at.z()) - (-sole_z);
  leg.hip_width = 2 * std::abs(hip.y() - root_at.y());
  leg.joint_speed = std::numeric_limits<double>::infinity();
  for (const Axis& a : pitch) leg.joint_speed = std::min(leg.joint_speed, a.lim->velocity);
  if (!yaw.empty()) {
    const DofLimits& l = *yaw.back().lim;
    leg.hip_yaw = std::min(std::abs(l.lower), std::abs(l.upper));
  }
  if (!roll.empty()) {  // outward: toward the foot's side (+x axis roll: negative on the left)
    const DofLimits& l = *roll.back().lim;
    const bool left = hip.y() > root_at.y();
    const double sign = roll.back().axis.x() > 0 ? 1.0 : -1.0;
    leg.hip_roll_out = std::abs((left ? -sign : sign) > 0 ? l.upper : l.lower);
  }
  if (!(leg.thigh > 0 && leg.shank > 0 && leg.hip_height > 0 && std::isfinite(leg.joint_speed))) {
    *why = "the leg's lengths or velocity limits are missing";
  }
  return leg;
}

GaitParams SlowGait(const GaitParams& base) {
  GaitParams g = base;
  const GaitParams d;
  g.step_forward = d.step_forward;
  g.step_back = d.step_back;
  g.step_side = d.step_side;
  g.step_yaw = d.step_yaw;
  g.step_yaw_in = d.step_yaw_in;
  g.single_support = d.single_support;
  g.double_support = d.double_support;
  g.step_height = d.step_height;
  return g;
}

GaitParams DeriveGait(const LegGeometry& leg, const GaitParams& base, double gravity, GaitBounds* bounds) {
  GaitParams g = base;
  GaitBounds b;
  b.tc = std::sqrt(base.com_height / gravity);
  const double length = leg.thigh + leg.shank;
  g.double_support = RoundUp(kDoubleSupportTc * b.tc);
  // Reach: each foot half a step from the hip with the leg at most kMaxStretch long.
  const double stretched = kMaxStretch * length;
  b.reach_step = 2 * std::sqrt(std::max(0.0, stretched * stretched - leg.hip_height * leg.hip_height));
  // Single support: kSingleTc Tc (the pendulum's own pace; the step's
  // length, not its duration, then follows the joints' speed).
  const double rate = kJointSpeedUse * leg.joint_speed;
  g.single_support = RoundUp(kSingleTc * b.tc);
  const double single = g.single_support;
  const double period = g.single_support + g.double_support;
  // The longest step that swing allows at that timing (bisection: the rate grows with the step).
  double lo = 0, hi = b.reach_step;
  for (int i = 0; i < 40; ++i) {
    const double mid = 0.5 * (lo + hi);
    (SwingRate(mid, single, period, leg.hip_height) <= rate ? lo : hi) = mid;
  }
  b.speed_step = lo;
  b.leg_step = kMaxStepOfLeg * length;
  g.step_forward = RoundDown(std::min({b.reach_step, b.speed_step, b.leg_step}));
  g.step_back = RoundDown(kBackFraction * g.step_forward);
  // Sideways: the swing foot lands step_side beyond its place, the hip still
  // over the stance foot's side: its leg reaches out by separation/2 +
  // step_side - hip_width/2 + (separation - hip_width)/2 at most.
  const double out0 =
      base.foot_separation - leg.hip_width;  // the swing leg's lateral offset with no side step
  b.roll_side = std::max(0.0, leg.hip_height * std::tan(kHipRollUse * leg.hip_roll_out) - out0);
  b.reach_side =
      std::max(0.0, std::sqrt(std::max(0.0, stretched * stretched - leg.hip_height * leg.hip_height)) - out0);
  // And the sole's lateral support (kSideOfSole).
  b.sole_side = kSideOfSole * 2 * base.foot_half_width;
  g.step_side = RoundDown(std::min({b.roll_side, b.reach_side, b.sole_side}));
  // Turning: the pelvis turns midway between the feet, so a hip yaws half a
  // step's turn; and the soles keep kSoleClearance apart with one foot turned
  // about the stance centre (outward: toes apart; inward: toes together).
  b.hip_yaw_turn = 2 * kHipYawUse * leg.hip_yaw;
  const auto turn_limit = [&](Side moving) {  // the centre turns left with `moving`, the other foot stays
    double lo_yaw = 0, hi_yaw = std::max(0.0, b.hip_yaw_turn);
    const Pose2 still = FootAt({}, Other(moving), base);
    for (int i = 0; i < 40; ++i) {
      const double mid = 0.5 * (lo_yaw + hi_yaw);
      const bool clear = SoleClearance(FootAt({0, 0, mid}, moving, base), still, base) >= kSoleClearance;
      (clear ? lo_yaw : hi_yaw) = mid;
    }
    return lo_yaw;
  };
  const double outward = turn_limit(Side::kLeft), inward = turn_limit(Side::kRight);
  b.sole_turn = outward;
  b.sole_turn_in = inward;
  g.step_yaw = RoundDown(std::min(b.hip_yaw_turn, outward));
  g.step_yaw_in = std::min(g.step_yaw, RoundDown(inward));
  g.step_height = RoundDown(kStepHeightOfLeg * length + 0.005);
  // A goal within two forward steps is stepped to directly (sideways,
  // backwards): cheaper than turning toward it and back.
  g.approach_radius = std::max(base.approach_radius, 2 * g.step_forward);
  if (bounds) *bounds = b;
  return g;
}

GaitSpeeds SpeedsOf(const GaitParams& g) {
  const double t = g.step_period();
  return {g.step_forward / t, g.step_back / t, g.step_side / (2 * t), (g.step_yaw + g.step_yaw_in) / (2 * t)};
}

std::array<double, 3> ClampSpeed(double v, double vy, double omega, const GaitParams& g) {
  const GaitSpeeds top = SpeedsOf(g);
  v = std::clamp(v, -top.back, top.forward);
  vy = std::clamp(vy, -top.side, top.side);
  const double period = g.step_period();
  const double r = StepFraction(v * period, 2 * vy * period, g);
  if (r > 1) v /= r, vy /= r;
  const double turn = top.turn * (1 - kTurnWhileStepping * std::min(r, 1.0));
  return {v, vy, std::clamp(omega, -turn, turn)};
}

}  // namespace robotalk::walking
