// What the RobotDaemon's planners (TrajectoryTracker, SpeedRamp) share to
// answer the commands they plan: a reply at a time, and the texts they put
// in it. Pure; allocates only the strings it returns.
#pragma once

#include "robotalk/clock.h"
#include "robotalk/command.h"

#include <cstdio>
#include <string>
#include <utility>
#include <vector>

namespace robotalk::planner_answers {

/// "0.25 s"
inline std::string Seconds(Duration d) {
  char text[32];
  std::snprintf(text, sizeof text, "%.3g s", ToSeconds(d));
  return text;
}

inline Reply MakeAnswer(CommandId id, Signal signal, std::string message, TimePoint exec, Duration lateness) {
  Reply r;
  r.id = id;
  r.signal = signal;
  r.message = std::move(message);
  r.exec_time = exec;
  r.lateness = lateness;
  return r;
}

/// Commands a planner holds per client (client id, count): what a client has
/// waiting on the robot beside its queue (RobotDaemon::queued, --max-queue).
using HeldCounts = std::vector<std::pair<std::int64_t, std::size_t>>;

/// One more held for `client` (a linear search: few clients hold any).
inline void CountHeld(HeldCounts& counts, std::int64_t client) {
  for (auto& [id, n] : counts) {
    if (id == client) {
      ++n;
      return;
    }
  }
  counts.emplace_back(client, 1);
}

/// `note` and `more`, joined with "; ".
inline std::string Append(const std::string& note, const std::string& more) {
  return note.empty() ? more : note + "; " + more;
}

}  // namespace robotalk::planner_answers
