// The hip strategy (drivers/ode_sim/walking/hip_strategy.h), tested without
// ODE: the lean's trigger, direction, bounds and return, and a linear
// inverted pendulum with an upper body (a flywheel: the hips' torque tau on
// it moves the ground's force, c'' = w^2 (c - p) - tau / (m h)) standing on a
// sole whose centre of pressure p the ankles put at the DCM's side edge
// (DCM feedback saturated in the sole, as the stiff servos do on ODE): a push
// it falls to with the ankles alone is caught with the lean.
#include "walking/hip_strategy.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace robotalk::walking {
namespace {

constexpr double kTick = 0.001;

// The DcmEstimator's impulse() for a 0.1 s push of `dv` m/s along `dir`
// (its leaky integral, 0.15 s), at time t after the push's start.
Eigen::Vector2d ImpulseAt(double t, double dv, const Eigen::Vector2d& dir) {
  constexpr double kPush = 0.1, kWindow = 0.15;
  const double a = dv / kPush;
  const double at_end = a * kWindow * (1 - std::exp(-kPush / kWindow));
  const double j =
      t < kPush ? a * kWindow * (1 - std::exp(-t / kWindow)) : at_end * std::exp(-(t - kPush) / kWindow);
  return j * dir;
}

TEST(HipStrategy, UnderTheTriggerNothingLeans) {
  HipStrategy hip(kTick);
  for (int i = 0; i < 3000; ++i) {
    const double j = 0.07 * std::sin(i * 0.01);  // walking unpushed on ODE: under 0.084 m/s
    EXPECT_EQ(hip.Update(Eigen::Vector2d(j, -j)), Eigen::Vector2d::Zero());
  }
  EXPECT_FALSE(hip.active());
  EXPECT_EQ(hip.leans(), 0);
}

TEST(HipStrategy, APushLeansTowardItWithinTheBoundsThenBackUprightOnce) {
  const HipStrategyParams p;
  for (const double deg : {0.0, 90.0, 135.0, 270.0}) {
    const Eigen::Vector2d dir(std::cos(deg * M_PI / 180), std::sin(deg * M_PI / 180));
    for (const double dv : {0.15, 0.4}) {  // 8 and 21 N s on 52.5 kg
      SCOPED_TRACE(testing::Message() << deg << " deg, " << dv << " m/s");
      HipStrategy hip(kTick);
      double angle = 0, rate = 0, peak = 0, max_accel = 0, max_back_rate = 0;
      bool upright_again = false;
      for (int i = 0; i < 5000; ++i) {
        const Eigen::Vector2d lean = hip.Update(ImpulseAt(i * kTick, dv, dir));
        // Along the push: the lean's direction is the push's.
        EXPECT_NEAR(lean.x() * dir.y() - lean.y() * dir.x(), 0, 1e-9);
        const double a = lean.dot(dir);
        EXPECT_GE(a, -1e-12);
        const double r = (a - angle) / kTick;
        max_accel = std::max(max_accel, std::abs(r - rate) / kTick);
        if (peak > 0 && a < peak) max_back_rate = std::max(max_back_rate, -r);
        angle = a;
        rate = r;
        peak = std::max(peak, a);
        if (peak > 0 && !hip.active()) {
          upright_again = true;
          EXPECT_EQ(lean, Eigen::Vector2d::Zero());
        }
      }
      EXPECT_LE(peak, p.max_lean + 1e-12);
      // The target: the gain times the impulse's peak (at the push's end).
      EXPECT_NEAR(peak, std::min(p.max_lean, p.gain * ImpulseAt(0.1, dv, dir).norm()), 1e-9);
      EXPECT_LE(std::abs(rate), p.rate + 1e-9);
      EXPECT_LE(max_accel, std::max(p.accel, p.brake) + 1e-6);
      EXPECT_LE(max_back_rate, p.back_rate + 1e-9);
      EXPECT_TRUE(upright_again);
      EXPECT_EQ(hip.leans(), 1);
    }
  }
}

TEST(HipStrategy, APushWhileLeaningIsNoNewTriggerAndBadParamsAreRefused) {
  HipStrategy hip(kTick);
  const Eigen::Vector2d x = Eigen::Vector2d::UnitX();
  for (int i = 0; i < 300; ++i) hip.Update(ImpulseAt(i * kTick, 0.4, x));
  ASSERT_TRUE(hip.active());
  const Eigen::Vector2d before = hip.lean();
  hip.Update(Eigen::Vector2d(0, 0.5));  // a push to the left while leaning forward
  EXPECT_NEAR(hip.lean().y(), 0, 1e-12);
  EXPECT_NEAR(hip.lean().x(), before.x(), 0.01);
  EXPECT_EQ(hip.leans(), 1);
  EXPECT_THROW(HipStrategy(0), std::invalid_argument);
  HipStrategyParams bad;
  bad.max_lean = 0;
  EXPECT_THROW(HipStrategy(kTick, bad), std::invalid_argument);
  bad = {};
  bad.hold = -1;
  EXPECT_THROW(HipStrategy(kTick, bad), std::invalid_argument);
  bad = {};
  bad.brake = std::nan("");
  EXPECT_THROW(HipStrategy(kTick, bad), std::invalid_argument);
}

// The pendulum with an upper body, standing on the simple humanoid's sole
// (15 cm ahead of the ankle, 9 behind), pushed forward 0.1 s by `dv` m/s.
// The hips' torque is the upper body's inertia times the lean's angular
// acceleration. Survived: the CoM 4 s later within 0.5 m.
bool Survives(double dv, bool hip_on) {
  constexpr double kMass = 52.5, kHeight = 0.7, kUpperInertia = 2.8;  // kg, m, kg m^2 about the hips
  constexpr double kFront = 0.15, kBack = 0.09, kAnkleGain = 3;
  const double w = std::sqrt(9.81 / kHeight);
  HipStrategy hip(kTick);
  double c = 0, v = 0, rate = 0, angle = 0;
  for (int i = 0; i < 4000; ++i) {
    const double t = i * kTick;
    const double push = t < 0.1 ? dv / 0.1 : 0;
    double tau = 0;
    if (hip_on) {
      const double a = hip.Update(ImpulseAt(t, dv, Eigen::Vector2d::UnitX())).x();
      const double r = (a - angle) / kTick;
      tau = kUpperInertia * (r - rate) / kTick;
      angle = a;
      rate = r;
    }
    const double p = std::clamp(kAnkleGain * (c + v / w), -kBack, kFront);
    v += (w * w * (c - p) - tau / (kMass * kHeight) + push) * kTick;
    c += v * kTick;
    if (std::abs(c) > 0.5) return false;
  }
  return true;
}

TEST(HipStrategy, AnUpperBodyLeaningTowardAPushCatchesOneTheAnklesAloneFallTo) {
  // The ankles alone catch 33.3 N s (0.634 m/s) on this pendulum; with the lean 35.7 N s.
  EXPECT_TRUE(Survives(0.60, false));
  EXPECT_FALSE(Survives(0.66, false));
  EXPECT_TRUE(Survives(0.66, true));
  EXPECT_TRUE(Survives(0.30, true));  // a small push: leaning does not topple it either
  EXPECT_FALSE(Survives(0.72, true));
}

}  // namespace
}  // namespace robotalk::walking
