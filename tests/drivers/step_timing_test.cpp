// Step timing adaptation with step location (issue 26, item 4;
// drivers/ode_sim/walking/step_timing.h), tested without ODE: the DCM of a
// linear inverted pendulum walks on point-like stance CoPs held inside each
// stance sole (the ankles push the DCM's error back within the sole), steps
// where and when the adapter says, and is pushed (a change of velocity).
#include "walking/step_timing.h"
#include "walking/capturability.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <stdexcept>

namespace robotalk::walking {
namespace {

constexpr double kG = 9.81, kHeight = 0.70, kMass = 52.5;
const double kOmega = std::sqrt(kG / kHeight);  // 3.74/s
// The derived gait's step (docs/ode_sim.md, "The gait from the model"):
// 0.22 m ahead, the feet 0.18 m apart, 0.55 s of swing (double support
// taken as instantaneous here: 0.4 m/s).
constexpr double kStep = 0.22, kWidth = 0.18, kSwing = 0.55;
// The sole around the ankle, as the driver's ankles use it (3 cm inside).
constexpr double kFront = 0.15 - 0.03, kBack = 0.09 - 0.03, kHalf = 0.06 - 0.03;
constexpr double kMinSwing = 0.30;  // s after lift-off: the soonest landing

// The periodic gait's DCM relative to the stance ankle at lift-off (x:
// ahead; y: toward the swing side): the DCM offset at each landing equals
// the next step's start. x: b e^{wT} = L + b; y: c e^{wT} = W - c.
Eigen::Vector2d PeriodicStart() {
  const double e = std::exp(kOmega * kSwing);
  return {kStep / (e - 1), kWidth / (e + 1)};
}

struct Walk {
  bool fell = false;
  double worst_error = 0;        // m, the DCM from the periodic gait's, over the walk
  double end_error = 0;          // m, at the end
  double soonest_landing = 1e9;  // s of swing, the shortest step taken
};

// Walks 8 steps straight ahead from the periodic state, pushed by `dv`
// (m/s) `at` s into the third step. The adapter is asked every 10 ms with
// the measured DCM; `timing` false holds T at the plan's (location only).
Walk WalkAndPush(const Eigen::Vector2d& dv, double at, bool timing, const StepTimingParams& params = {}) {
  const StepTimingAdapter adapter(kOmega, params);
  constexpr double kTick = 0.001;
  Walk out;
  Pose2 stance{0, -kWidth / 2, 0};  // the right foot carries; the left swings
  Side swing = Side::kLeft;
  Eigen::Vector2d xi = stance.xy() + Eigen::Vector2d(PeriodicStart().x(), PeriodicStart().y());
  double elapsed = 0, land = kSwing;  // s into this step; s of its landing
  Eigen::Vector2d landing = stance.xy() + Eigen::Vector2d(kStep, kWidth);
  for (int step = 0; step < 8 && !out.fell; ++step) {
    const double s = SideSign(swing);
    const Eigen::Vector2d start(PeriodicStart().x(), s * PeriodicStart().y());
    const Eigen::Vector2d u_nom = stance.xy() + Eigen::Vector2d(kStep, s * kWidth);
    const Eigen::Vector2d b_nom = stance.xy() + start * std::exp(kOmega * kSwing) - u_nom;
    for (int t = 0; elapsed < land - 1e-9; ++t, elapsed += kTick) {
      if (step == 2 && std::abs(elapsed - at) < kTick / 2) xi += dv / kOmega;
      const Eigen::Vector2d nominal = stance.xy() + start * std::exp(kOmega * elapsed);
      const Eigen::Vector2d e = xi - nominal;
      out.worst_error = std::max(out.worst_error, e.norm());
      if (e.norm() > 0.5) {
        out.fell = true;
        break;
      }
      // The ankles: the CoP toward the error, within the sole.
      const Eigen::Vector2d cop =
          stance.xy() + Eigen::Vector2d(std::clamp(e.x(), -kBack, kFront), std::clamp(e.y(), -kHalf, kHalf));
      if (t % 10 == 0) {
        StepSituation sit;
        sit.dcm = xi;
        sit.cop = cop;
        sit.stance = stance;
        sit.swing = swing;
        sit.landing = u_nom;
        sit.offset = b_nom;
        sit.remaining = kSwing - elapsed;
        sit.soonest = timing ? std::max(0.0, kMinSwing - elapsed) : sit.remaining;
        const StepTiming r = adapter.Solve(sit);
        land = elapsed + r.remaining;
        landing = r.landing;
      }
      xi = cop + (xi - cop) * std::exp(kOmega * kTick);
    }
    if (out.fell) break;
    out.soonest_landing = std::min(out.soonest_landing, land);
    stance = {landing.x(), landing.y(), 0};
    swing = Other(swing);
    elapsed = 0;
    land = kSwing;
  }
  const double s = SideSign(swing);
  out.end_error = (xi - stance.xy() - Eigen::Vector2d(PeriodicStart().x(), s * PeriodicStart().y())).norm();
  return out;
}

Eigen::Vector2d Push(double deg, double n_s) {
  const double a = deg * std::numbers::pi / 180;
  return n_s / kMass * Eigen::Vector2d(std::cos(a), std::sin(a));
}

TEST(StepTiming, AnUndisturbedWalkKeepsThePlansLandingAndTime) {
  const StepTimingAdapter adapter(kOmega);
  StepSituation s;
  s.stance = {0.3, -0.09, 0.2};
  s.swing = Side::kLeft;
  s.landing = s.stance.Apply(kStep, kWidth);
  s.cop = s.stance.xy();
  const Eigen::Vector2d start = s.stance.Apply(0.02, 0.01) - s.stance.xy();
  s.dcm = s.cop + start * std::exp(kOmega * 0.1);
  s.remaining = 0.35;
  s.soonest = 0.1;
  s.offset = s.cop + start * std::exp(kOmega * (0.1 + 0.35)) - s.landing;
  const StepTiming r = adapter.Solve(s);
  EXPECT_DOUBLE_EQ(r.remaining, 0.35);
  EXPECT_LT((r.landing - s.landing).norm(), 1e-12);
  EXPECT_TRUE(r.fits);
  // Walking on undisturbed, every step is the plan's.
  const Walk w = WalkAndPush(Eigen::Vector2d::Zero(), 0.2, true);
  EXPECT_FALSE(w.fell);
  EXPECT_LT(w.worst_error, 1e-6);
  EXPECT_DOUBLE_EQ(w.soonest_landing, kSwing);
}

TEST(StepTiming, ALandingBeyondReachLandsSoonerWithinReachAndBesideTheStanceFoot) {
  StepTimingParams p;
  const StepTimingAdapter adapter(kOmega, p);
  StepSituation s;
  s.stance = {0, -0.09, 0};
  s.swing = Side::kLeft;
  s.landing = {kStep, 0.09};
  s.cop = {0.12, -0.09};  // the ankles at the toe
  s.dcm = {0.30, -0.05};  // pushed forward: 0.30 m ahead, 0.35 s to go
  s.remaining = 0.35;
  s.soonest = 0.05;
  s.offset = {0.02, -0.01};
  const StepTiming r = adapter.Solve(s);
  EXPECT_LT(r.remaining, 0.35);  // sooner
  EXPECT_GE(r.remaining, 0.05);
  const Eigen::Vector2d local = r.landing - s.stance.xy();
  EXPECT_LE(local.x(), p.reach + 1e-12);
  EXPECT_GE(local.y(), p.min_width - 1e-12);  // beside, never across
  EXPECT_LE(local.y(), p.max_width + 1e-12);
  // Held to the plan's time, the same landing would leave more error.
  s.soonest = s.remaining;
  const StepTiming fixed = adapter.Solve(s);
  EXPECT_DOUBLE_EQ(fixed.remaining, 0.35);
  EXPECT_GT((fixed.dcm_at_landing - fixed.landing - s.offset).norm(),
            (r.dcm_at_landing - r.landing - s.offset).norm());
  EXPECT_FALSE(fixed.fits);
  // The swing foot's reach from where it is bounds the landing.
  s.soonest = 0.05;
  s.foot = {-0.1, 0.09};
  s.foot_speed = 1.0;
  const StepTiming slow = adapter.Solve(s);
  EXPECT_LE((slow.landing - s.foot).norm(),
            std::max((s.landing - s.foot).norm(), s.foot_speed * slow.remaining) + 1e-9);
  EXPECT_GE(slow.remaining, s.soonest);
  EXPECT_LE(slow.remaining, s.remaining);
}

// The reproducer: a pushed pendulum walking on, the step's location alone
// (the plan's time) against location and time together.
TEST(StepTiming, LandingSoonerWhereTheDcmNeedsCapturesPushesTheLocationAloneFallsTo) {
  int fixed_survived = 0, timed_survived = 0, total = 0;
  for (const double deg : {0.0, 45.0, 90.0, 135.0, 180.0, 225.0, 270.0, 315.0}) {
    std::printf("%5.0f deg (instants survived of 10, location alone / with time):", deg);
    for (const double n_s : {20.0, 30.0, 40.0}) {
      int f = 0, t = 0;
      for (int i = 0; i < 10; ++i) {
        const double at = 0.05 * i;  // over the swing
        const Walk fixed = WalkAndPush(Push(deg, n_s), at, false);
        const Walk timed = WalkAndPush(Push(deg, n_s), at, true);
        fixed_survived += !fixed.fell;
        timed_survived += !timed.fell;
        f += !fixed.fell;
        t += !timed.fell;
        ++total;
        // What time adds never loses a push location alone survives.
        EXPECT_TRUE(timed.fell <= fixed.fell) << deg << " deg, " << n_s << " N s at " << at;
        if (!timed.fell) {
          EXPECT_LT(timed.end_error, 0.01) << deg << " deg, " << n_s << " N s at " << at;
        }
      }
      std::printf("  %2.0f N s %2d / %2d", n_s, f, t);
    }
    std::printf("\n");
  }
  std::printf("pushes survived of %d: location alone %d, location and time %d\n", total, fixed_survived,
              timed_survived);
  EXPECT_GE(timed_survived, fixed_survived + total / 10);
  // 30 N s toward the swing foot's side in the middle of the swing: caught
  // by a sooner step.
  EXPECT_TRUE(WalkAndPush(Push(90, 30), 0.25, false).fell);
  const Walk w = WalkAndPush(Push(90, 30), 0.25, true);
  EXPECT_FALSE(w.fell);
  EXPECT_LT(w.soonest_landing, kSwing);
}

// The capture bound (capturability.h) for this pendulum's limits at `at` s
// into the third step's swing toward `deg`: the largest push (N s, an
// impulse) any stepping strategy could recover.
double CaptureBoundAt(double at, double deg) {
  CaptureLimits l;
  l.omega = kOmega;
  l.front = kFront;
  l.back = kBack;
  l.half_width = kHalf;
  l.min_swing = kMinSwing;
  l.double_support = 0;  // instantaneous here
  CaptureSituation s;
  s.swing = Side::kLeft;  // the third step: the right foot carries, 2 steps on
  s.feet[1] = {2 * kStep, -kWidth / 2, 0};
  s.feet[0] = {kStep, kWidth / 2, 0};
  s.soonest = std::max(0.0, kMinSwing - at);
  s.dcm = s.feet[1].xy() + PeriodicStart() * std::exp(kOmega * at);
  const double a = deg * std::numbers::pi / 180;
  return CapturableShift(l, s, {std::cos(a), std::sin(a)}, kManyCaptureSteps) /
         DcmShiftPerImpulse(kMass, kOmega, 0);
}

TEST(StepTiming, NoPushBeyondTheCaptureBoundIsSurvivedAndTimingGetsCloserThanLocationAlone) {
  // At the 10 instants over a swing of the test above, per direction the
  // largest push survived (5 N s levels, below the first that falls) with
  // the landing's place alone and with its time: never beyond the bound;
  // how close each comes is printed (docs/ode_sim.md, "How large a push any
  // controller could survive").
  double sums[3] = {0, 0, 0};
  for (int k = 0; k < 8; ++k) {
    std::printf("%5d deg: bound / place alone / place and time (N s):", 45 * k);
    for (int i = 0; i < 10; ++i) {
      const double at = 0.05 * i, bound = CaptureBoundAt(at, 45.0 * k);
      double largest[2] = {0, 0};
      for (int timing = 0; timing < 2; ++timing) {
        for (double j = 5; j <= std::min(150.0, bound + 10) + 1e-9; j += 5) {
          if (WalkAndPush(Push(45.0 * k, j), at, timing == 1).fell) break;
          largest[timing] = j;
        }
        EXPECT_LE(largest[timing], bound) << 45 * k << " deg at " << at << " s, timing " << timing;
      }
      std::printf(" %.0f/%.0f/%.0f", bound, largest[0], largest[1]);
      sums[0] += bound;
      sums[1] += largest[0];
      sums[2] += largest[1];
    }
    std::printf("\n");
  }
  std::printf("sums over the 80 pushes (N s): bound %.0f, place alone %.0f, place and time %.0f\n", sums[0],
              sums[1], sums[2]);
  EXPECT_GT(sums[2], sums[1]);
}

TEST(StepTiming, BadSettingsAreRefused) {
  EXPECT_THROW(StepTimingAdapter(0), std::invalid_argument);
  StepTimingParams p;
  p.min_width = 0.5;  // above max_width
  EXPECT_THROW(StepTimingAdapter(kOmega, p), std::invalid_argument);
  p = {};
  p.w_offset = 0;
  EXPECT_THROW(StepTimingAdapter(kOmega, p), std::invalid_argument);
  p = {};
  p.resolution = 0;
  EXPECT_THROW(StepTimingAdapter(kOmega, p), std::invalid_argument);
}

}  // namespace
}  // namespace robotalk::walking
