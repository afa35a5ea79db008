#include "robotalk/traffic_layout.h"

#include "robotalk/channels.h"
#include "robotalk/error.h"

#include <charconv>
#include <vector>

namespace robotalk {
namespace {

constexpr std::string_view kUdpm = "udpm://";
constexpr int kLcmDefaultPort = 7667;  // LCM's port for a udpm URL that gives none

// The parts of "udpm://host:port?options" (options without the '?').
struct UdpmParts {
  std::string host;
  int port = 0;
  std::string options;
};

UdpmParts SplitUdpm(const std::string& url) {
  if (!url.starts_with(kUdpm)) throw TransportError("traffic layout: '" + url + "' is not a udpm:// URL");
  const std::size_t query = url.find('?');
  const std::string address =
      url.substr(kUdpm.size(), query == std::string::npos ? query : query - kUdpm.size());
  const std::size_t colon = address.rfind(':');
  if (colon == std::string::npos && !address.empty()) {
    return {address, kLcmDefaultPort, query == std::string::npos ? "" : url.substr(query + 1)};
  }
  int port = 0;
  const char* first = address.data() + (colon == std::string::npos ? 0 : colon + 1);
  const char* last = address.data() + address.size();
  const auto [end, ec] = std::from_chars(first, last, port);
  if (colon == std::string::npos || colon == 0 || ec != std::errc() || end != last || first == last ||
      port <= 0 || port > 65535) {
    throw TransportError("traffic layout: '" + url +
                         "' does not name a group and a port (udpm://GROUP:PORT)");
  }
  return {address.substr(0, colon), port, query == std::string::npos ? "" : url.substr(query + 1)};
}

std::vector<std::string> SplitOptions(const std::string& options) {
  std::vector<std::string> out;
  std::size_t pos = 0;
  while (pos <= options.size() && !options.empty()) {
    const std::size_t amp = options.find('&', pos);
    const std::string item = options.substr(pos, amp == std::string::npos ? amp : amp - pos);
    if (!item.empty()) out.push_back(item);
    if (amp == std::string::npos) break;
    pos = amp + 1;
  }
  return out;
}

// A literal channel name, or a robot pattern between fixed parts: no '|'
// (an alternative could reach any lane) and no escapes.
bool ReadsLiterally(std::string_view regex) {
  return regex.find('|') == std::string_view::npos && regex.find('\\') == std::string_view::npos;
}

}  // namespace

int ReplyLaneOf(std::int64_t client_id) {
  return 2 + static_cast<int>(static_cast<std::uint64_t>(client_id) % kReplyLanes);
}

int LaneOfChannel(std::string_view channel) {
  if (!channel.starts_with("ROBOTALK/")) return kMainLane;
  if (RobotOfRequestChannel(channel) || RobotOfHelloChannel(channel)) return kRequestLane;
  if (auto r = ParseReplyChannel(channel)) return ReplyLaneOf(r->client_id);
  if (auto h = ParseHelloAnswerChannel(channel)) return ReplyLaneOf(h->client_id);
  return kMainLane;
}

std::optional<int> LaneOfSubscription(std::string_view channel_regex) {
  if (channel_regex == kAnyRequestChannelRegex || channel_regex == kAnyHelloChannelRegex) return kRequestLane;
  if (!ReadsLiterally(channel_regex)) return std::nullopt;
  const int lane = LaneOfChannel(channel_regex);
  if (lane != kMainLane) return lane;
  // A literal name of a main-lane channel: only a plain name (no pattern
  // character) is known to stay on the main lane.
  if (channel_regex.find_first_of(".[]()*+?{}^$") == std::string_view::npos) return kMainLane;
  return std::nullopt;
}

TrafficUrl ParseTrafficUrl(const std::string& url) {
  if (url.empty()) throw TransportError("traffic layout: empty URL (resolve LCM's default URL first)");
  const std::size_t query = url.find('?');
  std::string kept;
  std::optional<std::string> traffic;
  if (query != std::string::npos) {
    for (const std::string& item : SplitOptions(url.substr(query + 1))) {
      if (item.starts_with("traffic=")) {
        traffic = item.substr(8);
        continue;
      }
      kept += (kept.empty() ? "" : "&") + item;
    }
  }
  TrafficUrl out;
  out.lcm_url = url.substr(0, query) + (kept.empty() ? "" : "?" + kept);
  const bool udpm = url.starts_with(kUdpm);
  if (traffic && *traffic != "single" && *traffic != "split") {
    throw TransportError("traffic layout: '" + url + "': traffic=" + *traffic +
                         " is neither traffic=single nor traffic=split");
  }
  if (traffic == "split" && !udpm) {
    throw TransportError("traffic layout: '" + url + "': traffic=split needs a udpm:// URL");
  }
  out.layout = (udpm && traffic != "single") ? TrafficLayout::kSplit : TrafficLayout::kSingle;
  if (out.layout == TrafficLayout::kSplit) {
    const UdpmParts parts = SplitUdpm(out.lcm_url);
    if (parts.port + kLaneCount - 1 > 65535) {
      throw TransportError("traffic layout: '" + url + "': the split layout uses ports " +
                           std::to_string(parts.port) + ".." + std::to_string(parts.port + kLaneCount - 1) +
                           ", past 65535; choose a lower port or traffic=single");
    }
  }
  return out;
}

std::string LaneUrl(const std::string& lcm_url, int lane) {
  if (lane < 0 || lane >= kLaneCount) {
    throw TransportError("traffic layout: lane " + std::to_string(lane) + " of '" + lcm_url +
                         "' is not in 0.." + std::to_string(kLaneCount - 1));
  }
  const UdpmParts parts = SplitUdpm(lcm_url);
  if (parts.port + lane > 65535) {
    throw TransportError("traffic layout: lane " + std::to_string(lane) + " of '" + lcm_url +
                         "' would pass port 65535");
  }
  std::string url = std::string(kUdpm) + parts.host + ":" + std::to_string(parts.port + lane);
  return parts.options.empty() ? url : url + "?" + parts.options;
}

}  // namespace robotalk
