#include "playback_estimator.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
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

// --- Quick start from send times (issue 11; an option since issue 23) -------

// A paced client (frame i sent at offset i) on a channel whose one-way delay
// is delay(k) for the k-th package (history first, then the frames); the
// client's clock reads `skew` ahead of the server's. Returns the late frames
// and the chosen delay after the first arrival.
struct QuickRun {
  int late = 0;
  Duration delay{};
  Duration hindsight{};  // the least delay that would have made no frame late
  bool quick = false;
};
template <typename Delay>
QuickRun RunPaced(std::size_t frames, Duration period, std::size_t history, Delay delay) {
  const Duration skew = std::chrono::seconds(5000);
  PlaybackEstimator est(frames, period * static_cast<int>(frames - 1), {.adaptive = false});
  DelayHistory h;
  std::size_t k = 0;
  for (; k < history; ++k) {  // connect: hello, clock rounds, CONFIG, heartbeats
    const TimePoint sent = kT0 - milliseconds(500) + milliseconds(20) * static_cast<int>(k);
    h.Add(sent + skew, sent + delay(k));
  }
  const TimePoint first_arrival = kT0 + delay(k);
  est.SetDelayHistory(h.Recent(first_arrival));
  QuickRun run;
  std::optional<TimePoint> start;
  for (std::size_t i = 0; i < frames; ++i, ++k) {
    const TimePoint sent = kT0 + period * static_cast<int>(i);
    const TimePoint arrival = sent + delay(k);
    run.hindsight = std::max(run.hindsight, arrival - first_arrival - period * static_cast<int>(i));
    if (!start) {
      est.Add(period * static_cast<int>(i), arrival, sent + skew);
      if (est.ready()) {
        run.quick = est.quick();
        start = est.StartTime();
        run.delay = *start - first_arrival;
      }
    }
    if (start && arrival > *start + period * static_cast<int>(i)) ++run.late;
  }
  return run;
}

TEST(PlaybackEstimator, QuickStartOnAQuietChannelDecidesAtTheFirstFrameWithinMilliseconds) {
  // Delays of 200-300 us (a LAN): the paper's estimate would wait 5 frames (0.4 s).
  std::mt19937_64 rng(7);
  std::uniform_int_distribution<int> us(200, 300);
  const QuickRun run =
      RunPaced(40, milliseconds(100), 10, [&](std::size_t) { return std::chrono::microseconds(us(rng)); });
  EXPECT_TRUE(run.quick);
  EXPECT_EQ(run.late, 0);
  const Duration margin = PlaybackEstimatorOptions{}.quick_margin;
  EXPECT_GE(run.delay, margin);
  EXPECT_LE(run.delay, margin + std::chrono::microseconds(250));  // + 2.5 x the 100 us spread
}

TEST(PlaybackEstimator, QuickStartCoversRandomJitterWithoutLateFramesOverManySeeds) {
  // Delays uniform in [0, 40] ms at 10 Hz (a congested but keeping-up
  // channel, the bench relay's U[0, X] service times): 1000 seeded runs.
  int late_runs = 0;
  std::vector<double> ratios;  // chosen delay / (hindsight minimum + the margin)
  for (std::uint64_t seed = 1; seed <= 1000; ++seed) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> d(0.0, 0.040);
    const QuickRun run =
        RunPaced(40, milliseconds(100), 10, [&](std::size_t) { return FromSeconds(d(rng)); });
    ASSERT_TRUE(run.quick) << "seed " << seed;
    if (run.late > 0) ++late_runs;
    ratios.push_back(ToSeconds(run.delay) /
                     ToSeconds(run.hindsight + PlaybackEstimatorOptions{}.quick_margin));
  }
  EXPECT_EQ(late_runs, 0);
  // The price of deciding at the first frame: when its own delay happens to
  // be high the hindsight minimum is near 0 and any safe choice is many times
  // it; in the median it is about 2.7x here (the paper's estimate: 0.5 s, ~12x).
  std::nth_element(ratios.begin(), ratios.begin() + 500, ratios.end());
  std::printf("median ratio to the hindsight minimum + margin: %.2f\n", ratios[500]);
  EXPECT_LT(ratios[500], 4.0);
}

TEST(PlaybackEstimator, ACongestedChannelOrAClientWithoutSendTimesGetsThePapersEstimate) {
  // Delays alternating 0 and 150 ms beside 100 ms frames: a queue can build;
  // wait for 5 frames and see the drift.
  const QuickRun congested =
      RunPaced(40, milliseconds(100), 10, [](std::size_t k) { return milliseconds(k % 2 ? 150 : 0); });
  EXPECT_FALSE(congested.quick);
  EXPECT_EQ(congested.late, 0);
  EXPECT_GE(congested.delay, milliseconds(400));
  // No history (a first package that is already a frame): the quick start
  // waits for 4 delays, its frames' own.
  const QuickRun fresh = RunPaced(40, milliseconds(100), 0, [](std::size_t) { return milliseconds(1); });
  EXPECT_TRUE(fresh.quick);
  EXPECT_EQ(fresh.delay, milliseconds(300) + PlaybackEstimatorOptions{}.quick_margin);
  // Frames without send times never start quickly.
  PlaybackEstimator est(40, milliseconds(3900), {.adaptive = false});
  est.SetDelayHistory(std::vector<Duration>(10, milliseconds(1)));
  est.Add(Duration(0), kT0);
  EXPECT_FALSE(est.ready());
  EXPECT_FALSE(est.delay_spread().has_value());
}

TEST(PlaybackEstimator, QuickStartCanBeSwitchedOff) {
  PlaybackEstimator est(40, milliseconds(3900), {.quick_start = false, .adaptive = false});
  est.SetDelayHistory(std::vector<Duration>(10, milliseconds(1)));
  est.Add(Duration(0), kT0, kT0 - milliseconds(1));
  EXPECT_FALSE(est.quick());
  EXPECT_FALSE(est.ready());
}

TEST(DelayHistory, KeepsTheLatestWithinTheWindowAndIgnoresOverflowingSendTimes) {
  DelayHistory h;
  for (int i = 0; i < 40; ++i) h.Add(kT0 + milliseconds(i), kT0 + milliseconds(i) + milliseconds(i % 5));
  std::vector<Duration> recent = h.Recent(kT0 + milliseconds(40));
  ASSERT_EQ(recent.size(), DelayHistory::kCapacity);
  EXPECT_EQ(recent.back(), milliseconds(39 % 5));                  // oldest first
  EXPECT_TRUE(h.Recent(kT0 + std::chrono::seconds(100)).empty());  // all older than 30 s
  h.Add(TimePoint::min(), TimePoint::max());                       // would overflow: ignored
  h.Add(kT0 - std::chrono::hours(24 * 365 * 100), kT0);  // a century: ignored (two delays must subtract)
  EXPECT_EQ(h.Recent(kT0 + milliseconds(40)).back(), milliseconds(39 % 5));
}

}  // namespace
}  // namespace robotalk
