// The pure part of RobotClient::RunSequence (paper §V, Table I): which frames
// travel together and when each package leaves, and what start time each
// frame carries in each mode. No I/O, no clock reads: RunSequence walks the
// plan on the client's Clock, and the tests walk it on a ManualClock.
//
//   direct:   one frame per package, each at its offset when paced (the
//             caller then blocks for its reply), start time Now()
//   delay:    start time At(server_start + offset)
//   playback: start time After(offset); the server chooses the delay
//   paced:    one frame per package at its offset; not paced: packages of
//             `batch` frames, all due at once
//   interpolation: each package carries one (a frame's own, else the
//             sequence's); frames of different interpolations never share a
//             package, a playback sequence has one, and a direct sequence
//             only step (its frames have no start time)
//
// Thread safety: value types and pure functions.
#pragma once

#include "robotalk/robot_client.h"

#include <cstddef>
#include <optional>
#include <vector>

namespace robotalk::client {

/// One package of a sequence.
struct PlannedSend {
  Duration send_at{0};                                 ///< when it leaves, after the sequence's first send
  std::vector<std::size_t> frames;                     ///< indices into the caller's frames, in offset order
  Interpolation interpolation = Interpolation::kStep;  ///< the package's
};

struct SequencePlan {
  std::vector<PlannedSend> sends;  ///< in the order they leave (send_at never decreases)
  Duration duration{0};            ///< the largest frame offset
};

/// Plans `frames` in `options`. Frames leave in offset order (equal offsets
/// in the order given). Throws ClientError for a negative offset, an
/// interpolation other than step in direct mode, and two interpolations in
/// one playback sequence.
SequencePlan PlanSequence(const std::vector<TimedCommand>& frames, const SequenceOptions& options);

/// The start time a frame at `offset` carries in `mode`; `server_start` is the
/// server time of offset 0 (delay mode only).
StartTime FrameStart(CommandMode mode, Duration offset, TimePoint server_start);

/// Walks a plan on a clock whose sequence started at `t0`.
class SequencePacer {
 public:
  SequencePacer(const SequencePlan& plan, TimePoint t0) : plan_(&plan), t0_(t0) {}
  /// The next package due at `now` (each returned once, in order), or nullopt.
  const PlannedSend* NextDue(TimePoint now);
  /// When the next package falls due; nullopt when all have been taken.
  std::optional<TimePoint> NextDeadline() const;
  bool done() const { return next_ >= plan_->sends.size(); }

 private:
  const SequencePlan* plan_;
  TimePoint t0_;
  std::size_t next_ = 0;
};

}  // namespace robotalk::client
