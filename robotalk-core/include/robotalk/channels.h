// The LCM channel names of the RoboTalk protocol (docs/protocol.md, Channels),
// in one place for the server, the client and tools.
#pragma once

#include <cinttypes>
#include <cstdint>
#include <cstdio>
#include <string>

namespace robotalk {

/// Every server announces its robots here once a second.
inline constexpr const char* kAnnounceChannel = "ROBOTALK/ANNOUNCE";

/// 16 lowercase hex digits: how client ids and configuration hashes are written.
inline std::string Hex64(std::uint64_t v) {
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016" PRIx64, v);
  return buf;
}

inline std::string RequestChannel(const std::string& robot) { return "ROBOTALK/" + robot + "/REQUEST"; }
inline std::string ReplyChannel(const std::string& robot, std::int64_t client_id) {
  return "ROBOTALK/" + robot + "/REPLY/" + Hex64(static_cast<std::uint64_t>(client_id));
}
inline std::string ConfigChannel(const std::string& robot) { return "ROBOTALK/" + robot + "/CONFIG"; }
inline std::string StateChannel(const std::string& robot) { return "ROBOTALK/" + robot + "/STATE"; }

}  // namespace robotalk
