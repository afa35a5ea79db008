// Capturability of the walking humanoid (issue 26, item 4;
// drivers/ode_sim/walking/capturability.h): the N-step capture regions of a
// LIPM with the model's sole, reach and step times against their closed
// forms, and against a brute-force search over step times and places.
#include "walking/capturability.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>

namespace robotalk::walking {
namespace {

// The simple humanoid's (docs/ode_sim.md, "The gait from the model"): CoM
// 0.70 m up (w = 3.74/s), a 24 x 12 cm sole 0.15 m ahead of and 0.09 m
// behind its ankle, the regeneration's reach box and soonest steps.
CaptureLimits Model() { return CaptureLimits{}; }

TEST(Capturability, ZeroStepsIsTheSole) {
  const CaptureLimits l = Model();
  for (Side s : {Side::kLeft, Side::kRight}) {
    const CaptureBox r = SingleSupportRegion(l, s, 0.2, 0);
    EXPECT_DOUBLE_EQ(r.x.lo, -l.back);
    EXPECT_DOUBLE_EQ(r.x.hi, l.front);
    EXPECT_DOUBLE_EQ(r.y.lo, -l.half_width);
    EXPECT_DOUBLE_EQ(r.y.hi, l.half_width);
  }
}

TEST(Capturability, OneStepIsTheSoleWidenedByTheReachTimesTheSwingsDecay) {
  // Koolen et al.'s d1 = r + l e^{-w dt} on each side the reach allows;
  // toward the stance foot's side (the swing foot never crosses) nothing.
  const CaptureLimits l = Model();
  for (const double first : {0.0, 0.1, 0.35}) {
    const double e = std::exp(-l.omega * first);
    const CaptureBox left = SingleSupportRegion(l, Side::kLeft, first, 1);
    EXPECT_NEAR(left.x.hi, l.front + l.reach * e, 1e-12);
    EXPECT_NEAR(left.x.lo, -l.back - l.reach_back * e, 1e-12);
    EXPECT_NEAR(left.y.hi, l.half_width + l.max_width * e, 1e-12);
    EXPECT_NEAR(left.y.lo, -l.half_width, 1e-12);
    const CaptureBox right = SingleSupportRegion(l, Side::kRight, first, 1);
    EXPECT_NEAR(right.y.lo, -l.half_width - l.max_width * e, 1e-12);
    EXPECT_NEAR(right.y.hi, l.half_width, 1e-12);
  }
}

TEST(Capturability, ManyStepsReachTheGeometricSumsLimit) {
  // Forward and backward every later step adds reach x (E D)^k, E for the
  // soonest swing, D for the double support: front + reach E / (1 - E D).
  const CaptureLimits l = Model();
  const double e = std::exp(-l.omega * l.min_swing), d = std::exp(-l.omega * l.double_support);
  const CaptureBox many = SingleSupportRegion(l, Side::kLeft, l.min_swing, kManyCaptureSteps);
  EXPECT_NEAR(many.x.hi, l.front + l.reach * e / (1 - e * d), 1e-9);
  EXPECT_NEAR(many.x.lo, -l.back - l.reach_back * e / (1 - e * d), 1e-9);
  // The regions only grow with the steps allowed, and converge.
  double last = 0;
  for (int n = 0; n <= kManyCaptureSteps; ++n) {
    const CaptureBox r = SingleSupportRegion(l, Side::kLeft, l.min_swing, n);
    EXPECT_GE(r.x.hi, last - 1e-15);
    last = r.x.hi;
  }
  EXPECT_NEAR(SingleSupportRegion(l, Side::kLeft, l.min_swing, kManyCaptureSteps - 1).x.hi, last, 1e-9);
}

TEST(Capturability, TowardTheStanceFootOnlyTheStepAfterTheSwingsCanCatch) {
  // With the left foot in the air, a DCM beyond the right sole's outer edge
  // needs the right foot to step out after the left lands beside it (at
  // least min_width to the left): y_lo = -h + min(0, (min_width - max_width E
  // + ...) D) E1. With the model's limits min_width > max_width E: nothing,
  // however many steps; without the crossing rule's width it catches.
  CaptureLimits l = Model();
  for (const double first : {0.0, 0.2}) {
    EXPECT_NEAR(SingleSupportRegion(l, Side::kLeft, first, kManyCaptureSteps).y.lo, -l.half_width, 1e-12);
  }
  l.min_width = 0.0;
  const double e = std::exp(-l.omega * l.min_swing), d = std::exp(-l.omega * l.double_support);
  const CaptureBox two = SingleSupportRegion(l, Side::kLeft, 0.0, 2);
  EXPECT_NEAR(two.y.lo, -l.half_width - l.max_width * e * d, 1e-12);
}

// One axis walked by brute force: the DCM at x0 (from the stance ankle),
// the CoP as near the DCM as the support allows (the best a 1-D controller
// can do), the given swing and double support times and landings (from the
// previous stance ankle); captured when the DCM ends in the last support.
bool Captures(double x0, double sole_lo, double sole_hi, const double* swing, const double* landing,
              const double* ds, int steps, double omega) {
  double xi = x0, stance = 0;
  const auto hold = [&](double lo, double hi, double t) {
    const double p = std::clamp(xi, lo, hi);
    xi = p + (xi - p) * std::exp(omega * t);
  };
  for (int k = 0; k < steps; ++k) {
    hold(stance + sole_lo, stance + sole_hi, swing[k]);
    const double next = stance + landing[k];
    const double lo = std::min(stance, next) + sole_lo, hi = std::max(stance, next) + sole_hi;
    if (lo <= xi && xi <= hi) return true;  // caught in double support
    hold(lo, hi, ds[k]);
    stance = next;
  }
  return stance + sole_lo <= xi && xi <= stance + sole_hi;
}

TEST(Capturability, NoTwoStepTimingNorPlacementBeatsTheRegionAndTheSoonestFarthestAttainsIt) {
  // Forward, two steps from 0.1 s before the soonest landing: a grid of
  // later swings, longer double supports and nearer landings never captures
  // a DCM 1 mm beyond the region's end; the soonest, farthest steps capture
  // one 1 mm inside it.
  const CaptureLimits l = Model();
  const double first = 0.1;
  const CaptureBox r = SingleSupportRegion(l, Side::kLeft, first, 2);
  int tried = 0;
  for (const double t1 : {first, first + 0.05, first + 0.2}) {
    for (const double t2 : {l.min_swing, l.min_swing + 0.1}) {
      for (const double d1 : {l.double_support, l.double_support + 0.1}) {
        for (const double u1 : {l.reach, 0.8 * l.reach, 0.3 * l.reach}) {
          for (const double u2 : {l.reach, 0.5 * l.reach}) {
            const double swing[2] = {t1, t2}, land[2] = {u1, u2}, ds[2] = {d1, l.double_support};
            EXPECT_FALSE(Captures(r.x.hi + 1e-3, -l.back, l.front, swing, land, ds, 2, l.omega))
                << t1 << " " << t2 << " " << d1 << " " << u1 << " " << u2;
            ++tried;
          }
        }
      }
    }
  }
  EXPECT_EQ(tried, 72);
  const double swing[2] = {first, l.min_swing}, land[2] = {l.reach, l.reach}, ds[2] = {l.double_support, 0};
  EXPECT_TRUE(Captures(r.x.hi - 1e-3, -l.back, l.front, swing, land, ds, 2, l.omega));
  const double back[2] = {-l.reach_back, -l.reach_back};
  EXPECT_TRUE(Captures(r.x.lo + 1e-3, -l.back, l.front, swing, back, ds, 2, l.omega));
  EXPECT_FALSE(Captures(r.x.lo - 1e-3, -l.back, l.front, swing, back, ds, 2, l.omega));
}

TEST(Capturability, ASwingSpeedNarrowsTheFirstLandingToWhereTheFootCanGet) {
  // Mid-swing, the left foot beside the right one, pushed forward: with the
  // foot free to land anywhere in reach at once, the region is the soonest
  // step's; with 1 m/s of swing the first landing lies within 1 m/s of its
  // swing from the foot, so the bound is lower, but still above the sole.
  const CaptureLimits l = Model();
  CaptureSituation s;
  s.swing = Side::kLeft;
  s.feet[1] = {0, -0.09, 0};
  s.feet[0] = {0.0, 0.09, 0};  // in the air, alongside
  s.soonest = 0.05;
  s.dcm = {0.08, -0.04};
  const double free = CapturableShift(l, s, {1, 0}, kManyCaptureSteps);
  const CaptureBox r = SingleSupportRegion(l, Side::kLeft, 0.05, kManyCaptureSteps);
  EXPECT_NEAR(free, r.x.hi - 0.08, 1e-12);
  CaptureLimits slow = l;
  slow.swing_speed = 1.0;
  const double bounded = CapturableShift(slow, s, {1, 0}, kManyCaptureSteps);
  EXPECT_LT(bounded, free - 0.05);
  EXPECT_GT(bounded, l.front - 0.08);
  // One step: Koolen's front + u e^{-w T} with the landing u at most 1 m/s x
  // T ahead of the foot (alongside the stance ankle), the best over T.
  const double one = CapturableShift(slow, s, {1, 0}, 1);
  double best = 0;
  for (int i = 0; i <= 200; ++i) {
    const double t = 0.05 + 0.005 * i;
    best = std::max(best, l.front + std::min(l.reach, 1.0 * t) * std::exp(-l.omega * t));
  }
  EXPECT_NEAR(one + 0.08, best, 1e-9);
}

TEST(Capturability, InDoubleSupportEitherFootMayLiftAndAPushsShiftIsItsImpulseSpread) {
  const CaptureLimits l = Model();
  CaptureSituation s;
  s.double_support = true;
  s.feet[0] = {0.22, 0.09, 0};  // the left foot just landed ahead
  s.feet[1] = {0.0, -0.09, 0};
  s.soonest = 0.05;
  s.dcm = {0.17, 0.0};
  // Sideways both ways: each way the foot on that side lifts and steps out,
  // the same distance by symmetry about the feet's middle.
  const double left = CapturableShift(l, s, {0, 1}, kManyCaptureSteps);
  const double right = CapturableShift(l, s, {0, -1}, kManyCaptureSteps);
  EXPECT_NEAR(left, right, 1e-12);
  // With the model's limits the box of the soles is the end: the outer foot
  // lifted steps out at most max_width from the inner one, too near for the
  // DCM 0.4 s later; a wider reach would catch beyond the box.
  EXPECT_DOUBLE_EQ(left, 0.09 + l.half_width);
  EXPECT_DOUBLE_EQ(CapturableShift(l, s, {0, 1}, 0), 0.09 + l.half_width);
  CaptureLimits wide = l;
  wide.max_width = 1.0;
  EXPECT_GT(CapturableShift(wide, s, {0, 1}, kManyCaptureSteps), 0.09 + l.half_width + 0.05);
  // Single support with the nominal DCM outside the sole: 0 steps catch nothing.
  s.double_support = false;
  s.swing = Side::kLeft;
  s.dcm = {0.2, -0.05};
  EXPECT_EQ(CapturableShift(l, s, {1, 0}, 0), 0);
  EXPECT_GT(CapturableShift(l, s, {1, 0}, 1), 0);
  // A constant force over D: the DCM afterwards is that of an impulse at the
  // start times (1 - e^{-wD}) / (wD), whatever the CoP holds.
  const double m = 52.5, w = l.omega, dur = 0.1, f = 200, dt = 1e-6;
  double xi = 0.01, free = 0.01;
  for (double t = 0; t < dur; t += dt) {
    xi += (w * (xi - 0.02) + f / (m * w)) * dt;
    free += w * (free - 0.02) * dt;
  }
  const double kick = (xi - free) * std::exp(-w * dur);
  EXPECT_NEAR(kick, f * dur * DcmShiftPerImpulse(m, w, dur), 1e-5);
  EXPECT_DOUBLE_EQ(DcmShiftPerImpulse(m, w, 0), 1 / (m * w));
}

}  // namespace
}  // namespace robotalk::walking
