// The Fig. 11 profile and its ideal path (tools/experiments/fig11_profile.h).
#include "fig11_profile.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <stdexcept>

namespace robotalk::experiments {
namespace {

constexpr double kPi = std::numbers::pi;

TEST(Fig11Profile, ShapeAndTiming) {
  const Fig11Profile p = MakeFig11Profile({.length = 6.0, .duration = 30.0});
  EXPECT_EQ(p.frames_per_small, 38);  // round(30 / 0.8)
  EXPECT_NEAR(p.duration, 30.4, 1e-12);
  ASSERT_EQ(p.frames.size(), 8u * 38u + 1u);
  EXPECT_NEAR(p.radius, 6.0 / (8 * kPi), 1e-12);
  EXPECT_NEAR(p.speed * p.duration, 6.0, 1e-9);  // constant speed over the whole length
  for (std::size_t i = 0; i < p.frames.size(); ++i)
    EXPECT_NEAR(p.frames[i].offset, 0.1 * static_cast<double>(i), 1e-9);
  EXPECT_GT(p.frames.front().omega, 0);  // first small half circle turns left
  EXPECT_LT(p.frames[38].omega, 0);      // second turns right
  EXPECT_NEAR(p.frames[4 * 38].omega, -p.speed / (4 * p.radius), 1e-12);  // large, right
  EXPECT_EQ(p.frames.back().v, 0.0);
  EXPECT_EQ(p.frames.back().omega, 0.0);
  EXPECT_THROW(MakeFig11Profile({.length = 0}), std::invalid_argument);
  EXPECT_THROW(MakeFig11Profile({.duration = NAN}), std::invalid_argument);
}

TEST(Fig11Profile, IdealPathClosesThroughTheDesignedPoints) {
  for (double duration : {12.8, 14.4, 30.0}) {
    const Fig11Profile p = MakeFig11Profile({.length = 3.0, .duration = duration});
    const IdealPath path(p, {});
    const double r = p.radius, t = p.frames_per_small * 0.1;
    const Pose2 ends[5] = {path.At(t), path.At(2 * t), path.At(3 * t), path.At(4 * t), path.End()};
    EXPECT_NEAR(ends[0].x, 0, 1e-9);
    EXPECT_NEAR(ends[0].y, 2 * r, 1e-9);
    EXPECT_NEAR(ends[1].y, 4 * r, 1e-9);
    EXPECT_NEAR(ends[2].y, 6 * r, 1e-9);
    EXPECT_NEAR(ends[3].y, 8 * r, 1e-9);
    EXPECT_NEAR(ends[3].theta, 0, 1e-9);
    EXPECT_NEAR(ends[4].x, 0, 1e-9);  // back at the start
    EXPECT_NEAR(ends[4].y, 0, 1e-9);
    EXPECT_NEAR(std::abs(ends[4].theta), kPi, 1e-9);
    EXPECT_NEAR(path.At(6 * t).x, 4 * r, 1e-9);  // top of the large half circle
    EXPECT_NEAR(path.At(6 * t).y, 4 * r, 1e-9);
  }
}

TEST(Fig11Profile, IdealPathFromAnotherStartPose) {
  const Fig11Profile p = MakeFig11Profile({.length = 3.0, .duration = 14.4});
  const IdealPath path(p, {1.0, -2.0, kPi / 2});
  EXPECT_NEAR(path.End().x, 1.0, 1e-9);
  EXPECT_NEAR(path.End().y, -2.0, 1e-9);
  // The first half circle turns left from heading +y: it bulges towards -x... its end is at (1 - 2r, -2).
  EXPECT_NEAR(path.At(p.frames_per_small * 0.1).x, 1.0 - 2 * p.radius, 1e-9);
}

TEST(Fig11Profile, DistanceToArcs) {
  // Quarter circle of radius 1 around (0, 1), from (0, 0) heading +x, turning left.
  const Arc arc{{0, 0, 0}, 1.0, 1.0, kPi / 2};
  EXPECT_NEAR(arc.End().x, 1.0, 1e-12);
  EXPECT_NEAR(arc.End().y, 1.0, 1e-12);
  EXPECT_NEAR(arc.Distance(0, 1), 1.0, 1e-12);                               // centre
  EXPECT_NEAR(arc.Distance(std::sqrt(2.0), 1 - std::sqrt(2.0)), 1.0, 1e-9);  // 2 from the centre, mid-sweep
  EXPECT_NEAR(arc.Distance(-1, 1), std::sqrt(2.0), 1e-9);  // outside the sweep: nearest end (0, 0)
  EXPECT_NEAR(arc.Distance(0, -0.5), 0.5, 1e-12);          // on the start ray: 0.5 below the start
  const Arc right{{0, 0, 0}, 1.0, -1.0, kPi / 2};          // turning right, centre (0, -1)
  EXPECT_NEAR(right.End().y, -1.0, 1e-12);
  EXPECT_NEAR(right.Distance(1, -1), 0.0, 1e-12);
  EXPECT_NEAR(right.Distance(1, 1), std::hypot(1, 2) - 1,
              1e-9);                               // (1, 1) is at 63° around the centre: within the sweep
  const Arc line{{0, 0, kPi / 2}, 2.0, 0.0, 1.0};  // straight up to (0, 2)
  EXPECT_NEAR(line.Distance(0.3, 1.0), 0.3, 1e-12);
  EXPECT_NEAR(line.Distance(0, 3), 1.0, 1e-12);
}

TEST(Fig11Profile, DeviationOfTheIdealSamplesIsZero) {
  const Fig11Profile p = MakeFig11Profile({.length = 3.0, .duration = 14.4});
  const IdealPath path(p, {});
  std::vector<Pose2> on, off;
  for (int i = 0; i <= 720; ++i) {
    const Pose2 q = path.At(i * 0.02);
    on.push_back(q);
    off.push_back(
        {q.x + 0.01 * std::cos(q.theta + kPi / 2), q.y + 0.01 * std::sin(q.theta + kPi / 2), q.theta});
  }
  const Deviation d0 = MeasureDeviation(path, on);
  EXPECT_EQ(d0.samples, 721u);
  EXPECT_LT(d0.max, 1e-9);
  // Shifted 1 cm sideways: about 1 cm from the path (less where the path passes nearby).
  const Deviation d1 = MeasureDeviation(path, off);
  EXPECT_LE(d1.max, 0.01 + 1e-9);
  EXPECT_GT(d1.mean, 0.009);
}

}  // namespace
}  // namespace robotalk::experiments
