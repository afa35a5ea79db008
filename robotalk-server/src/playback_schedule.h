// When each frame of a started playback sequence plays (issue 23 item 3).
// Pure: no I/O, no clock of its own; times come from the caller.
//
// The start (PlaybackEstimator) is decided at the first frame, with a small
// buffer: the worst one-way delay seen recently. A later frame may still be
// slower than that. Instead of a start large enough for every frame to come
// (many times what the sequence needed, issue 23), the schedule lets each
// gap between successive frames stretch, within a bound, while the frame
// after it has not arrived:
//
//   - frame i (offset o_i) arriving at a_i, the last frame placed (o_c, T_c):
//     its time is T_c + (o_i − o_c) × [1, 1 + max_stretch], as early as
//     possible but no earlier than a_i + margin (it must be in the
//     RobotDaemon's queue before it is due: reactive stretch) and, when the
//     client stamps its send times, no earlier than its send time + the
//     playout delay (the worst delay seen in this sequence + margin:
//     proactive stretch, so the frames after a slow one get its headroom);
//   - a gap is never shortened below the recorded one: the timing only
//     stretches, by at most max_stretch of each gap, so of the whole;
//   - a frame that arrives after the latest time the bound allows is late:
//     it is counted and plays at a_i + margin (the sequence pauses, the gap
//     exceeds the bound once), so one slow frame does not make every later
//     frame late too;
//   - a frame with an offset at or before the last placed one (reordered, or
//     several commands at one instant) plays at T_c − (o_c − o): both gaps
//     around it stay within the bound; if that time is before its arrival it
//     is late (it plays late or is superseded, as in the fixed schedule).
//
//   - a thin buffer (issue 23, tenth session; thin_max_stretch, thin_lead):
//     a frame that arrives after the latest time max_stretch allows it, or
//     less than thin_lead before it (its buffer thin: on a FIFO link the
//     frames after it queue behind it), may take up to thin_max_stretch of
//     its gap, and plays no sooner than thin_lead after its arrival: the
//     buffer grows faster while it is thin, so a queue that outgrows
//     max_stretch a gap is followed. Such gaps are counted (thin_gaps); the
//     stated tolerance is then thin_max_stretch per gap, max_stretch after
//     every frame that came in time.
//
// max_stretch = 0 is the fixed schedule of the paper: frame i at start + o_i.
#pragma once

#include "robotalk/clock.h"

#include <cstddef>
#include <optional>

namespace robotalk {

struct PlaybackScheduleOptions {
  /// How much longer than recorded a gap between two frames may play: each
  /// gap is at most (1 + max_stretch) × its recorded length. 0: fixed.
  double max_stretch = 0.05;
  /// A frame plays no sooner than this after it arrived (the hand-over to
  /// the RobotDaemon and its wake-up).
  Duration margin = std::chrono::milliseconds(2);
  /// A thin buffer's bound (see above): a frame arriving after the time
  /// max_stretch allows its gap at most, or less than `thin_lead` before it,
  /// may take up to this fraction of it and plays at least `thin_lead` after
  /// its arrival (a zero lead: only a frame past the normal bound). At or
  /// below max_stretch: off.
  double thin_max_stretch = 0;
  Duration thin_lead{0};
};

class PlaybackSchedule {
 public:
  /// `start`: when offset 0 plays. `playout_delay`: play time − client send
  /// time to keep (mixed clocks; nullopt: the client sends no send times).
  PlaybackSchedule(TimePoint start, std::optional<Duration> playout_delay,
                   PlaybackScheduleOptions options = {});

  struct Placement {
    TimePoint at;       ///< when the frame plays
    bool late = false;  ///< it arrived after the bound allowed it to play
  };
  /// Places one frame: its offset, its arrival and its one-way delay
  /// (arrival − client send time, OneWayDelay; nullopt: unknown).
  Placement Place(Duration offset, TimePoint arrival, std::optional<Duration> delay = std::nullopt);

  /// How much later than start + offset the last frame placed plays.
  Duration stretch() const { return knot_at_ - (start_ + knot_offset_); }
  /// The largest (gap played / gap recorded) − 1 among the gaps within the
  /// bound (late frames' pauses are counted in late_frames instead).
  double max_gap_stretch() const { return max_gap_stretch_; }
  std::size_t late_frames() const { return late_; }
  /// Gaps that played longer than max_stretch allows (a thin buffer's, within thin_max_stretch).
  std::size_t thin_gaps() const { return thin_; }
  std::optional<Duration> playout_delay() const { return playout_delay_; }

 private:
  TimePoint start_;
  std::optional<Duration> playout_delay_;
  PlaybackScheduleOptions options_;
  Duration knot_offset_{0};  // the last frame placed in offset order
  TimePoint knot_at_;
  double max_gap_stretch_ = 0;
  std::size_t late_ = 0, thin_ = 0;
};

}  // namespace robotalk
