// The LCM channel names of the RoboTalk protocol (docs/protocol.md, Channels),
// built AND parsed here, in one place for the server, the client and tools.
//
//   ROBOTALK/ANNOUNCE                       every server's robots, once a second
//   ROBOTALK/<robot>/HELLO                  client -> server: open a session
//   ROBOTALK/<robot>/HELLO/<client id hex>  server -> one client: the answer
//   ROBOTALK/<robot>/REQUEST                client -> server packages
//   ROBOTALK/<robot>/REPLY/<client id hex>  server -> one client
//   ROBOTALK/<robot>/CONFIG                 the robot's description
//   ROBOTALK/<robot>/STATE                  broadcast state samples
//
// A robot name is one channel segment: non-empty, no '/'. The parsers return
// nullopt for any other channel (they never throw). Thread-safe (pure).
#pragma once

#include "robotalk/clock.h"

#include <chrono>
#include <cinttypes>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <optional>
#include <string>
#include <string_view>

namespace robotalk {

/// Every server announces its robots here once a second (kAnnouncePeriod).
inline constexpr const char* kAnnounceChannel = "ROBOTALK/ANNOUNCE";
/// How often a server announces (ServerOptions::announce_period's default);
/// clients' waits for an announcement are counted in it.
inline constexpr Duration kAnnouncePeriod = std::chrono::seconds(1);
/// One announce period and half of one for the network, scheduling and the
/// clock sync (1.5 s): every live server is heard within it. `robotalk
/// robots` listens this long by default; robotalk-web's --robot-timeout is
/// at least this; the CLI's AnnounceWatch refuses a signed announcement
/// older than this on arrival.
inline constexpr Duration kAnnounceHeardWithin = kAnnouncePeriod * 3 / 2;
/// Subscription regex (LCM: whole-name match) for the REQUEST channel of every robot.
inline constexpr const char* kAnyRequestChannelRegex = "ROBOTALK/[^/]+/REQUEST";
/// Subscription regex for the HELLO channel of every robot.
inline constexpr const char* kAnyHelloChannelRegex = "ROBOTALK/[^/]+/HELLO";

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
inline std::string HelloChannel(const std::string& robot) { return "ROBOTALK/" + robot + "/HELLO"; }
inline std::string HelloAnswerChannel(const std::string& robot, std::int64_t client_id) {
  return "ROBOTALK/" + robot + "/HELLO/" + Hex64(static_cast<std::uint64_t>(client_id));
}
inline std::string ConfigChannel(const std::string& robot) { return "ROBOTALK/" + robot + "/CONFIG"; }
inline std::string StateChannel(const std::string& robot) { return "ROBOTALK/" + robot + "/STATE"; }

/// The longest robot name: LCM refuses a channel name over 63 characters
/// (LCM_MAX_CHANNEL_NAME_LENGTH), and the longest channel,
/// ROBOTALK/<robot>/REPLY/<16 hex digits>, leaves 31 for the name.
inline constexpr std::size_t kMaxRobotNameLength = 31;
/// True when `name` may name a served robot: 1 to kMaxRobotNameLength
/// characters, only [A-Za-z0-9_-] (the server's --robot and AddRobot,
/// RobotClient::Connect, access lists and known-servers files all check this
/// one rule).
bool IsValidRobotName(std::string_view name);
/// What is wrong with `name` as a robot name ("" when it is valid), for errors.
std::string RobotNameProblem(std::string_view name);

/// The robot of "ROBOTALK/<robot>/REQUEST"; nullopt for any other channel.
std::optional<std::string> RobotOfRequestChannel(std::string_view channel);
/// The robot of "ROBOTALK/<robot>/HELLO".
std::optional<std::string> RobotOfHelloChannel(std::string_view channel);
/// The robot of "ROBOTALK/<robot>/CONFIG".
std::optional<std::string> RobotOfConfigChannel(std::string_view channel);
/// The robot of "ROBOTALK/<robot>/STATE".
std::optional<std::string> RobotOfStateChannel(std::string_view channel);

struct ReplyChannelParts {
  std::string robot;
  std::int64_t client_id = 0;
  bool operator==(const ReplyChannelParts&) const = default;
};
/// Robot and client id of "ROBOTALK/<robot>/REPLY/<16 lowercase hex digits>"
/// (exactly what ReplyChannel() writes).
std::optional<ReplyChannelParts> ParseReplyChannel(std::string_view channel);
/// Robot and client id of "ROBOTALK/<robot>/HELLO/<16 lowercase hex digits>".
std::optional<ReplyChannelParts> ParseHelloAnswerChannel(std::string_view channel);

/// What a channel of the list above carries.
enum class ChannelKind { kAnnounce, kHello, kHelloAnswer, kRequest, kReply, kConfig, kState };
/// "ANNOUNCE", "HELLO", "HELLO answer", "REQUEST", "REPLY", "CONFIG", "STATE".
const char* ToString(ChannelKind kind);

struct ChannelParts {
  ChannelKind kind = ChannelKind::kAnnounce;
  std::string robot;           ///< empty for kAnnounce
  std::int64_t client_id = 0;  ///< kHelloAnswer and kReply; 0 otherwise
  bool operator==(const ChannelParts&) const = default;
};
/// Any channel of the list above, as the functions above parse it (for
/// readers of every channel: logs, recorders); nullopt for any other.
std::optional<ChannelParts> ParseChannel(std::string_view channel);

}  // namespace robotalk
