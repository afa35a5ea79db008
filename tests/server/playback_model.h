// Issue 23 item 3: a pure model of playback over a simulated channel (no
// clock, no I/O): a paced client, its connect-time packages, the estimator's
// start and the bounded stretch, the hindsight minimum of each run. Shared by
// playback_schedule_test.cpp and playback_stretch_test.cpp.
#pragma once

#include "playback_estimator.h"
#include "playback_schedule.h"

#include <algorithm>
#include <functional>
#include <memory>
#include <optional>
#include <random>
#include <type_traits>
#include <vector>

namespace robotalk::playback_model {

using std::chrono::milliseconds;

inline const TimePoint kT0(std::chrono::seconds(100));
inline const Duration kMargin = milliseconds(2);

struct SimRun {
  int late = 0;
  std::size_t thin_gaps = 0;  // gaps stretched past max_stretch (a thin buffer's)
  Duration start_delay{};     // offset 0's time − the first arrival
  Duration hindsight{};       // the least delay after the first arrival with no frame late
  double max_gap_stretch = 0;
  Duration stretch{};  // of the last frame
};

// A paced client (frame i sent at offset i), `history` connect-time packages
// before it (each a round trip: sent once the one before it arrived, and at
// least 20 ms after it; with `burst`, all sent 1 ms apart, as a client's
// hello, clock and heartbeat), one-way delay delay(k, sent) for the k-th package;
// its clock reads 5000 s ahead. `options` decides how the start is estimated.
// `server_lag`, where given, holds how long after it reached the server's
// socket the last package delay() gave was handled (the server's own lag).
inline SimRun Simulate(std::size_t frames, Duration period, std::size_t history,
                       const std::function<Duration(std::size_t, TimePoint)>& delay,
                       PlaybackEstimatorOptions options = {}, bool burst = false,
                       const Duration* server_lag = nullptr) {
  const auto lag = [server_lag] { return server_lag ? *server_lag : Duration(0); };
  const Duration skew = std::chrono::seconds(5000);
  PlaybackEstimator est(frames, period * static_cast<int>(frames - 1), options);
  DelayHistory h;
  std::size_t k = 0;
  for (TimePoint next = kT0 - std::chrono::seconds(4); k < history; ++k) {
    const TimePoint sent = next, arrival = sent + delay(k, sent);
    h.Add(sent + skew, arrival, arrival - lag());
    next = burst ? sent + milliseconds(1) : std::max(sent + milliseconds(20), arrival + milliseconds(1));
  }
  struct Frame {
    Duration offset;
    TimePoint arrival, sent;
    Duration lag;
  };
  std::vector<Frame> all;
  for (std::size_t i = 0; i < frames; ++i, ++k) {
    const TimePoint sent = kT0 + period * static_cast<int>(i);
    const TimePoint arrival = sent + delay(k, sent);
    all.push_back({period * static_cast<int>(i), arrival, sent + skew, lag()});
  }
  std::stable_sort(all.begin(), all.end(),
                   [](const Frame& a, const Frame& b) { return a.arrival < b.arrival; });
  const TimePoint first = all.front().arrival;
  SimRun run;
  for (const Frame& f : all) run.hindsight = std::max(run.hindsight, f.arrival - first - f.offset);
  est.SetDelayHistory(h.RecentSamples(first));
  std::optional<PlaybackSchedule> schedule;
  std::vector<const Frame*> buffered;
  for (const Frame& f : all) {
    if (!schedule) {
      est.Add(f.offset, f.arrival, f.sent, f.lag);
      buffered.push_back(&f);
      if (!est.ready()) continue;
      const TimePoint start = est.StartTime();
      run.start_delay = start - first;
      schedule.emplace(start, est.playout_delay(), est.schedule_options());
      std::stable_sort(buffered.begin(), buffered.end(),
                       [](const Frame* a, const Frame* b) { return a->offset < b->offset; });
      for (const Frame* b : buffered) {
        const auto p = schedule->Place(b->offset, b->arrival, OneWayDelay(b->sent, b->arrival));
        if (p.late || p.at < b->arrival) ++run.late;
      }
      continue;
    }
    const auto p = schedule->Place(f.offset, f.arrival, OneWayDelay(f.sent, f.arrival));
    if (p.late || p.at < f.arrival) ++run.late;
  }
  run.max_gap_stretch = schedule->max_gap_stretch();
  run.thin_gaps = schedule->thin_gaps();
  run.stretch = schedule->stretch();
  return run;
}

struct Summary {
  int late_runs = 0, late_frames = 0;
  double median_ratio = 0, worst_stretch = 0;
};

// `runs` seeded channels; the ratio is the start delay over the hindsight
// minimum, both + the 2 ms margin every start needs (a frame must be in the
// RobotDaemon's queue before it is due).
// A channel: the k-th package's delay (sent at `sent`), and where the server
// itself is the queue, its lag handling that package (handled − reached the
// socket), written into `server_lag` as each delay is drawn.
struct Channel {
  template <class F>
  requires(!std::is_same_v<std::decay_t<F>, Channel>)
      Channel(F f,
              std::shared_ptr<Duration> lag = std::make_shared<Duration>(0))  // NOLINT: a lambda is a channel
      : delay(std::move(f)), server_lag(std::move(lag)) {}
  std::function<Duration(std::mt19937_64&, std::size_t, TimePoint)> delay;
  std::shared_ptr<Duration> server_lag;
  Duration operator()(std::mt19937_64& rng, std::size_t k, TimePoint sent) const {
    return delay(rng, k, sent);
  }
};
// Seeds 1 to `runs` of `channel`: `frames` at 10 Hz after 10 connect-time
// round trips, or a burst of `burst` packages; each run to `each`.
inline void ForEachRun(int runs, const Channel& channel, PlaybackEstimatorOptions options, std::size_t frames,
                       std::size_t burst, const std::function<void(const SimRun&)>& each) {
  for (int seed = 1; seed <= runs; ++seed) {
    std::mt19937_64 rng(static_cast<std::uint64_t>(seed));
    each(Simulate(
        frames, milliseconds(100), burst > 0 ? burst : 10,
        [&](std::size_t k, TimePoint sent) { return channel(rng, k, sent); }, options, burst > 0,
        channel.server_lag.get()));
  }
}

inline Summary Many(int runs, const Channel& channel, PlaybackEstimatorOptions options = {},
                    std::size_t frames = 40, std::size_t burst = 0) {
  Summary s;
  std::vector<double> ratios;
  ForEachRun(runs, channel, options, frames, burst, [&](const SimRun& r) {
    s.late_frames += r.late;
    if (r.late > 0) ++s.late_runs;
    s.worst_stretch = std::max(s.worst_stretch, r.max_gap_stretch);
    ratios.push_back(ToSeconds(r.start_delay) / ToSeconds(r.hindsight + kMargin));
  });
  std::nth_element(ratios.begin(), ratios.begin() + runs / 2, ratios.end());
  s.median_ratio = ratios[static_cast<std::size_t>(runs / 2)];
  return s;
}

// Issue 23 item 3's goal over `runs` seeded runs of `channel`: runs with no
// frame late and start / (hindsight + 2 ms) <= 1.25, runs with a late frame,
// runs with a gap stretched past max_stretch (a thin buffer's), the median
// ratio, the largest gap stretch and the longest whole-sequence stretch.
struct Goal {
  int met = 0, late_runs = 0, thin_runs = 0;
  double median_ratio = 0, worst_gap = 0;
  Duration worst_stretch{};
};
inline Goal Runs(const Channel& channel, PlaybackEstimatorOptions options, std::size_t burst, int runs = 300,
                 std::size_t frames = 40) {
  Goal g;
  std::vector<double> ratios;
  ForEachRun(runs, channel, options, frames, burst, [&](const SimRun& r) {
    g.late_runs += r.late > 0;
    const double ratio = ToSeconds(r.start_delay) / ToSeconds(r.hindsight + kMargin);
    ratios.push_back(ratio);
    g.met += r.late == 0 && ratio <= 1.25;
    g.thin_runs += r.thin_gaps > 0;
    g.worst_gap = std::max(g.worst_gap, r.max_gap_stretch);
    g.worst_stretch = std::max(g.worst_stretch, r.stretch);
  });
  std::nth_element(ratios.begin(), ratios.begin() + runs / 2, ratios.end());
  g.median_ratio = ratios[static_cast<std::size_t>(runs / 2)];
  return g;
}

// A 40-frame sequence at 10 Hz whose frame 0 took 1 ms, arrived at kT0 and
// was handled `server_lag` after it reached the socket, after `history`.
inline PlaybackEstimator AtFirstFrame(const std::vector<DelayHistory::Sample>& history,
                                      PlaybackEstimatorOptions options = {},
                                      Duration server_lag = Duration(0)) {
  PlaybackEstimator est(40, milliseconds(3900), options);
  est.SetDelayHistory(history);
  est.Add(Duration(0), kT0, kT0 - milliseconds(1), server_lag);
  return est;
}
inline PlaybackEstimator AtFirstFrame(const std::vector<Duration>& history,
                                      PlaybackEstimatorOptions options = {}) {
  PlaybackEstimator est(40, milliseconds(3900), options);
  est.SetDelayHistory(history);
  est.Add(Duration(0), kT0, kT0 - milliseconds(1));
  return est;
}

inline Duration Uniform(std::mt19937_64& rng, double lo_ms, double hi_ms) {
  return FromSeconds(std::uniform_real_distribution<double>(lo_ms, hi_ms)(rng) / 1000.0);
}

// The relay's congestion: a FIFO link whose service is U[0, X] ms per message.
inline Channel Fifo(double x_ms) {
  auto busy = std::make_shared<TimePoint>();
  return {[busy, x_ms](std::mt19937_64& rng, std::size_t k, TimePoint sent) {
    if (k == 0) *busy = TimePoint{};
    *busy = std::max(*busy, sent) + Uniform(rng, 0, x_ms);
    return *busy - sent;
  }};
}

// Fig. 11's injector: the server pauses U[0, P] ms after each package it
// reads, so it reads the next one no sooner than that pause's end.
inline Channel ServerPauses(double p_ms) {
  // It reads a package no sooner than its pause ends: the package waited at
  // the socket that long (the server's own lag).
  auto free_at = std::make_shared<TimePoint>();
  auto lag = std::make_shared<Duration>(0);
  return {[free_at, lag, p_ms](std::mt19937_64& rng, std::size_t k, TimePoint sent) {
            if (k == 0) *free_at = TimePoint{};
            const TimePoint at_socket = sent + milliseconds(1);
            const TimePoint read = std::max(at_socket, *free_at);
            *lag = read - at_socket;
            *free_at = read + Uniform(rng, 0, p_ms);
            return read - sent;
          },
          lag};
}

inline Channel Jitter(double hi_ms) {
  return {[hi_ms](std::mt19937_64& rng, std::size_t, TimePoint) { return Uniform(rng, 0, hi_ms); }};
}

// A WAN path: 100-300 ms (fixed per run), +-50 ms uniform jitter.
inline Channel Wan() {
  auto base = std::make_shared<Duration>();
  return {[base](std::mt19937_64& rng, std::size_t k, TimePoint) {
    if (k == 0) *base = Uniform(rng, 100, 300);
    return *base + Uniform(rng, -50, 50);
  }};
}

}  // namespace robotalk::playback_model
