#include "trajectory_frames.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace robotalk::client {
namespace {

std::string Seconds(Duration d) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g s", ToSeconds(d));
  return buf;
}

}  // namespace

std::vector<TimedCommand> TrajectoryFrames(const RobotModel& model, CommandType type,
                                           const std::string& target,
                                           const std::vector<TrajectoryPoint>& points, const char* call) {
  const std::string what = std::string("RobotClient::") + call + ": " +
                           (type == CommandType::kFrameSetPoint ? "frame '" : "joint '") + target + "': ";
  if (points.empty()) throw ClientError(what + "no points");
  std::vector<TimedCommand> frames;
  frames.reserve(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    const TrajectoryPoint& p = points[i];
    const std::string at = what + "point " + std::to_string(i) + ": ";
    if (p.time_from_start < Duration(0)) {
      throw ClientError(at + "time_from_start " + Seconds(p.time_from_start) + " is negative");
    }
    if (i > 0 && p.time_from_start <= points[i - 1].time_from_start) {
      throw ClientError(at + "time_from_start " + Seconds(p.time_from_start) + " is not after point " +
                        std::to_string(i - 1) + "'s (" + Seconds(points[i - 1].time_from_start) +
                        "): times must increase");
    }
    Command c{.type = type, .target = target, .values = p.positions};
    c.velocities = p.velocities;
    c.accelerations = p.accelerations;
    if (auto refusal = CheckCommand(model, c)) {
      throw ClientError(
          at + refusal->message +
          (refusal->signal == Signal::kError ? "" : " (" + std::string(ToString(refusal->signal)) + ")"));
    }
    frames.push_back({p.time_from_start, std::move(c), std::nullopt});
  }
  return frames;
}

SequenceOptions TrajectorySequence(const TrajectoryOptions& options, const std::vector<TimedCommand>& frames,
                                   const char* call) {
  if (options.mode == CommandMode::kDirect) {
    throw ClientError(
        std::string("RobotClient::") + call +
        ": a trajectory needs mode delay or playback (a direct command has no start time, so it "
        "is a step, not a waypoint)");
  }
  // An encoded command: id, type, start, target (length + NUL), three counts,
  // 8 bytes a number; the package header and MAC fit in the margin.
  std::size_t largest = 0;
  for (const TimedCommand& f : frames) {
    const Command& c = f.command;
    largest = std::max(largest, 8 + 1 + 8 + 5 + c.target.size() + 6 +
                                    8 * (c.values.size() + c.velocities.size() + c.accelerations.size()));
  }
  constexpr std::size_t kPackageBudget = 48 * 1024;
  SequenceOptions s;
  s.mode = options.mode;
  s.delay = options.delay;
  s.start = options.start;
  s.paced = false;
  s.batch = std::clamp<std::size_t>(kPackageBudget / std::max<std::size_t>(largest, 1), 1, 200);
  s.interpolation = options.interpolation;
  return s;
}

}  // namespace robotalk::client
