#include "sequence_plan.h"

#include <algorithm>
#include <numeric>

namespace robotalk::client {

SequencePlan PlanSequence(const std::vector<TimedCommand>& frames, const SequenceOptions& options) {
  for (std::size_t i = 0; i < frames.size(); ++i) {
    if (frames[i].offset < Duration(0)) {
      throw ClientError("RobotClient::RunSequence: frame " + std::to_string(i) + " has a negative offset (" +
                        std::to_string(ToSeconds(frames[i].offset)) + " s)");
    }
  }
  const auto interpolation = [&](std::size_t i) {
    return frames[i].interpolation.value_or(options.interpolation);
  };
  for (std::size_t i = 0; i < frames.size(); ++i) {
    const Interpolation in = interpolation(i);
    if (options.mode == CommandMode::kDirect && in != Interpolation::kStep) {
      throw ClientError("RobotClient::RunSequence: frame " + std::to_string(i) + ": interpolation " +
                        InterpolationName(in) +
                        " needs mode delay or playback (a direct frame has no start time, so it is a step)");
    }
    if (options.mode == CommandMode::kPlayback && in != interpolation(0)) {
      throw ClientError("RobotClient::RunSequence: a playback sequence has one interpolation: frame " +
                        std::to_string(i) + " is " + InterpolationName(in) + ", frame 0 " +
                        InterpolationName(interpolation(0)));
    }
  }
  SequencePlan plan;
  if (frames.empty()) return plan;
  std::vector<std::size_t> order(frames.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return frames[a].offset < frames[b].offset; });
  plan.duration = frames[order.back()].offset;
  // Direct mode is a handshake: one frame per package whatever the batch.
  const bool one_each = options.paced || options.mode == CommandMode::kDirect;
  const std::size_t batch = one_each ? 1 : std::max<std::size_t>(options.batch, 1);
  for (std::size_t k = 0; k < order.size();) {
    PlannedSend send;
    send.send_at = options.paced ? frames[order[k]].offset : Duration(0);
    send.interpolation = interpolation(order[k]);
    for (; k < order.size() && send.frames.size() < batch && interpolation(order[k]) == send.interpolation;
         ++k)
      send.frames.push_back(order[k]);
    plan.sends.push_back(std::move(send));
  }
  return plan;
}

StartTime FrameStart(CommandMode mode, Duration offset, TimePoint server_start) {
  switch (mode) {
    case CommandMode::kDirect:
      return StartTime::Now();
    case CommandMode::kDelay:
      return StartTime::At(server_start + offset);
    case CommandMode::kPlayback:
      return StartTime::After(offset);
  }
  return StartTime::Now();
}

const PlannedSend* SequencePacer::NextDue(TimePoint now) {
  if (done() || t0_ + plan_->sends[next_].send_at > now) return nullptr;
  return &plan_->sends[next_++];
}

std::optional<TimePoint> SequencePacer::NextDeadline() const {
  if (done()) return std::nullopt;
  return t0_ + plan_->sends[next_].send_at;
}

}  // namespace robotalk::client
