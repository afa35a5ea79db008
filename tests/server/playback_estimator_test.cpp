#include "playback_estimator.h"

#include <gtest/gtest.h>

#include <random>

namespace robotalk {
namespace {

using std::chrono::milliseconds;

const TimePoint kT0(std::chrono::seconds(100));

// Simulates a sequence of N frames every `period`, arriving through a channel
// that delivers frame i at arrival(i); returns whether, with the estimated
// start, every frame is there before it has to play.
template <typename Arrival>
bool PlaysWithoutRunningDry(std::size_t n, Duration period, Arrival arrival, TimePoint* start_out = nullptr) {
  PlaybackEstimator est(n, period * static_cast<int>(n - 1),
                        {.min_frames = 5, .fraction = 0.1, .margin = milliseconds(50)});
  std::size_t i = 0;
  for (; i < n && !est.ready(); ++i) est.Add(period * static_cast<int>(i), arrival(i));
  const TimePoint start = est.StartTime();
  if (start_out) *start_out = start;
  for (std::size_t j = 0; j < n; ++j) {
    if (arrival(j) > start + period * static_cast<int>(j)) return false;
  }
  return true;
}

TEST(PlaybackEstimator, NeedsTenPercentOfTheFramesButAtLeastFive) {
  EXPECT_EQ(PlaybackEstimator(300, milliseconds(1000)).frames_needed(), 30u);
  EXPECT_EQ(PlaybackEstimator(20, milliseconds(1000)).frames_needed(), 5u);
  EXPECT_EQ(PlaybackEstimator(3, milliseconds(1000)).frames_needed(), 3u);
}

TEST(PlaybackEstimator, StartsAfterTheMarginOnAnIdealChannel) {
  TimePoint start;
  ASSERT_TRUE(PlaysWithoutRunningDry(
      100, milliseconds(100), [](std::size_t i) { return kT0 + milliseconds(100) * static_cast<int>(i); },
      &start));
  // The channel keeps up: the start waits only for the 10 frames the estimate
  // needs (playback's start latency) and the margin.
  EXPECT_EQ(start, kT0 + milliseconds(900) + milliseconds(50));
}

TEST(PlaybackEstimator, DelaysBySequenceBacklogWhenArrivalsAreSlowerThanCommands) {
  // Frames every 100 ms, arriving every 150 ms: the last of 200 arrives 9.95 s late.
  TimePoint start;
  auto slow = [](std::size_t i) { return kT0 + milliseconds(150) * static_cast<int>(i); };
  ASSERT_TRUE(PlaysWithoutRunningDry(200, milliseconds(100), slow, &start));
  EXPECT_NEAR(ToSeconds(start - kT0), 199 * 0.05 + 0.05, 1e-9);
}

TEST(PlaybackEstimator, CoversRandomCongestionLikeThePapers) {
  // The paper's injector: after each frame a pause uniform in [0, 0.1] s before the next.
  std::mt19937_64 rng(42);
  std::uniform_real_distribution<double> pause(0.0, 0.1);
  std::vector<TimePoint> arrivals;
  TimePoint busy = kT0;
  for (int i = 0; i < 300; ++i) {
    const TimePoint sent = kT0 + milliseconds(100) * i;
    busy = std::max(busy, sent) + FromSeconds(pause(rng));
    arrivals.push_back(busy);
  }
  EXPECT_TRUE(
      PlaysWithoutRunningDry(arrivals.size(), milliseconds(100), [&](std::size_t i) { return arrivals[i]; }));
}

TEST(PlaybackEstimator, IsNotFooledByBurstsOfFramesAtOneOffset) {
  // Pairs of commands per instant (a base speed and a head set-point), every
  // 2.5 s, arriving on time.
  PlaybackEstimator est(7, milliseconds(6500),
                        {.min_frames = 5, .fraction = 0.1, .margin = milliseconds(100)});
  for (int i = 0; i < 5; ++i) {
    const Duration offset = milliseconds(2500) * (i / 2);
    est.Add(offset, kT0 + offset + milliseconds(2));
  }
  ASSERT_TRUE(est.ready());
  // Decided when the fifth frame (offset 5 s) arrived; no growth to add.
  EXPECT_GE(est.StartTime() - kT0, milliseconds(5000));
  EXPECT_LT(est.StartTime() - kT0, milliseconds(5110));
}

TEST(PlaybackEstimator, ReportsTheMeanIntervals) {
  PlaybackEstimator est(10, milliseconds(900));
  for (int i = 0; i < 5; ++i) est.Add(milliseconds(100) * i, kT0 + milliseconds(120) * i);
  EXPECT_EQ(est.mean_command_interval(), milliseconds(100));
  EXPECT_EQ(est.mean_arrival_interval(), milliseconds(120));
}

}  // namespace
}  // namespace robotalk
