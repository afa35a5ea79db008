// Small text helpers of RobotSessions' replies (robot_sessions*.cpp only).
#pragma once

#include "robotalk/channels.h"
#include "robotalk/clock.h"
#include "robotalk/command.h"

#include <cstdint>
#include <cstdio>
#include <string>

namespace robotalk::sessions_text {

inline Reply MakeReply(CommandId id, Signal signal, std::string message, TimePoint now) {
  Reply r;
  r.id = id;
  r.signal = signal;
  r.message = std::move(message);
  r.exec_time = now;
  return r;
}

inline std::string Seconds(Duration d) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g s", ToSeconds(d));
  return buf;
}

inline std::string Client(std::int64_t id) { return "client " + Hex64(static_cast<std::uint64_t>(id)); }

inline std::string KiB(std::size_t bytes) { return std::to_string(bytes / 1024) + " KiB"; }

}  // namespace robotalk::sessions_text
