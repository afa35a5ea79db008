// The DCM estimator (drivers/ode_sim/walking/dcm_estimator.h), tested
// without ODE: a linear inverted pendulum balances on its ankles (its CoP
// held inside a sole), its kinematic CoM and CoP measured with noise, and is
// pushed (a force the estimator's model does not see).
#include "walking/dcm_estimator.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <stdexcept>

namespace robotalk::walking {
namespace {

constexpr double kTick = 0.001, kOmega = 3.74, kMass = 52.5;

struct Trial {
  double rms_estimate = 0, rms_raw = 0;  // m, the DCM's error before the push
  double worst_in_push = 0;              // m, the estimate's DCM error from the push's start on
  double seen_true = -1, seen_estimate = -1, seen_raw = -1;  // s after the push: DCM past 5 cm
  double impulse_before = 0, seen_impulse = -1;              // m/s, worst before; s: impulse past 0.05 m/s
};

// The pendulum stands at p = 0 (x axis) with an ankle feedback on its true
// DCM, the CoP within +-0.1 m; pushed by `impulse` N*s over 0.1 s at 2 s.
// Measured: the CoM with `com_noise` (m, white), the CoP with 5 mm; "raw"
// is the driver's former velocity: differenced, low-passed over 10 ms.
Trial Simulate(double impulse, double com_noise, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> n_com(0, com_noise), n_cop(0, 0.005);
  DcmEstimator est(kOmega, kTick,
                   {.com_noise = std::max(com_noise, 1e-4), .accel_noise = 0.05, .force_noise = 5});
  double c = 0, v = 0, raw_v = 0, prev = 0;
  Trial r;
  int before = 0;
  for (int i = 0; i < 3000; ++i) {
    const double t = i * kTick;
    const double xi = c + v / kOmega;
    const double p = std::clamp(xi + 1.0 * xi, -0.1, 0.1);
    const double push = (t >= 2.0 && t < 2.1) ? impulse / 0.1 / kMass : 0;
    const double a = kOmega * kOmega * (c - p) + push;
    c += v * kTick + 0.5 * a * kTick * kTick;
    v += a * kTick;
    const double z = c + n_com(rng);
    const Eigen::Vector2d cop(p + n_cop(rng), 0);
    est.Update(Eigen::Vector2d(z, 0), &cop);
    if (i == 0) prev = z;
    raw_v += ((z - prev) / kTick - raw_v) * std::min(1.0, kTick / 0.01);
    prev = z;
    const double truth = c + v / kOmega, e = est.dcm().x(), raw = z + raw_v / kOmega;
    if (t > 0.5 && t < 2.0) r.impulse_before = std::max(r.impulse_before, std::abs(est.impulse().x()));
    if (t >= 2.0 && r.seen_impulse < 0 && est.impulse().x() > 0.05) r.seen_impulse = t - 2.0;
    if (t > 0.5 && t < 2.0) {
      r.rms_estimate += (e - truth) * (e - truth);
      r.rms_raw += (raw - truth) * (raw - truth);
      ++before;
    }
    if (t >= 2.0) {
      r.worst_in_push = std::max(r.worst_in_push, std::abs(e - truth));
      if (r.seen_true < 0 && truth > 0.05) r.seen_true = t - 2.0;
      if (r.seen_estimate < 0 && e > 0.05) r.seen_estimate = t - 2.0;
      if (r.seen_raw < 0 && raw > 0.05) r.seen_raw = t - 2.0;
    }
  }
  r.rms_estimate = std::sqrt(r.rms_estimate / before);
  r.rms_raw = std::sqrt(r.rms_raw / before);
  return r;
}

TEST(DcmEstimator, TheEstimatedDcmIsFarLessNoisyThanTheDifferencedOne) {
  for (unsigned seed = 1; seed <= 3; ++seed) {
    const Trial r = Simulate(10, 0.0005, seed);
    std::printf("seed %u: DCM error rms %.2f mm estimated, %.2f mm differenced\n", seed, 1e3 * r.rms_estimate,
                1e3 * r.rms_raw);
    EXPECT_LT(r.rms_estimate, 0.3 * r.rms_raw)
        << "seed " << seed << ": " << r.rms_estimate << " vs " << r.rms_raw;
    EXPECT_LT(r.rms_estimate, 0.004) << "seed " << seed;
  }
}

TEST(DcmEstimator, APushIsSeenWithinAFewMilliseconds) {
  for (unsigned seed = 1; seed <= 3; ++seed) {
    const Trial r = Simulate(20, 0.0005, seed);
    std::printf(
        "seed %u: DCM past 5 cm %.1f ms after the push, estimate %.1f ms, raw %.1f ms; worst %.1f mm\n", seed,
        1e3 * r.seen_true, 1e3 * r.seen_estimate, 1e3 * r.seen_raw, 1e3 * r.worst_in_push);
    ASSERT_GT(r.seen_true, 0) << "the push moved the DCM past 5 cm";
    ASSERT_GT(r.seen_estimate, 0) << "seed " << seed;
    EXPECT_LT(r.seen_estimate - r.seen_true, 0.01) << "seed " << seed;
    EXPECT_LT(r.worst_in_push, 0.025) << "seed " << seed;
  }
}

// impulse() tells a push from the pendulum's own motion: 10 N*s (0.19 m/s)
// pass 0.05 m/s within 70 ms of the push's start; unpushed it stays under 0.02.
TEST(DcmEstimator, ImpulseSeesAPushAndNotTheAnklesWork) {
  for (unsigned seed = 1; seed <= 3; ++seed) {
    const Trial r = Simulate(10, 0.0005, seed);
    std::printf("seed %u: impulse before the push at most %.3f m/s; past 0.05 m/s %.1f ms into it\n", seed,
                r.impulse_before, 1e3 * r.seen_impulse);
    EXPECT_LT(r.impulse_before, 0.02) << "seed " << seed;
    EXPECT_GT(r.seen_impulse, 0) << "seed " << seed;
    EXPECT_LT(r.seen_impulse, 0.07) << "seed " << seed;
  }
}

TEST(DcmEstimator, WithoutNoiseItFollowsThePendulumExactly) {
  const Trial r = Simulate(20, 0, 1);
  EXPECT_LT(r.rms_estimate, 0.002);
}

TEST(DcmEstimator, RejectsBadParameters) {
  EXPECT_THROW(DcmEstimator(0, kTick), std::invalid_argument);
  EXPECT_THROW(DcmEstimator(kOmega, 0), std::invalid_argument);
  EXPECT_THROW(DcmEstimator(kOmega, kTick, {.com_noise = 0}), std::invalid_argument);
  EXPECT_THROW(DcmEstimator(kOmega, kTick, {.accel_noise = -1}), std::invalid_argument);
  EXPECT_THROW(DcmEstimator(kOmega, kTick, {.force_noise = 0}), std::invalid_argument);
  EXPECT_THROW(DcmEstimator(kOmega, kTick, {.impulse_window = 0}), std::invalid_argument);
}

}  // namespace
}  // namespace robotalk::walking
