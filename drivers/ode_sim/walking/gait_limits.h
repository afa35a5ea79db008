// The gait from the model: step length, sideways step, turn per step and
// the step's timing derived from the legs' geometry, joint limits and sole
// (docs/ode_sim.md, "Walking", "The gait from the model"). Pure maths, no
// ODE; MeasureLeg reads a RobotModel's kinematics (no physics).
//
// The rules, each a bound the gait must respect (the constants in
// gait_limits.cpp say how much of a limit is used):
// - Timing from the linear inverted pendulum (time constant Tc =
//   sqrt(com_height / g)): double support kDoubleSupportTc x Tc (the time
//   the ZMP takes from one foot to the other; much shorter and the CoM
//   cannot follow it), single support kSingleTc x Tc (the pendulum's
//   pace: a longer step is cheaper than a quicker one).
// - Step length (forward): the knee's reach, the stretched leg (at most
//   kMaxStretch of thigh + shank, where the knee is near its singularity)
//   from the hip at its walking height, on both legs at once (the feet
//   half a step before and behind the hip in double support); and the
//   swing's joint rate: the foot's peak speed relative to the hip (a
//   cosine move within the swing window) within kJointSpeedUse of the
//   slowest pitch joint's velocity limit; and at most kMaxStepOfLeg of thigh
//   + shank (a measured bound, not derived: Atlas, whose fast joints leave
//   only the reach, fell on its reach-limited step). Backwards: kBackFraction of forward (the
//   heel edge is shorter and the swing foot cannot see).
// - Sideways: the outward hip roll and the reach (the swing foot lands
//   `step_side` beyond its place while the hip is still over the stance foot);
//   and at most kSideOfSole of the sole's width (a measured bound, not
//   derived: the swing pushes the stance sole's centre of pressure to its
//   edge; Atlas, whose hip roll allows a step wider for its sole, fell rocking
//   on its sole's edge after such steps).
// - Turning: half a step's turn per hip yaw (the pelvis turns midway between
//   the feet) within kHipYawUse of the range, and the soles at least
//   kSoleClearance apart with one foot turned about the stance centre:
//   toes apart (step_yaw) and toes together (step_yaw_in) separately.
// - Swing height: kStepHeightOfLeg of the leg length.
//
// Thread safety: free functions, no state.
#pragma once

#include "walking/gait.h"

#include <array>
#include <string>

namespace robotalk {
class RobotModel;
}

namespace robotalk::walking {

/// One leg of the model and the joint limits that bound the gait. Lengths m,
/// angles rad, rates rad/s.
struct LegGeometry {
  double thigh = 0;         ///< hip (pitch axis) to knee
  double shank = 0;         ///< knee to ankle
  double hip_height = 0;    ///< hip above the ankle in the walking stance
  double hip_width = 0;     ///< between the two hips (y)
  double hip_yaw = 0;       ///< the hip yaw's range either way (the smaller side); 0 = none
  double hip_roll_out = 0;  ///< the hip roll's outward range
  double joint_speed = 0;   ///< the slowest velocity limit of the hip pitch, knee and ankle pitch
};

/// The leg from `foot` up to the first root of `model` at q = 0 (the knee:
/// the chain's joint between the hip and the ankle farthest from both; hip
/// yaw/roll: the chain's joints about z / x). `hip_height` is filled from
/// `pelvis_height` (the pelvis above the sole in the stance) and the sole
/// depth `sole_z` (< 0, the sole below the ankle). Empty `why` on success;
/// else it names what is missing.
LegGeometry MeasureLeg(const RobotModel& model, int foot, double sole_z, double pelvis_height,
                       std::string* why);

/// Per-rule limits (for the docs and tests): the step each rule allows.
struct GaitBounds {
  double tc = 0;                           ///< s, LIPM time constant
  double reach_step = 0, speed_step = 0;   ///< m, forward step by the knee's reach / the swing rate
  double leg_step = 0;                     ///< m, forward step by the leg's length (measured bound)
  double roll_side = 0, reach_side = 0;    ///< m, sideways step by the hip roll / the reach
  double sole_side = 0;                    ///< m, sideways step by the sole's width (measured bound)
  double hip_yaw_turn = 0, sole_turn = 0;  ///< rad per step by the hip yaw / the soles' clearance
  double sole_turn_in = 0;                 ///< rad per step toward the stance foot (toes together)
};

/// The fast gait: `base` with its geometry (foot, separation, com_height,
/// ankle_x, zmp_x) kept and step length, side, yaw, timing, swing height
/// derived from `leg` (the rules above). *bounds (if not null) gets each rule's limit.
GaitParams DeriveGait(const LegGeometry& leg, const GaitParams& base, double gravity,
                      GaitBounds* bounds = nullptr);

/// The slow gait (0.10 m every 1.1 s) on `base`'s geometry: GaitParams' defaults.
GaitParams SlowGait(const GaitParams& base);

/// Steady speeds of a gait: forward, back, sideways (m/s) and turning
/// (rad/s), as SETSPEED's clamps compute them (a sideways walk moves on
/// every second step).
struct GaitSpeeds {
  double forward = 0, back = 0, side = 0, turn = 0;
};
GaitSpeeds SpeedsOf(const GaitParams& g);

/// A SETSPEED twist (v, vy m/s, omega rad/s) within the gait: each within
/// SpeedsOf(g), (v, vy) within the ellipse of their limits, omega within
/// what the translation leaves (footstep_planner.h's StepBy rules).
std::array<double, 3> ClampSpeed(double v, double vy, double omega, const GaitParams& g);

/// The smallest distance between the two soles (rectangles around their
/// ankles) at these poses, m; negative when they overlap (by the overlap
/// depth's lower bound 0 when they merely touch).
double SoleClearance(const Pose2& a, const Pose2& b, const GaitParams& g);

}  // namespace robotalk::walking
