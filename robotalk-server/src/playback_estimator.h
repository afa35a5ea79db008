// Playback mode's delay estimate (paper §V-C), as pure maths: no I/O, no
// clock of its own. Feed it the arrival time and the sequence offset of each
// frame; once enough frames are in, it says when offset 0 must play so that
// the whole declared sequence plays without running dry.
//
// Model (paper §V-C): T_c is the average time between commands (their
// offsets), T_a the average time between arrivals. If arrivals are slower
// (T_a > T_c) every frame lags further behind its offset, by (T_a/T_c - 1)
// per second of sequence, so the last frame, at offset D, lags about
// D·(T_a/T_c - 1) more than the first. A congested channel makes that growth
// a random walk (a queue's backlog), so the estimator projects the worst lag
// seen so far to D with the drift and the spread of the walk, both at an
// upper confidence bound (ExtraLagBound), adds a margin, and never starts
// before the moment it decides (playback's start latency).
#pragma once

#include "robotalk/clock.h"

#include <cstddef>
#include <optional>
#include <vector>

namespace robotalk {

struct PlaybackEstimatorOptions {
  /// Frames needed before estimating: max(min_frames, fraction * N), capped at N.
  std::size_t min_frames = 5;
  double fraction = 0.1;
  /// Added to the estimate, on top of the jitter observed.
  Duration margin = std::chrono::milliseconds(100);
  /// The arrival rate is taken at the upper bound of its confidence interval,
  /// mean + z · standard error (2 ≈ 97.5 % one-sided for many frames).
  double confidence_z = 2.0;
};

class PlaybackEstimator {
 public:
  /// `total_frames` and `duration` (offset of the last frame) as the client declared.
  PlaybackEstimator(std::size_t total_frames, Duration duration, PlaybackEstimatorOptions options = {});

  /// Records one frame: its offset from the sequence start and its arrival.
  void Add(Duration offset, TimePoint arrival);
  std::size_t frames_seen() const { return frames_.size(); }
  std::size_t frames_needed() const { return needed_; }
  bool ready() const { return frames_.size() >= needed_; }

  /// The server time at which offset 0 plays. REQUIRES: ready().
  TimePoint StartTime() const;
  /// Average time between commands and between arrivals over the frames seen.
  Duration mean_command_interval() const;
  Duration mean_arrival_interval() const;
  /// How much more than the worst lag seen so far the last frame may lag,
  /// `remaining` seconds of sequence later (upper confidence bound).
  Duration ExtraLagBound(Duration remaining) const;

 private:
  struct Frame {
    Duration offset;
    TimePoint arrival;
  };
  std::size_t total_;
  Duration duration_;
  PlaybackEstimatorOptions options_;
  std::size_t needed_;
  std::vector<Frame> frames_;
};

}  // namespace robotalk
