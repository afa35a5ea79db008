// Footstep planning for the walking controller: where the feet go, step by
// step, from one stance to another (GOTO) or at a commanded rate (SETSPEED).
// Pure maths, no ODE, no I/O; allocates only the returned vector.
//
// A step moves the stance centre (gait.h) by (dx, dy, dyaw) in its own frame,
// clamped to GaitParams' limits: dx in [-step_back, step_forward], a
// sideways dy only toward the swing foot's side (|dy| <= step_side; a step
// toward the stance foot would cross the legs), so a lateral walk moves on
// every second step; (dx, dy) together within the ellipse of those limits
// (a diagonal step is no longer than the leg reaches); |dyaw| <= step_yaw
// turning toward the swing foot's side (toes apart), <= step_yaw_in toward
// the stance foot's (toes together), both less while the step translates
// (StepFraction). The swing foot lands at
// FootAt(new centre, side). Toward a goal farther than approach_radius the
// centre turns toward the goal and walks forward (translating only when the
// goal lies within walk_cone of ahead); closer, it steps straight to the goal
// pose (sideways, backwards, turning). The plan ends with both feet around
// the goal centre: the last step brings the trailing foot alongside.
//
// Thread safety: free functions, no state.
#pragma once

#include "walking/gait.h"

#include <vector>

namespace robotalk::walking {

/// The stance centre after one step of `swing` by (dx, dy, dyaw) (its own
/// frame), clamped to the step limits; *clamped (if not null) says whether
/// the request was changed.
Pose2 StepBy(const Pose2& centre, double dx, double dy, double dyaw, Side swing, const GaitParams& g,
             bool* clamped = nullptr);

/// How much of the step limits a translation (dx, dy) uses: 1 on the
/// ellipse through (step_forward or -step_back, 0) and (0, +-step_side).
double StepFraction(double dx, double dy, const GaitParams& g);
/// A step turns at most (1 - kTurnWhileStepping x StepFraction) of step_yaw
/// (step_yaw_in): a full-length step turns half as much as a turn in place.
inline constexpr double kTurnWhileStepping = 0.5;

/// One step of `swing` from `centre` toward `goal` (the rules above).
Pose2 StepToward(const Pose2& centre, const Pose2& goal, Side swing, const GaitParams& g);

/// A footstep with the stance centre it was placed around.
struct PlannedStep {
  Footstep step;
  Pose2 centre;
};

/// Steps from a stance around `start` (both feet at FootAt(start, ...)) to a
/// stance around `goal`, the first swing foot chosen toward the goal's side
/// (or its turn). Empty when already there (within 1 mm and 1 mrad). At most
/// `max_steps` steps; *reached (if not null) says whether the plan ends at the goal.
/// `first`: the first swing side, or FirstSwing() when not given.
std::vector<PlannedStep> PlanFootsteps(const Pose2& start, const Pose2& goal, const GaitParams& g,
                                       int max_steps = 400, bool* reached = nullptr,
                                       const Side* first = nullptr);

/// The first swing side toward a goal: the side it lies on, else the side
/// of the turn, else left.
Side FirstSwing(const Pose2& start, const Pose2& goal);

}  // namespace robotalk::walking
