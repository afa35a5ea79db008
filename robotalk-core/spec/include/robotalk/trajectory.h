// A pure trajectory: per-dof piecewise polynomials through timed waypoints,
// sampled at any time for position, velocity and acceleration. No I/O, no
// clock: every time is a TimePoint given by the caller (docs/specification.md,
// "Trajectories").
//
// Knots. Knot 0 is the actuator's state at the start time (position, velocity,
// acceleration: where it is, not where it was asked to be). Every waypoint
// after it is a knot. Velocities and accelerations not given are chosen when
// the waypoints are added, from that batch and the knot before it, and never
// change afterwards (so a splice never moves the past):
//  - velocity (kCubic, kQuintic): the three-point rule, the slope of the
//    parabola through the knot and its neighbours, (h1·d0 + h0·d1)/(h0 + h1)
//    for the adjacent slopes d0, d1 over spacings h0, h1; zero where one of
//    them is zero (a repeated position: a plateau, a stop); zero at the last
//    waypoint of a batch. At a turn the curve may pass the turning waypoint
//    (a cubic by at most h·|v|/4 for a segment of duration h whose knots'
//    velocities are at most |v|); the server clamps references to the joint
//    limits whatever the plan.
//  - acceleration (kQuintic): the central difference of the knot velocities
//    either side, (v[k+1] - v[k-1]) / (t[k+1] - t[k-1]); zero at the last
//    waypoint of a batch.
//
// Interpolation (segment k runs from knot k to knot k+1):
//  - kStep: the value is knot k's position on [t[k], t[k+1]) and jumps to the
//    next at t[k+1]; velocity and acceleration are zero (RoboTalk's set-point).
//  - kLinear: a straight line; velocity steps at each knot.
//  - kCubic: the cubic Hermite segment through both knots' positions and
//    velocities: position and velocity continuous (C1).
//  - kQuintic: the quintic Hermite segment through positions, velocities and
//    accelerations: C2.
//
// Before the start time a sample is the trajectory's value at the start time. After the last knot the
// trajectory holds (starvation): the last position with zero velocity; if the last knot's velocity is not
// zero (kCubic, kQuintic: given, or the start state with no waypoints), each dof decelerates to rest at its
// hold deceleration (constant deceleration, so it stops v²/(2·a) past the last knot) and holds there. kStep
// and kLinear hold the last position at once.
//
// Thread safety: none; const members may be called concurrently.
// Real time: Sample() does not allocate once the sample is sized (MakeSample);
// Append(), Splice() and Forget() do not allocate once the knot storage has
// grown to the most knots the trajectory has held (it doubles when full, and
// never shrinks); the constructor, CheckLimits() and ScaleToLimits() allocate.
#pragma once

#include "robotalk/clock.h"
#include "robotalk/error.h"

#include <Eigen/Core>

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace robotalk {

/// Its value is its wire code (package_header_t's INTERPOLATION_*).
enum class Interpolation : std::int8_t { kStep = 0, kLinear = 1, kCubic = 2, kQuintic = 3 };

/// "step", "linear", "cubic", "quintic".
const char* InterpolationName(Interpolation interpolation);
/// Parses those names (any case); nullopt for another word.
std::optional<Interpolation> ParseInterpolation(std::string_view name);

/// Position, velocity, acceleration of every dof (rad or m, per s, per s²).
struct TrajectoryState {
  Eigen::VectorXd position;
  Eigen::VectorXd velocity;
  Eigen::VectorXd acceleration;
};

/// A timed waypoint. `velocity` and `acceleration` are optional: empty means
/// "not given" (chosen by the rule above); otherwise one value per dof.
struct Waypoint {
  TimePoint time;
  Eigen::VectorXd position;
  Eigen::VectorXd velocity;
  Eigen::VectorXd acceleration;
};

/// What Sample() fills. `holding`: after the last knot.
struct TrajectorySample {
  Eigen::VectorXd position;
  Eigen::VectorXd velocity;
  Eigen::VectorXd acceleration;
  bool holding = false;
};

/// Limits per dof; an empty vector means "no limit" for that quantity.
/// velocity and acceleration are magnitudes (> 0); position_min <= position_max.
struct TrajectoryLimits {
  Eigen::VectorXd position_min;
  Eigen::VectorXd position_max;
  Eigen::VectorXd velocity;
  Eigen::VectorXd acceleration;
};

/// The extremes of a trajectory per dof, from a time on, the hold included.
struct LimitCheck {
  Eigen::VectorXd max_velocity;      ///< largest |velocity|
  Eigen::VectorXd max_acceleration;  ///< largest |acceleration|
  Eigen::VectorXd min_position;
  Eigen::VectorXd max_position;
  bool within = true;
  /// Every limit exceeded, "dof 1: |velocity| 3.2 exceeds the limit 2", "; "-separated.
  std::string violations;
};

/// What ScaleToLimits changed (for a MODIFIED reply).
struct TimeScaling {
  bool changed = false;
  std::string reason;         ///< the violations before scaling ("" when none)
  double largest_factor = 1;  ///< the largest stretch of one segment (new/old duration)
  Duration old_end{};         ///< last knot time - start time, before
  Duration new_end{};         ///< and after
  LimitCheck after;           ///< within == false: limits that time cannot fix
};

class Trajectory {
 public:
  /// Starts at `start_time` from `start` (the actuator's state; an empty
  /// velocity or acceleration means zero). `hold_deceleration`: per dof,
  /// > 0, the deceleration used to stop after the last knot.
  /// @throw Error naming the bad value (non-finite, wrong size, <= 0).
  Trajectory(Interpolation interpolation, TimePoint start_time, const TrajectoryState& start,
             const Eigen::VectorXd& hold_deceleration);

  /// Adds waypoints after the last knot; their times strictly increasing and
  /// after it. @throw Error naming the waypoint and value.
  void Append(std::span<const Waypoint> waypoints);
  void Append(const std::vector<Waypoint>& waypoints) { Append(std::span<const Waypoint>(waypoints)); }

  /// Replaces everything after `t` with `waypoints` (times strictly after t,
  /// increasing): the trajectory up to t is unchanged and a knot at t carries
  /// its sampled position, velocity and acceleration, so the result is
  /// continuous there to the order of the interpolation. t before the start
  /// is the start; t after the last knot splices onto the hold.
  /// @throw Error naming the waypoint and value (the trajectory is unchanged).
  void Splice(TimePoint t, std::span<const Waypoint> waypoints);
  void Splice(TimePoint t, const std::vector<Waypoint>& waypoints) {
    Splice(t, std::span<const Waypoint>(waypoints));
  }

  /// Drops the knots of segments that end at or before `t` (the segment
  /// holding t stays), so a trajectory spliced forever stays bounded; its
  /// first remaining knot becomes the start. Samples at or after t do not
  /// change; earlier ones return the new start.
  void Forget(TimePoint t);

  /// A sample sized for this trajectory.
  TrajectorySample MakeSample() const;
  /// Samples at t into `out`. REQUIRES: out sized by MakeSample() (no allocation).
  void Sample(TimePoint t, TrajectorySample* out) const;

  /// The extremes from `from` on (the hold included) against `limits`.
  /// @throw Error on bad limits (wrong size, negative, non-finite, min > max).
  LimitCheck CheckLimits(const TrajectoryLimits& limits, TimePoint from = TimePoint::min()) const;

  /// Stretches the segments that start at or after `from` until velocity and
  /// acceleration stay within `limits` (position limits are reported, not
  /// fixed). Knot 0 (the actuator's state) is never changed; a stretched
  /// segment's knot velocities scale by 1/factor and accelerations by 1/factor².
  /// `from` should be a knot's time (the start, or the time of a Splice): a
  /// segment that began before it is not stretched.
  /// @throw Error on bad limits.
  TimeScaling ScaleToLimits(const TrajectoryLimits& limits, TimePoint from = TimePoint::min());

  Interpolation interpolation() const { return interpolation_; }
  int num_dofs() const { return static_cast<int>(hold_deceleration_.size()); }
  /// Knot 0 is the start; knot i > 0 the waypoints.
  int num_knots() const { return static_cast<int>(times_.size()); }
  TimePoint knot_time(int k) const { return times_[static_cast<std::size_t>(k)]; }
  /// Knot k's position, velocity and acceleration (the chosen ones included).
  TrajectoryState knot(int k) const;
  TimePoint start_time() const { return times_.front(); }
  TimePoint end_time() const { return times_.back(); }

 private:
  void Resolve(std::size_t first);  // choose missing v/a for knots >= first
  // A segment's polynomial coefficients for one dof, c[0..5]: value = sum c[i] tau^i.
  void Coefficients(std::size_t segment, int dof, double* c) const;
  void Evaluate(std::size_t segment, double tau, int dof, double* p, double* v, double* a) const;
  void EvaluateHold(double tau, int dof, double* p, double* v, double* a) const;
  void CheckWaypoints(TimePoint after, std::span<const Waypoint> waypoints) const;
  // Appends one knot (empty velocity / acceleration: not given, chosen by Resolve).
  void AddKnot(TimePoint time, const Eigen::VectorXd& position, const Eigen::VectorXd& velocity,
               const Eigen::VectorXd& acceleration);
  // Appends `waypoints`, then chooses the missing rates from knot `first` on.
  void AddKnots(std::span<const Waypoint> waypoints, std::size_t first);

  Interpolation interpolation_;
  Eigen::VectorXd hold_deceleration_;
  std::vector<TimePoint> times_;
  // Knot states, one column per knot (the first num_knots() columns: the
  // rest is capacity); given_* marks values the caller gave.
  Eigen::MatrixXd p_, v_, a_;
  TrajectorySample splice_sample_;  // Splice()'s state at the splice time (sized once)
  std::vector<bool> given_v_, given_a_;
};

}  // namespace robotalk
