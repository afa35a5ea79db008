// Issue 23 item 3: the adaptive start and the bounded stretch of playback's
// schedule, on a manual timeline (no clock: every time is given).
#include "playback_schedule.h"
#include "playback_estimator.h"
#include "playback_model.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <functional>
#include <memory>
#include <random>

namespace robotalk {
namespace {

using std::chrono::milliseconds;

using namespace playback_model;

TEST(PlaybackSchedule, WithoutStretchEveryFramePlaysAtStartPlusItsOffset) {
  PlaybackSchedule s(kT0, std::nullopt, {.max_stretch = 0});
  EXPECT_EQ(s.Place(Duration(0), kT0 - milliseconds(5)).at, kT0);
  EXPECT_EQ(s.Place(milliseconds(100), kT0 + milliseconds(99)).at, kT0 + milliseconds(100));
  // Arriving after its time: late, and the schedule does not move.
  const auto late = s.Place(milliseconds(200), kT0 + milliseconds(250));
  EXPECT_TRUE(late.late);
  EXPECT_EQ(late.at, kT0 + milliseconds(200));
  EXPECT_EQ(s.Place(milliseconds(300), kT0 + milliseconds(260)).at, kT0 + milliseconds(300));
  EXPECT_EQ(s.late_frames(), 1u);
  EXPECT_EQ(s.stretch(), Duration(0));
}

TEST(PlaybackSchedule, AFrameSlowerThanTheBufferStretchesItsGapWithinTheBound) {
  PlaybackSchedule s(kT0, std::nullopt, {.max_stretch = 0.05, .margin = kMargin});
  EXPECT_EQ(s.Place(Duration(0), kT0 - milliseconds(5)).at, kT0);
  // Due at +100 ms, here at +101 ms: plays at +103 (its arrival + the margin), a 3 % longer gap.
  const auto p = s.Place(milliseconds(100), kT0 + milliseconds(101));
  EXPECT_FALSE(p.late);
  EXPECT_EQ(p.at, kT0 + milliseconds(103));
  EXPECT_NEAR(s.max_gap_stretch(), 0.03, 1e-9);
  // The next gap is measured from the stretched frame: the delay is kept, not caught up.
  EXPECT_EQ(s.Place(milliseconds(200), kT0 + milliseconds(150)).at, kT0 + milliseconds(203));
  EXPECT_EQ(s.stretch(), milliseconds(3));
  EXPECT_EQ(s.late_frames(), 0u);
}

TEST(PlaybackSchedule, AFramePastTheBoundIsLateAndTheSequencePausesForIt) {
  PlaybackSchedule s(kT0, std::nullopt, {.max_stretch = 0.05, .margin = kMargin});
  s.Place(Duration(0), kT0 - milliseconds(5));
  // The bound allows +105 ms; it arrives at +120: late, plays at +122.
  const auto p = s.Place(milliseconds(100), kT0 + milliseconds(120));
  EXPECT_TRUE(p.late);
  EXPECT_EQ(p.at, kT0 + milliseconds(122));
  EXPECT_EQ(s.late_frames(), 1u);
  EXPECT_EQ(s.max_gap_stretch(), 0.0) << "a pause is counted as late, not as a stretch";
  // The frames after it keep its headroom: on time again.
  const auto next = s.Place(milliseconds(200), kT0 + milliseconds(205));
  EXPECT_FALSE(next.late);
  EXPECT_EQ(next.at, kT0 + milliseconds(222));
}

TEST(PlaybackSchedule, AReorderedFramePlaysBetweenItsNeighboursWithinTheBound) {
  PlaybackSchedule s(kT0, std::nullopt, {.max_stretch = 0.05, .margin = kMargin});
  s.Place(Duration(0), kT0 - milliseconds(5));
  EXPECT_EQ(s.Place(milliseconds(200), kT0 + milliseconds(208)).at, kT0 + milliseconds(210));  // +5 %
  // Offset 100 arrives after offset 200: 100 ms before it, the first gap takes the stretch.
  const auto p = s.Place(milliseconds(100), kT0 + milliseconds(209));
  EXPECT_EQ(p.at, kT0 + milliseconds(110));
  EXPECT_TRUE(p.late) << "its time had passed when it came";
  const auto q = s.Place(milliseconds(200), kT0 + milliseconds(150));  // a second command at 200 ms
  EXPECT_EQ(q.at, kT0 + milliseconds(210));
  EXPECT_FALSE(q.late);
}

TEST(PlaybackSchedule, ASlowFrameRaisesThePlayoutDelaySoTheNextGetItsHeadroom) {
  // Playout delay 10 ms (send time + 10 ms); frame 1 takes 12 ms.
  PlaybackSchedule s(kT0, milliseconds(10), {.max_stretch = 0.05, .margin = kMargin});
  s.Place(Duration(0), kT0 - milliseconds(5), milliseconds(5));
  const auto p1 = s.Place(milliseconds(100), kT0 + milliseconds(102), milliseconds(12));
  EXPECT_EQ(p1.at, kT0 + milliseconds(104));  // 12 + 2 ms margin after its send time at +90
  EXPECT_EQ(*s.playout_delay(), milliseconds(14));
  // Frame 2, sent at +190, took 1 ms: plays 14 ms after its send time, not at +191.
  EXPECT_EQ(s.Place(milliseconds(200), kT0 + milliseconds(191), milliseconds(1)).at, kT0 + milliseconds(204));
  // A frame the client sent 8 ms behind its pacing (at +298), fast (1 ms):
  // 14 ms after its send time would be +312, but a gap stretches 5 % at most.
  EXPECT_EQ(s.Place(milliseconds(300), kT0 + milliseconds(299), milliseconds(1)).at, kT0 + milliseconds(309));
  EXPECT_NEAR(s.max_gap_stretch(), 0.05, 1e-9);
  EXPECT_EQ(s.late_frames(), 0u);
}

// --- The adaptive start with its schedule, on simulated channels ------------
// (playback_model.h)

// The schedule as these figures were measured: every gap within 10 %, no
// thin buffer (issue 23's tenth session, on by default since; its own
// figures on the same channels are in playback_thin_test.cpp).
const PlaybackEstimatorOptions kTenPercent{.thin_stretch = 0};

TEST(AdaptivePlayback, OnAJitteryChannelStartsNearTheHindsightMinimumAndFramesAreRarelyLate) {
  // Delays uniform in [0, 40] ms at 10 Hz: 1000 seeded channels. The quick
  // start (2.5 x spread + 10 ms, fixed timing) had a median 2.7x (its test in
  // playback_estimator_test.cpp) with no late run.
  const Summary s = Many(
      1000, [](std::mt19937_64& rng, std::size_t, TimePoint) { return Uniform(rng, 0, 40); }, kTenPercent);
  std::printf("U[0, 40] ms: median ratio %.2f, late runs %d, worst gap stretch %.3f\n", s.median_ratio,
              s.late_runs, s.worst_stretch);
  // 10 connect-time delays are a small sample of the channel: in 35 runs of
  // 1000 a frame came later than the buffer had grown by then, mostly frame
  // 1, which the start lead covers only to the worst seen + spread / n (2 of
  // 1000 without the lead, whose start exceeds 1.25x four times as often:
  // TheStartLeadMeetsTheGoalInMoreRunsOnEveryChannel).
  EXPECT_LE(s.late_runs, 50);
  EXPECT_LE(s.median_ratio, 1.25);
  EXPECT_LE(s.worst_stretch, PlaybackEstimatorOptions{}.max_stretch + 1e-9);
}

TEST(AdaptivePlayback, OnAWanProfileStartsNearTheHindsightMinimumAndFramesAreRarelyLate) {
  // 100-300 ms of delay (the path's, fixed per run), +-50 ms jitter.
  const Summary s = Many(
      1000,
      [](std::mt19937_64& rng, std::size_t k, TimePoint) {
        static thread_local Duration base{};
        if (k == 0) base = Uniform(rng, 100, 300);
        return base + Uniform(rng, -50, 50);
      },
      kTenPercent);
  std::printf("WAN: median ratio %.2f, late runs %d, worst gap stretch %.3f\n", s.median_ratio, s.late_runs,
              s.worst_stretch);
  // 43 of 1000 runs (16 without the start lead): the same small sample of a
  // 100 ms spread, a frame slower than the start covered before the first
  // gaps could stretch for it.
  EXPECT_LE(s.late_runs, 60);
  EXPECT_LE(s.median_ratio, 1.25);
  EXPECT_LE(s.worst_stretch, PlaybackEstimatorOptions{}.max_stretch + 1e-9);
}

TEST(AdaptivePlayback, OnACongestedLinkAQueueBuildsAndTheStartCoversIt) {
  // Frames every 100 ms; connect-time packages are round trips (no queue).
  // Beyond a spread of 1.2 frame intervals the paper's estimate decides by
  // default (X = 150: median 14.9x); with the queue start (an option, see
  // the next test) the start is decided within the first frames.
  // (The default now follows such a queue, playback_follow_test.cpp; here
  // the gate as it was.)
  const PlaybackEstimatorOptions queue{.thin_stretch = 0, .queue_start = true};
  for (double x : {50.0, 100.0, 150.0}) {
    const Summary s = Many(300, Fifo(x), {.thin_stretch = 0, .follow_queue = false});
    const Summary q = Many(300, Fifo(x), queue);
    std::printf(
        "X = %.0f: median ratio %.2f, late runs %d of 300 (%d frames), worst gap stretch %.3f; "
        "queue start %.2f, %d of 300 (%d frames)\n",
        x, s.median_ratio, s.late_runs, s.late_frames, s.worst_stretch, q.median_ratio, q.late_runs,
        q.late_frames);
    EXPECT_LE(s.worst_stretch, PlaybackEstimatorOptions{}.max_stretch + 1e-9);
    EXPECT_LE(q.worst_stretch, PlaybackEstimatorOptions{}.max_stretch + 1e-9);
    if (x < 120) {  // a frame's service fits in its interval
      // 9 and 12 of 300 (2 and 3 without the start lead): frame 1 slower than the worst seen.
      EXPECT_LE(s.late_runs, 20) << "X = " << x;
      EXPECT_LE(s.median_ratio, 1.25) << "X = " << x;
      EXPECT_LE(q.median_ratio, 1.25) << "X = " << x;
      continue;
    }
    // A queue at 75 % load: the paper's estimate 14.9x with 36 runs of 300
    // late; the queue start 1.42x with 52: ten services seen cannot tell the
    // worst of 40 frames to 25 %.
    EXPECT_GT(s.median_ratio, 5.0);
    EXPECT_LE(q.median_ratio, 1.6);
    EXPECT_LE(q.late_runs, 70);
  }
}

TEST(AdaptivePlayback, OnACongestedLinkTheConnectBurstsOwnQueueDoesNotTripTheGate) {
  // The relay's U[0, X] FIFO link with the client's connect-time packages
  // sent as a burst (1 ms apart) 4 s before the sequence: each waits behind
  // the one before it, so their delays add up (the paper's estimate decided
  // in 5 of 10 relay runs at X = 100, 9 of 10 at X = 150). Less that wait,
  // the delays spread as the services, which frames 100 ms apart meet.
  for (double x : {100.0, 150.0}) {
    const Summary before =
        Many(300, Fifo(x), {.thin_stretch = 0, .burst_wait_discount = false, .follow_queue = false}, 40, 4);
    const Summary now = Many(300, Fifo(x), kTenPercent, 40, 4);
    std::printf(
        "X = %.0f, a burst of 4: median ratio %.2f -> %.2f, late runs %d -> %d of 300 (%d -> %d frames)\n", x,
        before.median_ratio, now.median_ratio, before.late_runs, now.late_runs, before.late_frames,
        now.late_frames);
    EXPECT_LE(now.worst_stretch, PlaybackEstimatorOptions{}.max_stretch + 1e-9);
    EXPECT_LT(now.median_ratio, before.median_ratio) << "X = " << x;
    if (x < 120) {  // a frame's service fits in its interval
      // Measured 29.7 -> 1.60, 2 -> 8 late runs: four services are a small
      // sample, and a waiting package's delay is the least seen (the first
      // package's, a service itself) + its service, an overestimate by the
      // least service (never an underestimate: see ChannelDelays).
      EXPECT_GT(before.median_ratio, 5.0) << "the cause, reproduced: the paper's estimate";
      EXPECT_LE(now.median_ratio, 2.0);
      EXPECT_LE(now.late_runs, 20);
    }
  }
  // Fig. 11's server pauses with the same burst: the burst's services are
  // the pauses (U[0, 250] ms), so the gate mostly still gives the paper's
  // estimate; where all four pauses were under 1.2 intervals (0.48^4, 5 %)
  // the adaptive start decides and the 25 % drift outruns the stretch:
  // measured 2 -> 6 runs late of 100.
  const Summary fig11 = Many(100, ServerPauses(250), kTenPercent, 129, 4);
  const Summary fig11_before =
      Many(100, ServerPauses(250), {.thin_stretch = 0, .burst_wait_discount = false}, 129, 4);
  std::printf("Fig. 11 injector, a burst of 4: runs late %d -> %d of 100\n", fig11_before.late_runs,
              fig11.late_runs);
  EXPECT_LE(fig11.late_runs, 10);
}

TEST(AdaptivePlayback, ThePapersCongestionGetsThePapersEstimateBecauseNeitherStartCanSeeItsDrift) {
  // Fig. 11 (129 frames at 10 Hz): the server reads 8 packages a second, the
  // client sends 10, so every frame comes later than the one before (~2.8 s
  // over the sequence). A start that covers only the delays seen (the jitter
  // start at any spread) leaves a 25 % drift to a stretch bounded to 10 %:
  // every run has frames past the bound (fig11_congestion failed with it).
  // The queue start sees the drift only in the services of sparse
  // connect-time packages, most of which met no pause: it misses it in a
  // fifth of the runs. The paper's estimate (the default beyond 1.2 frame
  // intervals) waits for 13 frames, which show it.
  const Summary jitter = Many(100, ServerPauses(250), {.adaptive_max_spread = 1e9}, 129);
  const Summary queued = Many(100, ServerPauses(250), {.queue_start = true}, 129);
  const Summary paper = Many(100, ServerPauses(250), {}, 129);
  std::printf(
      "Fig. 11 injector, runs late of 100: jitter start %d (%d frames), queue start %d (%d frames), "
      "paper's %d (median ratio %.2f)\n",
      jitter.late_runs, jitter.late_frames, queued.late_runs, queued.late_frames, paper.late_runs,
      paper.median_ratio);
  EXPECT_EQ(jitter.late_runs, 100) << "the cause, reproduced";
  EXPECT_GE(queued.late_runs, 5);
  EXPECT_EQ(paper.late_runs, 0);
}

TEST(AdaptivePlayback, TheStartLiesOneGapsStretchBelowTheWorstDelayAndTheFirstGapReachesIt) {
  // Ten recent delays 1, 4, ..., 28 ms; frame 0 took 1 ms. The start covers
  // the worst, 28 ms, + spread / n (27 ms / 11) + the 2 ms margin, less frame
  // 0's own 1 ms: 30.45 ms after its arrival with no lead; one gap's stretch
  // (10 % of 100 ms) earlier with the lead (the default).
  std::vector<Duration> history;
  for (int i = 0; i < 10; ++i) history.push_back(milliseconds(1 + 3 * i));
  const double covered_s = 0.028 + 0.027 / 11 + 0.002 - 0.001;
  const auto start_of = [&](double lead, Duration first_delay) {
    PlaybackEstimator est(40, milliseconds(3900), {.start_lead = lead});
    est.SetDelayHistory(history);
    est.Add(Duration(0), kT0, kT0 - first_delay);
    EXPECT_TRUE(est.adaptive());
    return std::make_pair(est.StartTime(), *est.playout_delay());
  };
  const auto [before, playout] = start_of(0, milliseconds(1));
  EXPECT_NEAR(ToSeconds(before - kT0), covered_s, 1e-6);
  const auto [start, playout_now] = start_of(1, milliseconds(1));
  EXPECT_NEAR(ToSeconds(start - kT0), covered_s - 0.010, 1e-6);
  EXPECT_EQ(playout_now, playout) << "the buffer the schedule grows to is the same";
  // Frame 1, sent 100 ms after frame 0 and as slow as the worst seen (28
  // ms): its gap stretches by 10 ms at most, which reaches it.
  const auto place_frame1 = [&, start = start, playout = playout](Duration delay) {
    PlaybackSchedule s(start, playout, {.max_stretch = 0.10, .margin = kMargin});
    EXPECT_FALSE(s.Place(Duration(0), kT0, milliseconds(1)).late);
    const TimePoint sent = kT0 - milliseconds(1) + milliseconds(100);
    const auto p = s.Place(milliseconds(100), sent + delay, delay);
    if (!p.late) {
      EXPECT_LE(p.at, start + milliseconds(110)) << "within the bound";
    }
    return std::make_pair(p, s.max_gap_stretch());
  };
  const auto [on_time, stretch] = place_frame1(milliseconds(28));
  EXPECT_FALSE(on_time.late);
  EXPECT_NEAR(stretch, 0.10, 1e-6) << "the first gap takes the whole lead";
  // The trade: a frame 1 slower than the worst seen + spread / n - the
  // margin is late now; without the lead it had 10 ms more.
  EXPECT_TRUE(place_frame1(milliseconds(31)).first.late);
  EXPECT_GE(before + milliseconds(110), kT0 + milliseconds(99 + 31 + 2));
  // Frame 0 as slow as the worst seen: the start is its arrival + the
  // margin, never before (the decision, and frame 0's hand-over).
  EXPECT_EQ(start_of(1, milliseconds(28)).first, kT0 + kMargin);
}

TEST(AdaptivePlayback, TheStartLeadMeetsTheGoalInMoreRunsOnEveryChannel) {
  // The goal of issue 23 item 3 for a run: start / (hindsight minimum + the
  // margin) <= 1.25 and no frame late. Without the lead the start covers the
  // worst delay itself: the ratio exceeds 1.25 whenever frame 0 was slow
  // (its own delay is the hindsight's floor), which the lead halves at the
  // cost of a frame 1 slower than the worst seen being late (late runs 2 ->
  // 35 of 1000 at U[0, 40]).
  const std::vector<std::pair<const char*, Channel>> channels = {{"U[0, 40] ms", Jitter(40)},
                                                                 {"FIFO U[0, 50] ms", Fifo(50)},
                                                                 {"FIFO U[0, 100] ms", Fifo(100)},
                                                                 {"WAN", Wan()}};
  constexpr int kRuns = 300;
  for (const auto& [name, channel] : channels) {
    int met[2] = {0, 0}, late_runs[2] = {0, 0};
    for (int lead = 0; lead <= 1; ++lead) {
      for (int seed = 1; seed <= kRuns; ++seed) {
        std::mt19937_64 rng(static_cast<std::uint64_t>(seed));
        const SimRun r = Simulate(
            40, milliseconds(100), 10, [&](std::size_t k, TimePoint sent) { return channel(rng, k, sent); },
            {.thin_stretch = 0, .start_lead = static_cast<double>(lead)}, false, channel.server_lag.get());
        late_runs[lead] += r.late > 0;
        met[lead] += r.late == 0 && ToSeconds(r.start_delay) <= 1.25 * ToSeconds(r.hindsight + kMargin);
        EXPECT_LE(r.max_gap_stretch, 0.10 + 1e-9);
      }
    }
    std::printf("%s: goal met in %d of %d runs without the lead (%d late), %d with it (%d late)\n", name,
                met[0], kRuns, late_runs[0], met[1], late_runs[1]);
    EXPECT_GT(met[1], met[0]) << name;
    EXPECT_GE(met[1], kRuns * 9 / 10) << name;
    EXPECT_LE(late_runs[1], kRuns / 15) << name;
  }
}

TEST(AdaptivePlayback, TheOldEstimatorsRemainOptions) {
  auto jitter = [](std::mt19937_64& rng, std::size_t, TimePoint) { return Uniform(rng, 0, 40); };
  const Summary quick = Many(200, jitter, {.adaptive = false});
  EXPECT_EQ(quick.worst_stretch, 0.0) << "fixed timing";
  EXPECT_GT(quick.median_ratio, 2.0);
  const Summary paper = Many(50, jitter, {.quick_start = false, .adaptive = false});
  EXPECT_EQ(paper.late_frames, 0);
  EXPECT_GT(paper.median_ratio, 5.0) << "waits for 5 frames";
}

TEST(AdaptivePlayback, ARetransmittedPackageInTheHistoryDoesNotInflateTheStart) {
  // A LAN (1.0-1.9 ms); one connect-time package was lost and came as its
  // retransmission 100 ms after its first send time (+ 1 ms).
  std::vector<Duration> history;
  for (int i = 0; i < 10; ++i) history.push_back(std::chrono::microseconds(1000 + 100 * i));
  history.push_back(milliseconds(101));
  // No start lead (it would put the start at the floor, the arrival + 2 ms,
  // and hide what this test checks).
  PlaybackEstimator est(40, milliseconds(3900), {.start_lead = 0});
  est.SetDelayHistory(history);
  est.Add(Duration(0), kT0, kT0 - milliseconds(1));
  ASSERT_TRUE(est.adaptive());
  // Covers the 1.9 ms worst + 0.9 ms / 11 + 2 ms, less this frame's 1 ms.
  EXPECT_EQ(est.StartTime(), kT0 + std::chrono::microseconds(2900) + FromSeconds(0.0009 / 11));
  // Beyond 1.2 frame intervals (a retransmission on a WAN, or the paper's
  // congestion) the queue start decides when on; the retransmission is no service
  // either: the worst, 1.9 ms, + 2 ms, less this frame's 1 ms.
  history.back() = milliseconds(130);
  PlaybackEstimator wide(40, milliseconds(3900), {.queue_start = true});
  wide.SetDelayHistory(history);
  wide.Add(Duration(0), kT0, kT0 - milliseconds(1));
  EXPECT_TRUE(wide.queued());
  EXPECT_EQ(wide.StartTime(), kT0 + std::chrono::microseconds(2900));
}

TEST(QueueStart, ReadsEachServiceFromABurstAndCoversTheWorstWhereNoQueueCanBuild) {
  // Six connect-time packages sent at once (1 ms path): the first served at
  // once, the next five 30 ms each, so they queue: delays 1, 31, ..., 151 ms,
  // a spread of 1.5 frame intervals (the paper's estimate before). Each
  // package's service is what it added behind the one before (30 ms); at 10
  // Hz no queue of frames builds from 30 ms services, so the start covers
  // the worst service: 31 ms of delay, 30 more than this frame's, + 2 ms.
  const TimePoint burst = kT0 - std::chrono::seconds(2);
  std::vector<DelayHistory::Sample> history{{burst + milliseconds(1), milliseconds(1)}};
  for (int j = 1; j <= 5; ++j)
    history.push_back({burst + milliseconds(1 + 30 * j), milliseconds(1 + 30 * j)});
  // (Without the burst's discount, AConnectBurstThatQueuedBehindItself... below.)
  PlaybackEstimator est(40, milliseconds(3900), {.queue_start = true, .burst_wait_discount = false});
  est.SetDelayHistory(history);
  est.Add(Duration(0), kT0, kT0 - milliseconds(1));
  ASSERT_TRUE(est.ready());
  EXPECT_TRUE(est.queued());
  EXPECT_EQ(est.StartTime(), kT0 + milliseconds(32));
  EXPECT_EQ(est.playout_delay(), milliseconds(33));
  // Without the queue start: the paper's estimate, which waits for frames.
  PlaybackEstimator paper(40, milliseconds(3900), {.burst_wait_discount = false, .follow_queue = false});
  paper.SetDelayHistory(history);
  paper.Add(Duration(0), kT0, kT0 - milliseconds(1));
  EXPECT_FALSE(paper.ready());
}

TEST(AdaptivePlayback, AConnectBurstThatQueuedBehindItselfOnAFifoLinkGetsTheAdaptiveStart) {
  // The same burst (issue 23 item 3's U[0, 100] and U[0, 150] relay runs):
  // six packages sent at once through a FIFO link, delays 1, 31, ..., 151
  // ms. Package j waited 30 (j - 1) ms behind package j - 1, sent with it;
  // a frame, 100 ms after the one before it, does not. Less that wait each
  // took 31 ms: a spread of 30 ms, within the gate, so the adaptive start
  // decides at the first frame: the worst, 31 ms, + 30 ms / 7 delays, less
  // this frame's 1 ms and the 10 ms start lead, + 2 ms (with the discount
  // off: the paper's estimate, ReadsEachServiceFromABurst... above).
  const TimePoint burst = kT0 - std::chrono::seconds(2);
  std::vector<DelayHistory::Sample> history{{burst + milliseconds(1), milliseconds(1)}};
  for (int j = 1; j <= 5; ++j)
    history.push_back({burst + milliseconds(1 + 30 * j), milliseconds(1 + 30 * j)});
  PlaybackEstimator est(40, milliseconds(3900));
  est.SetDelayHistory(history);
  est.Add(Duration(0), kT0, kT0 - milliseconds(1));
  ASSERT_TRUE(est.adaptive());
  EXPECT_FALSE(est.queued());
  ASSERT_TRUE(est.ready());
  EXPECT_EQ(est.delay_spread(), milliseconds(30));
  EXPECT_TRUE(est.burst_discounted());
  EXPECT_EQ(est.StartTime(), kT0 + milliseconds(22) + FromSeconds(0.030 / 7));
  // The schedule grows the buffer to the worst + 4 x 30 ms / 7, + 2 ms.
  EXPECT_EQ(est.playout_delay(), milliseconds(33) + FromSeconds(0.120 / 7));
  // Sent a frame interval apart they are no burst:
  // their delays are the channel's as frames meet it: beyond the gate, the
  // paper's estimate (follow_queue off), or by default the queue follow
  // (playback_follow_test.cpp), which covers them by its playout delay.
  std::vector<DelayHistory::Sample> paced{{burst + milliseconds(1), milliseconds(1)}};
  for (int j = 1; j <= 5; ++j)
    paced.push_back({burst + milliseconds(100 * j + 1 + 30 * j), milliseconds(1 + 30 * j)});
  PlaybackEstimator sparse(40, milliseconds(3900), {.follow_queue = false});
  sparse.SetDelayHistory(paced);
  sparse.Add(Duration(0), kT0, kT0 - milliseconds(1));
  EXPECT_FALSE(sparse.adaptive());
  EXPECT_FALSE(sparse.ready());
  const PlaybackEstimator followed = AtFirstFrame(paced);
  EXPECT_TRUE(followed.followed());
  EXPECT_TRUE(followed.ready());
}

TEST(QueueStart, WaitsWhileTheNextFrameMayComeFirstAndLearnsFromEachFrame) {
  // Services of 0 to 160 ms (the history's arrivals unknown: a delay's
  // excess over the least is taken as its service): a queue of 100 ms
  // frames builds, so the start lies beyond the next frame's arrival; until
  // the next frame may come after it, each frame adds its service and the
  // start is decided again. It is never before the latest frame's arrival.
  std::vector<Duration> history;
  for (int j = 0; j < 10; ++j) history.push_back(milliseconds(1 + 40 * (j % 5)));
  PlaybackEstimator est(40, milliseconds(3900), {.queue_start = true});
  est.SetDelayHistory(history);
  est.Add(Duration(0), kT0, kT0 - milliseconds(1));
  ASSERT_TRUE(est.queued());
  EXPECT_FALSE(est.ready());
  const TimePoint first = est.StartTime();
  EXPECT_GT(first - kT0, milliseconds(160)) << "the worst service and the queue behind it";
  int frames = 1;
  for (; !est.ready() && frames < 5; ++frames) {
    const TimePoint arrival = kT0 + milliseconds(100) * frames;
    est.Add(milliseconds(100) * frames, arrival, arrival - milliseconds(1));
  }
  ASSERT_TRUE(est.ready()) << "before the paper's 5 frames";
  EXPECT_TRUE(est.queued());
  EXPECT_GE(est.StartTime(), kT0 + milliseconds(100) * (frames - 1) + milliseconds(2));
}

TEST(QueueStart, AChannelThatMayBeSlowerThanTheSequenceGetsThePapersEstimate) {
  // Services of 0 to 250 ms, 125 on average at 100 ms frames: a drift the
  // 10 % stretch cannot follow. Not the queue start: the paper's, after 5 frames.
  std::vector<Duration> history;
  for (int j = 0; j < 10; ++j) history.push_back(milliseconds(1 + 250 * j / 9));
  PlaybackEstimator est(40, milliseconds(3900), {.queue_start = true});
  est.SetDelayHistory(history);
  est.Add(Duration(0), kT0, kT0 - milliseconds(1));
  EXPECT_FALSE(est.queued());
  EXPECT_FALSE(est.adaptive());
  EXPECT_FALSE(est.ready()) << "waits for frames";
}

TEST(AdaptivePlayback, AClientWithoutSendTimesGetsThePapersStartThenTheStretch) {
  PlaybackEstimator est(40, milliseconds(3900));
  est.SetDelayHistory(std::vector<Duration>(10, milliseconds(1)));
  est.Add(Duration(0), kT0);
  EXPECT_FALSE(est.ready());
  EXPECT_FALSE(est.adaptive());
  EXPECT_FALSE(est.playout_delay().has_value());
}

}  // namespace
}  // namespace robotalk
