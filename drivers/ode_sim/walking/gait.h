// Shared types of the walking controller (drivers/ode_sim/walking): planar
// poses, footsteps and the gait's parameters. Pure data, no ODE, no I/O.
//
// Conventions: world frame, z up, metres, radians, seconds. A *stance
// centre* is the planar pose of the pelvis that the feet are placed around:
// a foot stands at centre + R(theta) * (ankle_x, +-separation/2), the left
// one at +y. A foot's pose is its ankle's projection on the ground and the
// foot's yaw.
#pragma once

#include "ode_walk_status.h"  // Wrap, Pose2: part of the driver's public status

#include <Eigen/Core>

#include <cmath>
#include <numbers>

namespace robotalk::walking {

enum class Side : int { kLeft = 0, kRight = 1 };
inline Side Other(Side s) { return s == Side::kLeft ? Side::kRight : Side::kLeft; }
inline double SideSign(Side s) { return s == Side::kLeft ? 1.0 : -1.0; }

struct Footstep {
  Side side = Side::kLeft;
  Pose2 pose;  ///< the foot's ankle point on the ground and its yaw
};

/// The gait. Defaults are the slow gait of models/simple_humanoid.urdf
/// (0.10 m every 1.1 s; the pure tests use them); the ode driver fills the
/// geometry from the model and by default derives the steps and timing from
/// the legs (gait_limits.h, option gait=fast; docs/ode_sim.md, "Walking").
struct GaitParams {
  // Step limits, per step, of the stance centre in its own frame.
  double step_forward = 0.10;  ///< m
  double step_back = 0.05;     ///< m
  double step_side = 0.05;     ///< m, only toward the swing foot's side
  double step_yaw = 0.2;       ///< rad, turning toward the swing foot's side (toes apart)
  double step_yaw_in = 0.2;    ///< rad, turning toward the stance foot's side (toes together), <= step_yaw
  // Timing.
  double single_support = 0.8;  ///< s
  double double_support = 0.3;  ///< s
  double start_lead = 1.0;      ///< s: standing still after a start (the preview's look-ahead)
  double start_shift = 0.8;     ///< s: the first shift of weight onto the stance foot
  double end_shift = 0.8;       ///< s: the last shift back to the centre
  double step_height = 0.04;    ///< m: swing foot clearance
  // Geometry (from the model).
  double foot_separation = 0.18;  ///< m, between the ankles
  double ankle_x = 0.0;           ///< m, ankle ahead of the pelvis in the stance
  double zmp_x = 0.02;            ///< m, the ZMP's point under a foot, ahead of the ankle
  double foot_front = 0.15, foot_back = 0.09, foot_half_width = 0.06;  ///< m, sole around the ankle
  double com_height = 0.70;                                            ///< m, for the LIPM
  // Walking toward a far goal: turn toward it, walk, then step to the final pose.
  double approach_radius = 0.25;  ///< m: closer than this, step sideways/backwards instead of turning
  double walk_cone = 0.3;         ///< rad: translate only when the goal is this close to ahead

  double step_period() const { return single_support + double_support; }
};

/// Where a foot stands around a stance centre.
inline Pose2 FootAt(const Pose2& centre, Side side, const GaitParams& g) {
  const Eigen::Vector2d p = centre.Apply(g.ankle_x, SideSign(side) * 0.5 * g.foot_separation);
  return {p.x(), p.y(), centre.theta};
}

}  // namespace robotalk::walking
