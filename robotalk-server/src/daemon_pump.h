// The one pump from a RobotDaemon to its RobotSessions (issue 20: it was
// written twice, in ServerDaemon::Drain and RunSimulation).
#pragma once

#include "robot_daemon.h"
#include "robot_sessions.h"

#include <vector>

namespace robotalk {

/// Takes what `daemon` produced since the last call into `output` (its state
/// samples and audit lines stay there for the caller), files its replies and
/// ownership changes in `sessions` (RobotSessions::File: log lines go to its
/// TakeLog()), and replaces `to_send` with one batch per client to send.
/// `wait` as RobotDaemon::TakeOutput. Returns whether the RobotDaemon had
/// output. Thread: the sessions' (the ServerDaemon's, or the simulation's).
inline bool PumpOutput(RobotDaemon& daemon, RobotSessions& sessions, DaemonOutput& output,
                       std::vector<ReplyBatch>& to_send, bool wait = true) {
  const bool had = daemon.TakeOutput(output, wait);
  to_send.clear();
  sessions.File(output, to_send);  // also what the sessions made outside Handle (a panic's flushed items)
  return had;
}

}  // namespace robotalk
