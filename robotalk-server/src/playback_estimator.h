// Playback mode's delay estimate (paper §V-C), as pure maths: no I/O, no
// clock of its own. Feed it the arrival time and the sequence offset of each
// frame; once enough frames are in, it says when offset 0 must play so that
// the whole declared sequence plays without running dry.
//
// Model: with k frames seen, T_c is the average time between commands
// (their offsets) and T_a the average time between arrivals. If arrivals are
// slower (T_a > T_c) the backlog grows by (T_a - T_c) per frame, so the last
// of the N declared frames arrives about (N-1)(T_a - T_c) after the first one
// would have had to play. The start must also clear every frame already seen
// (start + o_i >= a_i), plus a margin for the jitter seen so far. T_a is taken
// at the upper bound of its confidence interval: a few frames give a noisy
// mean, and running dry costs more than starting a little later.
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
  /// The arrival interval used for the projection (upper confidence bound).
  Duration arrival_interval_bound() const;

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
