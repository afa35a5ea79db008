// The traffic layout: which LCM URL ("lane") carries which RoboTalk channel,
// so that a process receives only what concerns it (docs/protocol.md,
// Channels). All the lane rules live here; RoutedLcmTransport
// (routed_lcm_transport.h) applies them.
//
// From a main URL udpm://G:P?opts the split layout uses 66 lanes, all on the
// group G with the same options, on distinct ports:
//   lane 0       udpm://G:P?opts        ROBOTALK/ANNOUNCE, <robot>/CONFIG,
//                                       <robot>/STATE, every other channel
//   lane 1       udpm://G:(P+1)?opts    ROBOTALK/<robot>/REQUEST and
//                                       ROBOTALK/<robot>/HELLO (servers listen)
//   lane 2+b     udpm://G:(P+2+b)?opts  ROBOTALK/<robot>/REPLY/<client hex> and
//                                       ROBOTALK/<robot>/HELLO/<client hex>,
//                                       b = (uint64)client_id % 64
// Ports, not groups: on Linux a socket bound to INADDR_ANY:port receives the
// datagrams of every group any socket of the host joined on that port
// (IP_MULTICAST_ALL), so lanes on one port would not separate anything.
//
// The single layout puts every channel on the main URL (RoboTalk before the
// split; what lcm-logger and lcm-spy see whole). A RoboTalk URL selects it
// with the option `traffic=single` (`traffic=split` is the default for
// udpm://); memq:// and file:// are always single. The option is RoboTalk's,
// stripped before the URL reaches LCM.
//
// Pure functions, no I/O; thread-safe. Errors throw TransportError naming
// the URL and the bad part.
#pragma once

#include "robotalk/transport.h"  // TrafficLayout

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

namespace robotalk {

/// Reply lanes of the split layout (a client's: client_id % kReplyLanes).
inline constexpr int kReplyLanes = 64;
/// Lanes of the split layout: main, request, then the reply lanes.
inline constexpr int kLaneCount = 2 + kReplyLanes;
inline constexpr int kMainLane = 0;
inline constexpr int kRequestLane = 1;

/// The lane of client `client_id`'s replies and hello answers: 2 + id % 64.
int ReplyLaneOf(std::int64_t client_id);

/// The lane that carries `channel` in the split layout (kMainLane for any
/// channel that is not a RoboTalk request, hello, reply or hello answer).
int LaneOfChannel(std::string_view channel);

/// The one lane every channel matching `channel_regex` (LCM: POSIX extended,
/// whole-name match) travels on, when the rules can tell: the patterns
/// kAnyRequestChannelRegex and kAnyHelloChannelRegex, and a regex that read
/// literally is a request, hello, reply or hello-answer channel (its robot
/// segment may be a pattern without '/' or '|', e.g. ROBOTALK/.*/REPLY/<hex>).
/// nullopt for any other regex: its channels may be on any lane.
std::optional<int> LaneOfSubscription(std::string_view channel_regex);

/// A RoboTalk URL split into the LCM URL (traffic= option removed) and the
/// layout it selects.
struct TrafficUrl {
  std::string lcm_url;  ///< what LCM is given (lane 0 of the split layout)
  TrafficLayout layout = TrafficLayout::kSingle;
  bool operator==(const TrafficUrl&) const = default;
};

/// Parses the `traffic=` option of `url` ("" is not accepted: resolve LCM's
/// default URL first). udpm:// defaults to split; other schemes are single.
/// Throws TransportError for a traffic= value other than single|split, for
/// traffic=split on a scheme other than udpm://, and, for split, for a udpm
/// URL without a valid group:port (no port = LCM's 7667) or whose lanes
/// would pass port 65535.
TrafficUrl ParseTrafficUrl(const std::string& url);

/// The LCM URL of lane `lane` (0..kLaneCount-1) of split main URL `lcm_url`
/// (udpm://G:P?opts, traffic= already removed): udpm://G:(P+lane)?opts.
/// Throws TransportError for a URL that is not udpm://G:P or a bad lane.
std::string LaneUrl(const std::string& lcm_url, int lane);

}  // namespace robotalk
