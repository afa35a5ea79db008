#include "playback_schedule.h"

#include <algorithm>
#include <cmath>

namespace robotalk {

PlaybackSchedule::PlaybackSchedule(TimePoint start, std::optional<Duration> playout_delay,
                                   PlaybackScheduleOptions options)
    : start_(start), playout_delay_(playout_delay), options_(options), knot_at_(start) {}

PlaybackSchedule::Placement PlaybackSchedule::Place(Duration offset, TimePoint arrival,
                                                    std::optional<Duration> delay) {
  const bool fixed = options_.max_stretch <= 0;
  const TimePoint ready = arrival + options_.margin;  // the earliest it can play
  if (offset <= knot_offset_) {
    // Reordered, or another command at an instant already placed: slope 1
    // back from the knot keeps both gaps around it within the bound.
    const TimePoint at = knot_at_ - (knot_offset_ - offset);
    const bool late = (fixed ? arrival : ready) > at;
    if (late) ++late_;
    return {at, late};
  }
  const Duration gap = offset - knot_offset_;
  const TimePoint earliest = knot_at_ + gap;
  const auto stretched = [&](double fraction) {
    return earliest + FromSeconds(ToSeconds(gap) * std::max(0.0, fraction));
  };
  TimePoint latest = stretched(options_.max_stretch);
  Placement p{earliest, false};
  if (fixed) {
    p.late = arrival > earliest;
  } else {
    TimePoint want = ready;
    // A thin buffer: this frame came after the latest time the normal bound
    // allows, or less than thin_lead before it. On a FIFO link the frames
    // after it queue behind it; this gap may take up to thin_max_stretch,
    // and the frame plays no sooner than thin_lead after it arrived.
    const bool thin = options_.thin_max_stretch > options_.max_stretch &&
                      arrival + std::max(options_.thin_lead, options_.margin) > latest;
    if (thin) {
      latest = stretched(options_.thin_max_stretch);
      want = std::max(want, arrival + options_.thin_lead);
    }
    if (delay && playout_delay_) {
      // The playout delay grows to the worst delay this sequence has shown
      // (+ margin), so the frames after a slow one get its headroom. (Both
      // are bounded by OneWayDelay: no overflow.)
      playout_delay_ = std::max(*playout_delay_, *delay + options_.margin);
      want = std::max(want, arrival - *delay + *playout_delay_);
    }
    p.at = std::clamp(want, earliest, latest);
    if (ready > latest) {  // past the bound: a pause, counted; later frames keep their headroom
      p.late = true;
      p.at = ready;
    } else if (p.at > earliest) {
      max_gap_stretch_ = std::max(max_gap_stretch_, ToSeconds(p.at - knot_at_) / ToSeconds(gap) - 1.0);
      if (p.at > stretched(options_.max_stretch)) ++thin_;
    }
  }
  if (p.late) ++late_;
  knot_offset_ = offset;
  knot_at_ = p.at;
  return p;
}

}  // namespace robotalk
