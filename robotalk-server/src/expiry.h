// Command deadlines (issue 23): how late after its start time a command may
// still begin. A command past its limit is not executed: it answers
// INTERRUPTED "expired: arrived 0.84 s after its start, limit 0.1 s" and is
// counted (per session in its LinkHealth, per robot in SERVER_COUNTERS).
//
// Which limit a command carries (EffectiveMaxLate), decided once when it is
// admitted and kept in its QueuedItem:
//   - a command without a start time ("now"), a STOP and a query: never
//     (a STOP always runs; "now" cannot be late);
//   - its package's max_late when the client gave one (> 0, or never);
//   - else, for a servo command (JOINT_SETPOINT, JOINT_SPEED, JOINT_FORCE,
//     FRAME_SETPOINT, SETSPEED) the robot's --max-late default; a task
//     (GOTO) keeps "run late" (never) unless its package carries a limit.
//
// What the actuator does when its command expired (ExpiryHold): a set-point
// is not applied, so the actuator holds the last set-point that ran (an
// interpolated trajectory holds after its last known waypoint, decelerating
// within its limit: docs/specification.md, Trajectories). A speed or force
// (JOINT_SPEED, JOINT_FORCE, SETSPEED: the commands that move on until
// replaced) was meant to end the previous speed at its start time, so that
// actuator is stopped and holds (Driver::StopOnly), as the watchdog stops a
// vanished client's: the previous speed does not run on past its time.
// A GOTO with a limit that expired never starts; a GOTO already running is
// not affected.
//
// Pure functions; thread-safe.
#pragma once

#include "robotalk/clock.h"
#include "robotalk/command.h"

#include <optional>
#include <string>
#include <vector>

namespace robotalk {

/// A limit that never expires (QueuedItem::max_late's default).
inline constexpr Duration kNeverExpires = Duration::max();

/// The limit a command of `type` carries. `requested`: its package's
/// max_late (Request::max_late: 0 = the robot's default, Duration::max() =
/// never, else > 0); `robot_default`: the robot's --max-late for servo
/// commands (kNeverExpires for none). `has_start_time` false: never.
Duration EffectiveMaxLate(CommandType type, bool has_start_time, Duration requested, Duration robot_default);

/// The INTERRUPTED text of a command that began `lateness` after its start
/// time when its limit is `max_late`, or nullopt when it may run
/// (lateness <= max_late). `arrival_lateness`: how long after its start
/// time it reached the server (<= 0: in time, and it was the server that
/// was late); nullopt: `lateness` is its arrival's (a waypoint judged when
/// it arrives). Examples: "expired: arrived 0.84 s after its start, limit
/// 0.1 s"; "expired: began 0.2 s after its start (it arrived in time),
/// limit 0.1 s". Allocates only when it refuses.
std::optional<std::string> ExpiryRefusal(Duration lateness, Duration max_late,
                                         std::optional<Duration> arrival_lateness = std::nullopt);

/// True for a reply ExpiryRefusal's text produced (the sessions count them).
bool IsExpiryReply(const Reply& reply);

/// What holds the actuator of an expired command: the joints (a JOINT_SPEED
/// or JOINT_FORCE target) or the base (SETSPEED) to stop; nothing for a
/// set-point or a task. See the header comment.
struct ExpiryHold {
  int joint = -1;     ///< a joint index to stop, or -1
  bool base = false;  ///< stop the base
  bool any() const { return joint >= 0 || base; }
};
ExpiryHold HoldAfterExpiry(CommandType type, int target);

}  // namespace robotalk
