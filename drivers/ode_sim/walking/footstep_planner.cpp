// Footstep planning: see footstep_planner.h.
#include "walking/footstep_planner.h"

#include <algorithm>
#include <cmath>

namespace robotalk::walking {
namespace {

constexpr double kReachedXY = 1e-3;    // m
constexpr double kReachedYaw = 1e-3;   // rad
constexpr double kTinyLateral = 1e-9;  // m: no lateral component

}  // namespace

Pose2 StepBy(const Pose2& centre, double dx, double dy, double dyaw, Side swing, const GaitParams& g,
             bool* clamped) {
  double cx = std::clamp(dx, -g.step_back, g.step_forward);
  double cy = std::clamp(dy, -g.step_side, g.step_side);
  if (cy * SideSign(swing) < 0) cy = 0;  // never step toward the stance foot
  // Together: the translation within the ellipse of the forward (backward)
  // and sideways limits, the turn within what the translation leaves.
  const double r = StepFraction(cx, cy, g);
  if (r > 1) cx /= r, cy /= r;
  const double yaw_limit =
      (dyaw * SideSign(swing) >= 0 ? g.step_yaw : g.step_yaw_in) *  // toes apart / together
      (1 - kTurnWhileStepping * std::min(r, 1.0));
  const double cyaw = std::clamp(dyaw, -yaw_limit, yaw_limit);
  if (clamped) *clamped = cx != dx || cyaw != dyaw || std::abs(cy - dy) > kTinyLateral;
  const Eigen::Vector2d p = centre.Apply(cx, cy);
  return {p.x(), p.y(), Wrap(centre.theta + cyaw)};
}

double StepFraction(double dx, double dy, const GaitParams& g) {
  const double lx = dx >= 0 ? g.step_forward : g.step_back;
  return std::hypot(lx > 0 ? dx / lx : 0.0, g.step_side > 0 ? dy / g.step_side : 0.0);
}

Pose2 StepToward(const Pose2& centre, const Pose2& goal, Side swing, const GaitParams& g) {
  const double c = std::cos(centre.theta), s = std::sin(centre.theta);
  const double gx = goal.x - centre.x, gy = goal.y - centre.y;
  const double lx = c * gx + s * gy, ly = -s * gx + c * gy;  // goal in the centre's frame
  const double dist = std::hypot(lx, ly);
  if (dist > g.approach_radius) {
    const double bearing = std::atan2(ly, lx);
    if (std::abs(bearing) > g.walk_cone) return StepBy(centre, 0, 0, bearing, swing, g);  // turn first
    // Walk, steering toward the goal, stopping the long walk at the approach radius's edge.
    const double along = std::max(0.0, lx - 0.5 * g.approach_radius);
    return StepBy(centre, along, ly, bearing, swing, g);
  }
  return StepBy(centre, lx, ly, Wrap(goal.theta - centre.theta), swing, g);
}

Side FirstSwing(const Pose2& start, const Pose2& goal) {
  const double c = std::cos(start.theta), s = std::sin(start.theta);
  const double ly = -s * (goal.x - start.x) + c * (goal.y - start.y);
  if (std::abs(ly) > kReachedXY) return ly > 0 ? Side::kLeft : Side::kRight;
  const double turn = Wrap(goal.theta - start.theta);
  if (std::abs(turn) > kReachedYaw) return turn > 0 ? Side::kLeft : Side::kRight;
  return Side::kLeft;
}

std::vector<PlannedStep> PlanFootsteps(const Pose2& start, const Pose2& goal, const GaitParams& g,
                                       int max_steps, bool* reached, const Side* first) {
  std::vector<PlannedStep> plan;
  const auto at_goal = [&](const Pose2& p) {
    return std::hypot(p.x - goal.x, p.y - goal.y) < kReachedXY &&
           std::abs(Wrap(p.theta - goal.theta)) < kReachedYaw;
  };
  if (reached) *reached = true;
  if (at_goal(start)) return plan;
  Pose2 centre = start;
  Side swing = first ? *first : FirstSwing(start, goal);
  while (static_cast<int>(plan.size()) < max_steps) {
    centre = StepToward(centre, goal, swing, g);
    if (at_goal(centre)) centre = goal;  // no sub-millimetre residue
    plan.push_back({{swing, FootAt(centre, swing, g)}, centre});
    swing = Other(swing);
    if (at_goal(centre)) {  // the trailing foot comes alongside
      plan.push_back({{swing, FootAt(centre, swing, g)}, centre});
      return plan;
    }
  }
  if (reached) *reached = false;
  return plan;
}

}  // namespace robotalk::walking
