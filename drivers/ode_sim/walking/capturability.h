// Capturability of the walking humanoid (issue 26, item 4; docs/ode_sim.md,
// "How large a push any controller could survive"). Pure maths, no ODE, no
// state: an upper bound on the push any stepping controller could recover,
// on the linear inverted pendulum with the model's limits.
//
// The model (Koolen, de Boer, Smith, Pratt et al., "Capturability-based
// analysis and control of legged locomotion", IJRR 2012; Pratt et al. 2006,
// the capture point; read, not copied): the DCM xi = c + c'/w of a LIPM
// (w = sqrt(g / z_c)) moves as xi' = w (xi - p), p the centre of pressure.
// - In single support p lies anywhere in the stance sole (a rectangle around
//   the ankle: `front`, `back`, `half_width`); a swing foot may land no sooner
//   than `min_swing` after its lift-off, anywhere in the reach box of the
//   stance foot (its frame: `reach` ahead, `reach_back` behind, between
//   `min_width` and `max_width` toward the swing foot's side: never across).
// - After a landing both feet carry for at least `double_support`, p anywhere
//   in the bounding box of the two soles (a superset of their hull: the bound
//   stays an upper bound); then the foot that landed carries and the other
//   one swings (feet alternate).
// - Captured: the DCM inside the support (a sole, or that box in double
//   support), where p = xi holds it still.
// A state is N-step capturable when some choice of CoP, step times (each
// no sooner than the limits allow) and places (each within reach) captures
// it within N landings. With the double support's box the constraints are
// separable per axis of the stance foot's frame, and on each axis the
// capture set is an interval whose ends come from the farthest landing
// (reach) and the soonest steps: every capture set holds the stance sole,
// so a later step or a longer double support only lets the DCM run further
// (the ends move monotonically with each step's time and place). The
// N-step regions are therefore boxes, computed backward from the 0-step
// one (the sole), and exact for this model (the bounding box aside).
//
// Closed forms (tests/drivers/capturability_test.cpp): with E = e^{-w T}
// for the first swing's T and D = e^{-w d} for the double support,
//   0 steps: [-back, front] x [-half_width, half_width];
//   1 step, forward: front + reach E (Koolen's r + l e^{-w dt});
//   infinitely many, forward, each swing min_swing: front + reach E / (1 - E D).
// Toward the stance foot's side, a swing foot that never crosses catches
// nothing beyond the stance sole by itself; only the step after it can.
//
// Frames: world (plan) frame, metres, seconds; the feet of one situation
// share a yaw (a straight walk; the box is taken in that yaw's frame).
// Threading: free functions, no state. Allocation: none.
#pragma once

#include "walking/gait.h"

#include <Eigen/Core>

namespace robotalk::walking {

struct CaptureLimits {
  double omega = 3.74;  ///< 1/s, sqrt(g / com_height)
  // The stance sole (the centre of pressure's range) around its ankle, m.
  double front = 0.15, back = 0.09, half_width = 0.06;
  // The landing's ankle from the stance ankle, in the stance foot's frame, m.
  double reach = 0.45, reach_back = 0.30, min_width = 0.14, max_width = 0.40;
  double min_swing = 0.35;       ///< s from a lift-off to its landing, at the soonest
  double double_support = 0.10;  ///< s from a landing to the next lift-off, at the soonest
  /// m/s, 0: off. The first landing (the foot in the air, or in double
  /// support the first to lift) at most this far per s of its swing from
  /// where that foot is (per axis: the box around that disc, so still an
  /// upper bound); its time then scanned (5 ms) up to 1 s beyond the
  /// soonest. Later steps are bounded by the reach box alone.
  double swing_speed = 0;
};

struct Interval {
  double lo = 0, hi = 0;
  bool Contains(double v) const { return lo <= v && v <= hi; }
};

/// A capture region: intervals of the DCM along the stance foot's x (ahead)
/// and y (left) from a reference point (the stance ankle, or the world origin).
struct CaptureBox {
  Interval x, y;
  bool Contains(const Eigen::Vector2d& p) const { return x.Contains(p.x()) && y.Contains(p.y()); }
};

/// In single support with the foot on side `swing` in the air, its landing
/// no sooner than `first` s from now (>= 0): the DCMs, from the stance ankle
/// in its frame, that at most `steps` (>= 0) landings capture.
CaptureBox SingleSupportRegion(const CaptureLimits& l, Side swing, double first, int steps);

/// Where the walk is when pushed.
struct CaptureSituation {
  bool double_support = false;
  Pose2 feet[2];             ///< ankle points (left, right); in single support the swing foot's is unused
  Side swing = Side::kLeft;  ///< single support: the foot in the air
  /// Single support: s until the swing foot may land at the soonest;
  /// double support: s until either foot may lift at the soonest.
  double soonest = 0;
  Eigen::Vector2d dcm = Eigen::Vector2d::Zero();  ///< the DCM before the push
};

class WalkPattern;  // walk_pattern.h

/// Where a walk on its plan is now: its feet, the foot in the air, the
/// plan's DCM, and the soonest landing (`min_swing` after the lift-off,
/// taken as single_support before the planned landing) or lift-off
/// (`double_support` after the landing, `since_landing` s ago).
CaptureSituation SituationOf(const WalkPattern& w, double since_landing, const CaptureLimits& l);

/// How far (m) the DCM may be displaced from s.dcm along `dir` (a unit
/// vector, world frame) and still be captured within `steps` landings (in
/// double support, either foot may lift first); 0 when s.dcm itself is not.
double CapturableShift(const CaptureLimits& l, const CaptureSituation& s, const Eigen::Vector2d& dir,
                       int steps);

/// The DCM's displacement (m per N s) by a push of constant force over
/// `duration` s (>= 0) on a LIPM of `mass` kg, referred to the push's start
/// (the same DCM afterwards whatever the CoP does meanwhile: the dynamics
/// are linear): (1 - e^{-w D}) / (w D) / (m w); 1 / (m w) for an impulse.
double DcmShiftPerImpulse(double mass, double omega, double duration);

/// Enough steps for the infinite-step limit (the regions grow by less than
/// 1e-9 m beyond it with this model's limits).
inline constexpr int kManyCaptureSteps = 40;

}  // namespace robotalk::walking
