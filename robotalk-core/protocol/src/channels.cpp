#include "robotalk/channels.h"

#include <utility>

namespace robotalk {
namespace {

constexpr std::string_view kPrefix = "ROBOTALK/";

// The robot segment of "ROBOTALK/<robot>/<suffix>", suffix starting with '/'.
std::optional<std::string> RobotBefore(std::string_view channel, std::string_view suffix) {
  if (channel.size() <= kPrefix.size() + suffix.size()) return std::nullopt;
  if (!channel.starts_with(kPrefix) || !channel.ends_with(suffix)) return std::nullopt;
  const std::string_view robot =
      channel.substr(kPrefix.size(), channel.size() - kPrefix.size() - suffix.size());
  if (robot.empty() || robot.find('/') != std::string_view::npos) return std::nullopt;
  return std::string(robot);
}

std::optional<std::uint64_t> ParseHex64(std::string_view hex) {
  if (hex.size() != 16) return std::nullopt;
  std::uint64_t v = 0;
  for (char c : hex) {
    int digit = 0;
    if (c >= '0' && c <= '9') {
      digit = c - '0';
    } else if (c >= 'a' && c <= 'f') {
      digit = c - 'a' + 10;
    } else {
      return std::nullopt;
    }
    v = (v << 4) | static_cast<std::uint64_t>(digit);
  }
  return v;
}

}  // namespace

bool IsValidRobotName(std::string_view name) { return RobotNameProblem(name).empty(); }

std::string RobotNameProblem(std::string_view name) {
  if (name.empty()) return "a robot name is not empty";
  if (name.size() > kMaxRobotNameLength) {
    return "a robot name has at most " + std::to_string(kMaxRobotNameLength) + " characters (this one " +
           std::to_string(name.size()) + "): its channels must fit LCM's 63";
  }
  for (const char c : name) {
    const bool ok =
        (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' || c == '-';
    if (!ok) return "a robot name is letters, digits, '_' or '-'";
  }
  return "";
}

std::optional<std::string> RobotOfRequestChannel(std::string_view channel) {
  return RobotBefore(channel, "/REQUEST");
}
std::optional<std::string> RobotOfHelloChannel(std::string_view channel) {
  return RobotBefore(channel, "/HELLO");
}
std::optional<std::string> RobotOfConfigChannel(std::string_view channel) {
  return RobotBefore(channel, "/CONFIG");
}
std::optional<std::string> RobotOfStateChannel(std::string_view channel) {
  return RobotBefore(channel, "/STATE");
}

namespace {
// "ROBOTALK/<robot><infix><16 hex>".
std::optional<ReplyChannelParts> ParseClientChannel(std::string_view channel, std::string_view kReply) {
  if (channel.size() < 16) return std::nullopt;
  auto id = ParseHex64(channel.substr(channel.size() - 16));
  if (!id) return std::nullopt;
  auto robot = RobotBefore(channel.substr(0, channel.size() - 16), kReply);
  if (!robot) return std::nullopt;
  return ReplyChannelParts{*robot, static_cast<std::int64_t>(*id)};
}
}  // namespace

std::optional<ReplyChannelParts> ParseReplyChannel(std::string_view channel) {
  return ParseClientChannel(channel, "/REPLY/");
}
std::optional<ReplyChannelParts> ParseHelloAnswerChannel(std::string_view channel) {
  return ParseClientChannel(channel, "/HELLO/");
}

const char* ToString(ChannelKind kind) {
  switch (kind) {
    case ChannelKind::kAnnounce:
      return "ANNOUNCE";
    case ChannelKind::kHello:
      return "HELLO";
    case ChannelKind::kHelloAnswer:
      return "HELLO answer";
    case ChannelKind::kRequest:
      return "REQUEST";
    case ChannelKind::kReply:
      return "REPLY";
    case ChannelKind::kConfig:
      return "CONFIG";
    case ChannelKind::kState:
      return "STATE";
  }
  return "?";
}

std::optional<ChannelParts> ParseChannel(std::string_view channel) {
  if (channel == kAnnounceChannel) return ChannelParts{};
  using Robot = std::optional<std::string> (*)(std::string_view);
  for (const auto& [kind, parse] :
       {std::pair<ChannelKind, Robot>{ChannelKind::kRequest, &RobotOfRequestChannel},
        {ChannelKind::kHello, &RobotOfHelloChannel},
        {ChannelKind::kConfig, &RobotOfConfigChannel},
        {ChannelKind::kState, &RobotOfStateChannel}}) {
    if (auto robot = parse(channel)) return ChannelParts{kind, std::move(*robot), 0};
  }
  if (auto reply = ParseReplyChannel(channel))
    return ChannelParts{ChannelKind::kReply, reply->robot, reply->client_id};
  if (auto answer = ParseHelloAnswerChannel(channel))
    return ChannelParts{ChannelKind::kHelloAnswer, answer->robot, answer->client_id};
  return std::nullopt;
}

}  // namespace robotalk
