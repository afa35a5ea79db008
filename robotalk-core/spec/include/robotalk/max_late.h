// A command's deadline: how late after its start time it may still begin
// (a package's max_late; docs/server.md, Deadlines). Beside the
// Request (request.h) and the client's options (robot_client.h).
#pragma once

#include "robotalk/clock.h"

namespace robotalk {

/// The robot's default (its --max-late; a GOTO runs late).
inline constexpr Duration kMaxLateServerDefault{0};
/// Never expires: runs however late (protocol 3's behaviour).
inline constexpr Duration kMaxLateNever = Duration::max();

}  // namespace robotalk
