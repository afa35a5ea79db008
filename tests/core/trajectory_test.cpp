#include "robotalk/trajectory.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <limits>
#include <new>
#include <numbers>
#include <random>

#include "support/allocation_counter.h"  // g_allocations, g_mallocs

namespace robotalk {
namespace {

using Eigen::VectorXd;
using std::chrono::microseconds;
using std::chrono::milliseconds;
using std::chrono::nanoseconds;
using ::testing::HasSubstr;

const TimePoint kT0{std::chrono::seconds(1000)};
TimePoint Ms(double ms) {
  return kT0 + std::chrono::duration_cast<Duration>(std::chrono::duration<double, std::milli>(ms));
}

VectorXd V(std::initializer_list<double> values) {
  VectorXd v(static_cast<Eigen::Index>(values.size()));
  Eigen::Index i = 0;
  for (double x : values) v[i++] = x;
  return v;
}

TrajectoryState Rest(const VectorXd& p) { return {p, VectorXd::Zero(p.size()), VectorXd::Zero(p.size())}; }

Trajectory Make(Interpolation interpolation, const TrajectoryState& start,
                const std::vector<Waypoint>& points, double hold = 2.0) {
  Trajectory t(interpolation, kT0, start, VectorXd::Constant(start.position.size(), hold));
  t.Append(points);
  return t;
}

TrajectorySample At(const Trajectory& t, TimePoint time) {
  TrajectorySample s = t.MakeSample();
  t.Sample(time, &s);
  return s;
}

// Two dofs, uneven spacing, a turn, a plateau; some waypoints carry velocities.
std::vector<Waypoint> Points() {
  return {{Ms(100), V({0.3, -0.2}), {}, {}},
          {Ms(250), V({0.8, -0.1}), {}, {}},
          {Ms(300), V({0.5, -0.1}), V({-2.0, 0.0}), {}},
          {Ms(600), V({-0.4, 0.6}), {}, {}},
          {Ms(700), V({-0.2, 0.6}), {}, {}}};
}

// The largest jump of position, velocity and acceleration across `t` (1 ns either side).
struct Jumps {
  double p = 0, v = 0, a = 0;
};
Jumps JumpAt(const Trajectory& traj, TimePoint t) {
  const TrajectorySample before = At(traj, t - nanoseconds(1)), after = At(traj, t + nanoseconds(1));
  return {(after.position - before.position).cwiseAbs().maxCoeff(),
          (after.velocity - before.velocity).cwiseAbs().maxCoeff(),
          (after.acceleration - before.acceleration).cwiseAbs().maxCoeff()};
}

constexpr double kJump = 1e-4;  // far above 2 ns of any slope here, far below a real step

TEST(Trajectory, EveryInterpolationPassesExactlyThroughItsWaypoints) {
  for (Interpolation kind :
       {Interpolation::kStep, Interpolation::kLinear, Interpolation::kCubic, Interpolation::kQuintic}) {
    const Trajectory traj = Make(kind, Rest(V({0, 0})), Points());
    for (const Waypoint& w : Points()) {
      EXPECT_LT((At(traj, w.time).position - w.position).norm(), 1e-12) << InterpolationName(kind);
    }
  }
}

TEST(Trajectory, StepJumpsAtEachWaypointsTimeWithZeroVelocity) {
  const Trajectory traj = Make(Interpolation::kStep, Rest(V({0, 0})), Points());
  EXPECT_EQ(At(traj, Ms(99.999)).position, V({0, 0}));
  EXPECT_EQ(At(traj, Ms(100)).position, V({0.3, -0.2}));
  EXPECT_EQ(At(traj, Ms(249.999)).position, V({0.3, -0.2}));
  EXPECT_EQ(At(traj, Ms(250)).position, V({0.8, -0.1}));
  EXPECT_EQ(At(traj, Ms(150)).velocity, V({0, 0}));
  EXPECT_GT(JumpAt(traj, Ms(250)).p, 0.4);
}

TEST(Trajectory, LinearMovesInAStraightLineBetweenWaypoints) {
  const Trajectory traj = Make(Interpolation::kLinear, Rest(V({0, 0})), Points());
  const TrajectorySample mid = At(traj, Ms(175));
  EXPECT_NEAR(mid.position[0], 0.55, 1e-12);
  EXPECT_NEAR(mid.velocity[0], 0.5 / 0.15, 1e-9);
  EXPECT_NEAR(mid.acceleration[0], 0, 1e-12);
  EXPECT_LT(JumpAt(traj, Ms(250)).p, kJump);
  EXPECT_GT(JumpAt(traj, Ms(250)).v, 1.0);  // a linear trajectory's velocity steps: the check can fail
}

TEST(Trajectory, CubicIsContinuousInPositionAndVelocityAtEveryKnot) {
  const Trajectory traj = Make(Interpolation::kCubic, Rest(V({0, 0})), Points());
  for (const Waypoint& w : Points()) {
    EXPECT_LT(JumpAt(traj, w.time).p, kJump);
    EXPECT_LT(JumpAt(traj, w.time).v, kJump);
  }
  EXPECT_GT(JumpAt(traj, Ms(250)).a, 1.0);  // C1 only: acceleration steps
}

TEST(Trajectory, QuinticIsContinuousInPositionVelocityAndAccelerationAtEveryKnot) {
  std::vector<Waypoint> points = Points();
  points[1].acceleration = V({-30, 4});
  const Trajectory traj = Make(Interpolation::kQuintic, Rest(V({0, 0})), points);
  for (const Waypoint& w : points) {
    const Jumps j = JumpAt(traj, w.time);
    EXPECT_LT(j.p, kJump);
    EXPECT_LT(j.v, kJump);
    EXPECT_LT(j.a, 1e-3);  // 2 ns of jerk
  }
  EXPECT_NEAR(At(traj, Ms(250)).acceleration[0], -30, 1e-6);
  EXPECT_NEAR(At(traj, Ms(300)).velocity[0], -2.0, 1e-9);
}

TEST(Trajectory, TheFirstSegmentStartsFromTheActuatorsState) {
  const TrajectoryState start{V({0.1, 0.2}), V({0.5, -1.0}), V({3.0, 0.0})};
  const Trajectory quintic = Make(Interpolation::kQuintic, start, Points());
  for (TimePoint t : {kT0, kT0 - milliseconds(5), kT0 + nanoseconds(1)}) {
    const TrajectorySample s = At(quintic, t);
    EXPECT_LT((s.position - start.position).norm(), 1e-8);
    EXPECT_LT((s.velocity - start.velocity).norm(), 1e-6);
    EXPECT_LT((s.acceleration - start.acceleration).norm(), 1e-3);
  }
  const TrajectorySample cubic = At(Make(Interpolation::kCubic, start, Points()), kT0);
  EXPECT_EQ(cubic.position, start.position);
  EXPECT_EQ(cubic.velocity, start.velocity);
}

TEST(Trajectory, VelocitiesNotGivenFollowTheThreePointRuleAndPlateausStayFlat) {
  // Equal spacing: v = (d0 + d1) / 2; zero next to a repeated position and at the end.
  const Trajectory traj = Make(Interpolation::kCubic, Rest(V({0})),
                               {{Ms(100), V({0.1}), {}, {}},
                                {Ms(200), V({0.4}), {}, {}},
                                {Ms(300), V({0.4}), {}, {}},
                                {Ms(400), V({0.0}), {}, {}}});
  EXPECT_NEAR(traj.knot(1).velocity[0], (1.0 + 3.0) / 2, 1e-12);
  EXPECT_EQ(traj.knot(2).velocity[0], 0.0);  // a plateau
  EXPECT_EQ(traj.knot(3).velocity[0], 0.0);
  EXPECT_EQ(traj.knot(4).velocity[0], 0.0);  // the end
  const LimitCheck check = traj.CheckLimits({});
  EXPECT_NEAR(check.max_position[0], 0.4, 1e-12);  // approaching a stop does not pass it
  EXPECT_NEAR(check.min_position[0], 0.0, 1e-12);
  // Uneven spacing: the slope of the parabola through the three waypoints.
  const Trajectory uneven =
      Make(Interpolation::kCubic, Rest(V({0})),
           {{Ms(100), V({0.2}), {}, {}}, {Ms(400), V({0.8}), {}, {}}, {Ms(500), V({0.9}), {}, {}}});
  const double d0 = 0.6 / 0.3, d1 = 0.1 / 0.1;
  EXPECT_NEAR(uneven.knot(2).velocity[0], (0.1 * d0 + 0.3 * d1) / 0.4, 1e-12);
}

TEST(Trajectory, ATurnPassesItsWaypointByAtMostAQuarterOfVelocityTimesDuration) {
  // 0 -> 1 -> 0.9: the curve turns after the middle waypoint, as a smooth
  // motion through those points would; by at most h·|v|/4 (h = 0.1 s).
  const Trajectory traj = Make(Interpolation::kCubic, Rest(V({0})),
                               {{Ms(100), V({0.0}), {}, {}},
                                {Ms(200), V({1.0}), {}, {}},
                                {Ms(300), V({0.9}), {}, {}},
                                {Ms(400), V({0.9}), {}, {}}});
  const double v = traj.knot(2).velocity[0];
  EXPECT_NEAR(v, (10.0 - 1.0) / 2, 1e-12);
  const LimitCheck check = traj.CheckLimits({});
  EXPECT_GT(check.max_position[0], 1.0);
  EXPECT_LE(check.max_position[0], 1.0 + 0.1 * v / 4);
}

TEST(Trajectory, ASineSampledAtTenHertzIsFollowedWithinAMilliradian) {
  // docs/performance.md's kinematic goal (issue 22): a 0.5 Hz, 0.5 rad sine
  // streamed as 10 Hz position-only waypoints, cubic and quintic.
  for (double phase : {0.0, 0.3, 1.1}) {
    auto sine = [phase](double t) { return 0.5 * std::sin(std::numbers::pi * t + phase); };
    std::vector<Waypoint> points;
    for (int k = 1; k <= 40; ++k) points.push_back({Ms(100.0 * k), V({sine(0.1 * k)}), {}, {}});
    for (Interpolation kind : {Interpolation::kCubic, Interpolation::kQuintic}) {
      const Trajectory traj = Make(kind, Rest(V({sine(0)})), points);
      double worst = 0;
      for (double ms = 300; ms <= 3700; ms += 1)
        worst = std::max(worst, std::abs(At(traj, Ms(ms)).position[0] - sine(ms / 1000)));
      EXPECT_LT(worst, 0.001) << InterpolationName(kind) << " phase " << phase;
    }
  }
}

TEST(Trajectory, AccelerationsNotGivenAreTheCentralDifferenceOfVelocities) {
  const Trajectory traj = Make(Interpolation::kQuintic, Rest(V({0, 0})), Points());
  for (int k = 1; k + 1 < traj.num_knots(); ++k) {
    const VectorXd expected =
        (traj.knot(k + 1).velocity - traj.knot(k - 1).velocity) /
        std::chrono::duration<double>(traj.knot_time(k + 1) - traj.knot_time(k - 1)).count();
    EXPECT_LT((traj.knot(k).acceleration - expected).norm(), 1e-12) << k;
  }
  EXPECT_EQ(traj.knot(traj.num_knots() - 1).acceleration, V({0, 0}));
}

void ExpectSpliceContinuous(Interpolation kind, TimePoint splice) {
  const Trajectory original = Make(kind, Rest(V({0, 0})), Points());
  Trajectory traj = original;
  traj.Splice(splice, {{splice + milliseconds(80), V({1.0, 1.0}), {}, {}},
                       {splice + milliseconds(200), V({0.0, 0.0}), {}, {}}});
  const Jumps j = JumpAt(traj, splice);
  EXPECT_LT(j.p, kJump) << InterpolationName(kind);
  if (kind == Interpolation::kCubic || kind == Interpolation::kQuintic) {
    EXPECT_LT(j.v, kJump) << InterpolationName(kind);
  }
  if (kind == Interpolation::kQuintic) {
    EXPECT_LT(j.a, 1e-3);
  }
  for (double ms = 0; ms < std::chrono::duration<double, std::milli>(splice - kT0).count(); ms += 7) {
    EXPECT_LT((At(traj, Ms(ms)).position - At(original, Ms(ms)).position).norm(), 1e-9)
        << "the past moved at " << ms;
  }
  EXPECT_LT((At(traj, splice + milliseconds(80)).position - V({1.0, 1.0})).norm(), 1e-12);
}

TEST(Trajectory, SpliceInsideASegmentIsContinuousAndKeepsThePast) {
  for (Interpolation kind :
       {Interpolation::kStep, Interpolation::kLinear, Interpolation::kCubic, Interpolation::kQuintic}) {
    ExpectSpliceContinuous(kind, Ms(333.3));
  }
}

TEST(Trajectory, SpliceExactlyAtAKnotIsContinuousAndKeepsThePast) {
  // (kStep is left out: it jumps at a knot by definition, splice or not.)
  for (Interpolation kind : {Interpolation::kLinear, Interpolation::kCubic, Interpolation::kQuintic}) {
    ExpectSpliceContinuous(kind, Ms(250));
  }
}

TEST(Trajectory, SpliceAfterTheEndContinuesFromTheHold) {
  Trajectory traj = Make(Interpolation::kCubic, Rest(V({0, 0})), Points());
  traj.Splice(Ms(900), {{Ms(1000), V({0.0, 0.0}), {}, {}}});
  EXPECT_LT(JumpAt(traj, Ms(900)).v, kJump);
  EXPECT_LT((At(traj, Ms(800)).position - V({-0.2, 0.6})).norm(), 1e-12);
}

// A receding-horizon client: every 10 ms, a 200 ms trajectory (11 points, 20 ms
// apart) starting 20 ms ahead, following a sine with a little measurement noise.
TEST(Trajectory, ARecedingHorizonOfAThousandSplicesNeverStepsInVelocity) {
  for (Interpolation kind : {Interpolation::kCubic, Interpolation::kQuintic}) {
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> noise(-0.002, 0.002);
    auto target = [](double ms) { return 0.5 * std::sin(std::numbers::pi * ms / 1000.0); };
    Trajectory traj(kind, kT0, {V({0}), V({0.5 * std::numbers::pi}), {}}, V({5.0}));  // on the sine
    TrajectorySample s = traj.MakeSample();
    traj.Sample(kT0, &s);
    double previous_v = s.velocity[0], previous_p = s.position[0], max_dv = 0, max_dp = 0, max_a = 0;
    int sampled = 0;
    for (int tick = 0; tick < 1000; ++tick) {
      const double now = 10.0 * tick;
      std::vector<Waypoint> points;
      for (int i = 0; i <= 10; ++i) {
        const double t = now + 20 + 20 * i;
        points.push_back({Ms(t), V({target(t) + noise(rng)}), {}, {}});
      }
      traj.Splice(Ms(now), points);
      traj.Forget(Ms(now));
      EXPECT_LE(traj.num_knots(), 13);  // now, the knot before it, 11 waypoints
      for (int ms = 1; ms <= 10; ++ms, ++sampled) {
        traj.Sample(Ms(now + ms), &s);
        EXPECT_FALSE(s.holding);
        max_dv = std::max(max_dv, std::abs(s.velocity[0] - previous_v));
        max_dp = std::max(max_dp, std::abs(s.position[0] - previous_p));
        max_a = std::max(max_a, std::abs(s.acceleration[0]));
        previous_v = s.velocity[0];
        previous_p = s.position[0];
      }
    }
    EXPECT_EQ(sampled, 10000);
    // A step in velocity is a change in one 1 ms sample larger than the
    // sampled acceleration allows (a splice that dropped the velocity: 2.4 rad/s
    // against a bound of 0.5). Measured: max |a| 75 (cubic) and 105 (quintic)
    // rad/s² with the ±2 mrad noise, 8 and 10 without it (the sine's own: 4.9).
    EXPECT_LT(max_a, 150.0) << InterpolationName(kind);
    EXPECT_LE(max_dv, 1.2 * max_a * 1e-3) << InterpolationName(kind);
    EXPECT_LT(max_dp, 0.005) << InterpolationName(kind);  // 0.5 π rad/s · 1 ms = 1.6 mrad, plus noise
  }
}

TEST(Trajectory, ForgettingThePastChangesNoLaterSample) {
  const Trajectory original = Make(Interpolation::kQuintic, Rest(V({0, 0})), Points());
  Trajectory traj = original;
  traj.Forget(Ms(275));
  EXPECT_EQ(traj.num_knots(), 4);  // 250 ms on
  EXPECT_EQ(traj.start_time(), Ms(250));
  for (double ms = 275; ms < 900; ms += 3) {
    const TrajectorySample a = At(traj, Ms(ms)), b = At(original, Ms(ms));
    EXPECT_EQ(a.position, b.position);
    EXPECT_EQ(a.velocity, b.velocity);
  }
  traj.Forget(Ms(5000));  // into the hold: the last knot stays
  EXPECT_EQ(traj.num_knots(), 1);
  EXPECT_EQ(At(traj, Ms(6000)).position, V({-0.2, 0.6}));
}

TEST(Trajectory, HoldsAtRestAfterTheLastWaypoint) {
  const Trajectory traj = Make(Interpolation::kCubic, Rest(V({0, 0})), Points());
  const TrajectorySample s = At(traj, Ms(5000));
  EXPECT_TRUE(s.holding);
  EXPECT_EQ(s.position, V({-0.2, 0.6}));
  EXPECT_EQ(s.velocity, V({0, 0}));
  EXPECT_FALSE(At(traj, Ms(699)).holding);
}

TEST(Trajectory, AMovingLastWaypointDeceleratesToRestWithinTheHoldDeceleration) {
  // Last waypoint at 1 rad/s, hold deceleration 2 rad/s²: stops 0.5 s later, 0.25 rad on.
  const Trajectory traj =
      Make(Interpolation::kQuintic, Rest(V({0})), {{Ms(500), V({0.5}), V({1.0}), {}}}, 2.0);
  EXPECT_NEAR(At(traj, Ms(750)).velocity[0], 0.5, 1e-9);
  EXPECT_NEAR(At(traj, Ms(750)).acceleration[0], -2.0, 1e-12);
  EXPECT_NEAR(At(traj, Ms(1000)).position[0], 0.75, 1e-9);
  EXPECT_EQ(At(traj, Ms(3000)).velocity[0], 0.0);
  EXPECT_NEAR(At(traj, Ms(3000)).position[0], 0.75, 1e-12);
  EXPECT_LT(JumpAt(traj, Ms(500)).v, kJump);
  // A moving start with no waypoints stops the same way.
  Trajectory moving(Interpolation::kCubic, kT0, {V({0}), V({-1.0}), {}}, V({4.0}));
  EXPECT_NEAR(At(moving, Ms(250)).position[0], -0.125, 1e-9);
  EXPECT_EQ(At(moving, Ms(250)).velocity[0], 0.0);
}

TEST(Trajectory, SampleDoesNotAllocate) {
  const Trajectory traj = Make(Interpolation::kQuintic, Rest(V({0, 0})), Points());
  TrajectorySample s = traj.MakeSample();
  const long before = g_allocations;
  for (int ms = -10; ms < 1000; ++ms) traj.Sample(Ms(ms), &s);
  EXPECT_EQ(g_allocations, before);
}

TEST(Trajectory, SplicingAStreamDoesNotAllocateOnceSized) {
  // As the server's tracker does with a stream: splice the next waypoint at
  // the knot before the last, re-planning it, and forget the passed knots.
  Trajectory traj(Interpolation::kQuintic, Ms(0), Rest(V({0, 0})), V({20, 20}));
  std::vector<Waypoint> batch(2, Waypoint{Ms(0), V({0, 0}), {}, {}});
  TrajectorySample s = traj.MakeSample();
  long during = 0;
  for (int k = 1; k < 600; ++k) {
    const double t = 0.01 * k;
    const long before = g_mallocs;
    batch[0].time = Ms(10.0 * k);
    batch[0].position = batch[1].position;
    batch[1].time = Ms(10.0 * (k + 1));
    batch[1].position << std::sin(t), std::cos(t);
    if (k == 1) {
      traj.Append(std::span<const Waypoint>(batch.data() + 1, 1));
    } else {
      traj.Splice(Ms(10.0 * (k - 1)), batch);
    }
    traj.Sample(Ms(10.0 * k - 5), &s);
    if (traj.num_knots() > 64) traj.Forget(Ms(10.0 * k - 5));
    if (k >= 300) during += g_mallocs - before;
  }
  EXPECT_EQ(during, 0);
}

TEST(Trajectory, CheckLimitsReportsTheLargestVelocityAndAccelerationPerDof) {
  const Trajectory traj = Make(Interpolation::kLinear, Rest(V({0, 0})), {{Ms(100), V({0.5, -0.1}), {}, {}}});
  TrajectoryLimits limits{V({-1, -1}), V({0.4, 1}), V({2, 2}), {}};
  const LimitCheck check = traj.CheckLimits(limits);
  EXPECT_NEAR(check.max_velocity[0], 5.0, 1e-9);
  EXPECT_NEAR(check.max_velocity[1], 1.0, 1e-9);
  EXPECT_FALSE(check.within);
  EXPECT_THAT(check.violations, HasSubstr("dof 0: |velocity| 5 exceeds the limit 2"));
  EXPECT_THAT(check.violations, HasSubstr("dof 0: position 0.5 is above the limit 0.4"));
  EXPECT_THAT(check.violations, ::testing::Not(HasSubstr("dof 1")));
}

TEST(Trajectory, TimeScalingMakesATooFastTrajectoryFitItsLimits) {
  for (Interpolation kind : {Interpolation::kLinear, Interpolation::kCubic, Interpolation::kQuintic}) {
    Trajectory traj = Make(kind, Rest(V({0, 0})), Points(), 40.0);
    const TrajectoryLimits limits{{}, {}, V({1.5, 2.0}), V({20.0, 20.0})};
    const TrajectoryLimits velocity_only{{}, {}, V({1.5, 2.0}), {}};
    ASSERT_FALSE(traj.CheckLimits(kind == Interpolation::kLinear ? velocity_only : limits).within);
    const TimeScaling scaled = traj.ScaleToLimits(kind == Interpolation::kLinear ? velocity_only : limits);
    EXPECT_TRUE(scaled.changed);
    EXPECT_TRUE(scaled.after.within) << InterpolationName(kind) << ": " << scaled.after.violations;
    EXPECT_THAT(scaled.reason, HasSubstr("dof 0: |velocity|"));
    EXPECT_GT(scaled.new_end, scaled.old_end);
    EXPECT_GT(scaled.largest_factor, 1.0);
    EXPECT_EQ(traj.knot_time(0), kT0);  // the start stays
    for (int k = 1; k < traj.num_knots(); ++k) {
      EXPECT_EQ(traj.knot(k).position, Points()[static_cast<std::size_t>(k - 1)].position);  // the path stays
    }
  }
}

TEST(Trajectory, TimeScalingFromASpliceLeavesThePastAndTheSpliceAlone) {
  const Trajectory original = Make(Interpolation::kQuintic, Rest(V({0, 0})), Points());
  Trajectory traj = original;
  const TimePoint splice = Ms(333.3);
  traj.Splice(splice, {{Ms(360), V({1.5, 1.0}), {}, {}}, {Ms(400), V({0.0, 0.0}), {}, {}}});
  const TrajectoryLimits limits{{}, {}, V({40, 40}), V({2000, 2000})};
  ASSERT_FALSE(traj.CheckLimits(limits, splice).within);
  const TimeScaling scaled = traj.ScaleToLimits(limits, splice);
  EXPECT_TRUE(scaled.changed);
  EXPECT_TRUE(scaled.after.within) << scaled.after.violations;
  for (double ms = 0; ms < 333; ms += 7) {
    EXPECT_LT((At(traj, Ms(ms)).position - At(original, Ms(ms)).position).norm(), 1e-9) << ms;
  }
  const Jumps j = JumpAt(traj, splice);
  EXPECT_LT(j.v, kJump);
  EXPECT_LT(j.a, 1e-3);
}

TEST(Trajectory, TimeScalingLeavesAFittingTrajectoryAlone) {
  Trajectory traj = Make(Interpolation::kCubic, Rest(V({0, 0})), Points());
  const TimeScaling scaled = traj.ScaleToLimits({{}, {}, V({100, 100}), V({1e4, 1e4})});
  EXPECT_FALSE(scaled.changed);
  EXPECT_EQ(scaled.new_end, scaled.old_end);
  EXPECT_EQ(traj.knot_time(5), Ms(700));
}

TEST(Trajectory, BadInputIsRefusedNamingWhatWasWrong) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  auto message = [](auto&& f) {
    try {
      f();
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  Trajectory traj(Interpolation::kCubic, kT0, Rest(V({0, 0})), V({1, 1}));
  EXPECT_THAT(message([&] {
                traj.Append({{Ms(10), V({0, 0}), {}, {}}, {Ms(20), V({0, nan}), {}, {}}});
              }),
              HasSubstr("waypoint 1: position[1] is nan"));
  EXPECT_THAT(message([&] {
                traj.Append({{Ms(10), V({0, 0}), {}, {}}, {Ms(10), V({0, 0}), {}, {}}});
              }),
              HasSubstr("waypoint 1: time 0.01 s is not after waypoint 0's 0.01 s"));
  EXPECT_THAT(message([&] {
                traj.Append({{Ms(10), V({0, 0, 0}), {}, {}}});
              }),
              HasSubstr("waypoint 0: position has 3 values, the trajectory has 2 dofs"));
  EXPECT_THAT(message([&] {
                traj.Append({{Ms(10), V({0, 0}), V({1}), {}}});
              }),
              HasSubstr("waypoint 0: velocity has 1 values"));
  EXPECT_THAT(message([&] {
                traj.Splice(Ms(50), {{Ms(40), V({0, 0}), {}, {}}});
              }),
              HasSubstr("waypoint 0: time -0.01 s is not after the trajectory's time 0 s"));
  EXPECT_EQ(traj.num_knots(), 1);  // nothing was added
  EXPECT_THAT(message([&] {
                traj.CheckLimits({{}, {}, V({1, -2}), {}});
              }),
              HasSubstr("limits: velocity[1] is -2 (must be > 0)"));
  EXPECT_THAT(message([&] {
                traj.CheckLimits({V({1, 0}), V({0, 0}), {}, {}});
              }),
              HasSubstr("position_min[0] 1 is above position_max 0"));
  EXPECT_THAT(message([&] { Trajectory(Interpolation::kStep, kT0, Rest(V({0})), V({0})); }),
              HasSubstr("hold_deceleration[0] is 0 (must be > 0)"));
  EXPECT_THAT(message([&] {
                Trajectory(Interpolation::kStep, kT0, {V({0}), V({nan}), {}}, V({1}));
              }),
              HasSubstr("start velocity[0] is nan"));
}

TEST(Interpolation, ParsesItsNamesInAnyCaseAndNothingElse) {
  for (Interpolation i :
       {Interpolation::kStep, Interpolation::kLinear, Interpolation::kCubic, Interpolation::kQuintic}) {
    EXPECT_EQ(ParseInterpolation(InterpolationName(i)), i);
  }
  EXPECT_EQ(ParseInterpolation("Quintic"), Interpolation::kQuintic);
  EXPECT_FALSE(ParseInterpolation("spline"));
  EXPECT_FALSE(ParseInterpolation(""));
  EXPECT_FALSE(ParseInterpolation("cubicx"));
}

}  // namespace
}  // namespace robotalk
