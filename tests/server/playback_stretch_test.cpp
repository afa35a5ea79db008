// Issue 23 item 3: a wider timing tolerance (`--playback-stretch F` above
// the default 0.1) moves the adaptive start's gate with it, so a congested
// link whose services a stretched gap can follow gets the adaptive start
// instead of the paper's estimate (seconds). On a manual timeline, then on
// the pure model's channels (playback_model.h).
#include "playback_estimator.h"
#include "playback_model.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <vector>

namespace robotalk {
namespace {

using namespace playback_model;

// Ten connect-time delays from 1 ms spread by `spread_ms`; 40 frames at 10 Hz;
// frame 0 took 1 ms and arrived at kT0.
PlaybackEstimator WithSpread(double spread_ms, double stretch) {
  std::vector<Duration> history;
  for (int i = 0; i < 10; ++i) history.push_back(FromSeconds((1 + spread_ms * i / 9) / 1000.0));
  // The gate itself (beyond it the queue follow, on by default, may decide:
  // playback_follow_test.cpp).
  PlaybackEstimator est(40, milliseconds(3900), {.max_stretch = stretch, .follow_queue = false});
  est.SetDelayHistory(history);
  est.Add(Duration(0), kT0, kT0 - milliseconds(1));
  return est;
}

TEST(PlaybackStretch, AWiderStretchMovesTheGateByAsMuchAndNothingChangesAtOrBelowTheDefault) {
  // The gate is 1.2 frame intervals at the default stretch (0.1) and below.
  for (double stretch : {0.0, 0.05, 0.10}) {
    EXPECT_TRUE(WithSpread(115, stretch).adaptive()) << stretch;
    EXPECT_FALSE(WithSpread(125, stretch).adaptive()) << "the paper's estimate, stretch " << stretch;
  }
  // At 0.5 each gap may play 50 ms longer: a service of up to 1.5 intervals
  // adds at most that to the next frame's delay, so the gate is 1.6
  // intervals (before: 1.2 whatever the stretch, the paper's estimate here).
  PlaybackEstimator est = WithSpread(140, 0.5);
  ASSERT_TRUE(est.adaptive());
  EXPECT_FALSE(est.queued());
  // It covers the worst, 141 ms, + spread / n (140 / 11) + the 2 ms margin,
  // less frame 0's own 1 ms and one gap's stretch (50 ms): nothing of the
  // spread lies beyond the excess threshold (1.0 + 0.4 intervals).
  EXPECT_NEAR(ToSeconds(est.StartTime() - kT0), 0.141 + 0.140 / 11 + 0.002 - 0.001 - 0.050, 1e-6);
  EXPECT_EQ(*est.playout_delay(), FromSeconds(0.141 + 0.140 * 4 / 11 + 0.002));
  EXPECT_FALSE(WithSpread(165, 0.5).adaptive()) << "beyond 1.6 intervals: the paper's estimate";
  // Between 1.4 and 1.6 intervals the spread beyond 1.4 is added 2.5 times
  // (a queue may build that the connect-time packages never met).
  EXPECT_NEAR(ToSeconds(WithSpread(150, 0.5).StartTime() - kT0),
              0.151 + 2.5 * 0.010 + 0.150 / 11 + 0.002 - 0.001 - 0.050, 1e-6);
}

struct Goal {
  int met = 0, late_runs = 0;
  double worst_gap_stretch = 0;
  Duration worst_stretch{};
};

// Issue 23's goal per run: start / (hindsight minimum + the margin) <= 1.25
// and no frame late (a pause past the bound counts as late).
Goal Runs(const Channel& channel, PlaybackEstimatorOptions options, int runs = 300) {
  Goal g;
  for (int seed = 1; seed <= runs; ++seed) {
    std::mt19937_64 rng(static_cast<std::uint64_t>(seed));
    const SimRun r = Simulate(
        40, milliseconds(100), 10, [&](std::size_t k, TimePoint sent) { return channel(rng, k, sent); },
        options, false, channel.server_lag.get());
    g.late_runs += r.late > 0;
    g.met += r.late == 0 && ToSeconds(r.start_delay) <= 1.25 * ToSeconds(r.hindsight + kMargin);
    g.worst_gap_stretch = std::max(g.worst_gap_stretch, r.max_gap_stretch);
    g.worst_stretch = std::max(g.worst_stretch, r.stretch);
  }
  return g;
}

TEST(PlaybackStretch, AtFiftyPercentTheHeaviestCongestionMeetsTheGoalInMostRuns) {
  // The relay's U[0, 150] ms FIFO link: services up to 1.5 frame intervals,
  // so the connect-time delays spread past 1.2 intervals and the default
  // gives the paper's estimate (52 of 300 runs met, median 14.9x). A 50 %
  // stretch follows any one service (at most 50 ms more per gap): measured
  // 293 of 300 met, 7 with a late frame (93 with the stretch alone, the gate
  // left at 1.2 intervals).
  // (The default now follows that queue: playback_follow_test.cpp; here the gate as it was.)
  const Goal before = Runs(Fifo(150), {.follow_queue = false});
  const Goal wide = Runs(Fifo(150), {.max_stretch = 0.5});
  std::printf(
      "FIFO U[0, 150] ms: goal met %d -> %d of 300, late runs %d -> %d, worst gap stretch %.3f, "
      "whole sequence up to %.0f ms longer\n",
      before.met, wide.met, before.late_runs, wide.late_runs, wide.worst_gap_stretch,
      ToSeconds(wide.worst_stretch) * 1e3);
  EXPECT_LE(before.met, 100) << "the cause, reproduced: the paper's estimate";
  EXPECT_GE(wide.met, 280);
  EXPECT_LE(wide.late_runs, 15);
  EXPECT_LE(wide.worst_gap_stretch, 0.5 + 1e-9);
  // And on every other channel of the model, at least as many runs as the default.
  const std::vector<std::pair<const char*, Channel>> channels = {{"U[0, 40] ms", Jitter(40)},
                                                                 {"FIFO U[0, 50] ms", Fifo(50)},
                                                                 {"FIFO U[0, 100] ms", Fifo(100)},
                                                                 {"WAN", Wan()}};
  for (const auto& [name, channel] : channels) {
    const Goal d = Runs(channel, {}), w = Runs(channel, {.max_stretch = 0.5});
    std::printf("%s: goal met %d -> %d of 300, late runs %d -> %d\n", name, d.met, w.met, d.late_runs,
                w.late_runs);
    EXPECT_GE(w.met, d.met) << name;
    EXPECT_LE(w.worst_gap_stretch, 0.5 + 1e-9) << name;
  }
}

TEST(PlaybackStretch, ThePapersCongestionStillGetsThePapersEstimateMostly) {
  // Fig. 11's server pauses (U[0, 250] ms after each package, a 25 % drift)
  // with a connect burst of 4: a pause can exceed what a 50 % stretch
  // follows in one gap, and the wider gate lets the adaptive start decide
  // more often (all four burst services under 1.6 intervals): measured 6 ->
  // 20 of 100 runs with frames past the bound. The option's cost, documented.
  const Summary before = Many(100, ServerPauses(250), {}, 129, 4);
  const Summary wide = Many(100, ServerPauses(250), {.max_stretch = 0.5}, 129, 4);
  std::printf("Fig. 11 injector, a burst of 4: runs late %d -> %d of 100\n", before.late_runs,
              wide.late_runs);
  EXPECT_LE(wide.late_runs, 30);
  // Without the burst every sparse package meets its own pause: the paper's estimate.
  EXPECT_EQ(Many(100, ServerPauses(250), {.max_stretch = 0.5}, 129).late_runs, 0);
}

}  // namespace
}  // namespace robotalk
