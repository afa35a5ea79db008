// Step timing adaptation together with step location (issue 26, item 4;
// docs/ode_sim.md, "Earlier and faster capture steps"). Pure maths, no ODE;
// tests/drivers/step_timing_test.cpp pushes a linear inverted pendulum.
//
// In single support the DCM xi = c + c'/w of a linear inverted pendulum
// whose centre of pressure holds at p moves as
//   xi(t) = p + (xi0 - p) e^{w t},
// so a step landing T s from now at u leaves the DCM offset b = xi(T) - u
// from the new foot. A walk plans a landing u_nom at T_nom with the offset
// b_nom its next steps expect. After a push xi0 is elsewhere; moving only
// the landing (what the regeneration does, push_recovery.h) lets the error
// grow e^{w T_nom} until a landing that reach may not allow. With the time
// free as well (Khadiv et al. 2016/2020, "Step timing adjustment" and
// "Walking control based on step timing adaptation"; Griffin et al. 2017,
// IHMC's step timing and location adjustment on Atlas; read, not copied),
// the next landing and its time are one small problem: with tau = e^{w T},
//   minimise  w_step |u - u_nom|^2 + w_offset |b - b_nom|^2 + w_time (tau - tau_nom)^2
//   subject to u + b = p + (xi0 - p) tau,
//              u within reach of the stance foot (a box in its frame: ahead,
//              behind, beside it never across), within what the swing foot
//              can still reach from where it is, and
//              T between the soonest the swing can land and T_nom.
// For a fixed tau the rest is a separable box-constrained least squares
// (exact per axis in the stance foot's frame), so the solver scans tau over
// T's range (`resolution`) and keeps the cheapest. An undisturbed walk
// (xi0 on the plan) returns the plan exactly: T_nom, u_nom.
//
// Threading: none needed (no state). Allocation: none.
#pragma once

#include "walking/gait.h"

#include <Eigen/Core>

namespace robotalk::walking {

struct StepTimingParams {
  double w_step = 1.0;       ///< per m^2 of landing moved
  double w_offset = 1000.0;  ///< per m^2 of the DCM offset at the landing off the plan's
  double w_time = 5.0;       ///< per unit of tau = e^{wT} off the plan's
  // The landing's ankle from the stance foot's ankle, in that foot's frame.
  double reach = 0.45;        ///< m ahead at most
  double reach_back = 0.30;   ///< m behind at most
  double min_width = 0.14;    ///< m sideways at least (never across the stance foot)
  double max_width = 0.40;    ///< m sideways at most
  double resolution = 0.005;  ///< s: the scan's step over T
};

/// One step's situation (the plan's frame; metres, seconds).
struct StepSituation {
  Eigen::Vector2d dcm = Eigen::Vector2d::Zero();      ///< the measured DCM now
  Eigen::Vector2d cop = Eigen::Vector2d::Zero();      ///< the stance CoP held until the landing
  Pose2 stance;                                       ///< the stance foot (its ankle point and yaw)
  Side swing = Side::kLeft;                           ///< the side of the foot that lands
  Eigen::Vector2d landing = Eigen::Vector2d::Zero();  ///< u_nom: the planned landing (ankle point)
  Eigen::Vector2d offset = Eigen::Vector2d::Zero();   ///< b_nom: the plan's DCM at its landing, from u_nom
  double remaining = 0;                               ///< T_nom: s until the planned landing (> 0)
  double soonest = 0;  ///< s from now: the soonest the swing can land (<= remaining)
  /// The swing foot now, and how far it moves per s left (0: no such bound):
  /// the landing at most max(|u_nom - foot|, foot_speed * T) from it.
  Eigen::Vector2d foot = Eigen::Vector2d::Zero();
  double foot_speed = 0;
};

struct StepTiming {
  double remaining = 0;                                      // T: s from now to the landing
  Eigen::Vector2d landing = Eigen::Vector2d::Zero();         // u
  Eigen::Vector2d dcm_at_landing = Eigen::Vector2d::Zero();  // xi(T) on the held CoP
  double cost = 0;
  /// The DCM offset at the landing is the plan's (the problem's constraints did not bind).
  bool fits = false;
};

class StepTimingAdapter {
 public:
  /// omega = sqrt(g / z_c) > 0, weights > 0, reach, widths and resolution
  /// sensible (0 < min_width <= max_width), else std::invalid_argument.
  explicit StepTimingAdapter(double omega, StepTimingParams params = {});
  /// The next landing and its time (above). REQUIRES remaining > 0 and
  /// 0 <= soonest (clamped to remaining).
  StepTiming Solve(const StepSituation& s) const;
  const StepTimingParams& params() const { return p_; }
  double omega() const { return omega_; }

 private:
  double omega_;
  StepTimingParams p_;
};

}  // namespace robotalk::walking
