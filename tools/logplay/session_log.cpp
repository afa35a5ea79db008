#include "session_log.h"

#include "robotalk/channels.h"
#include "robotalk/protocol_codec.h"
#include "robotalk_msgs/announce_t.hpp"

#include <algorithm>
#include <limits>

namespace robotalk::logplay {

using robotalk_msgs::package_header_t;

ChannelName ParseChannel(const std::string& channel) {
  const std::string prefix = "ROBOTALK/";
  if (channel.rfind(prefix, 0) != 0) return {};
  const std::string rest = channel.substr(prefix.size());
  if (rest == "ANNOUNCE") return {"", "ANNOUNCE", ""};
  const auto slash = rest.find('/');
  if (slash == std::string::npos) return {};
  ChannelName n;
  n.robot = rest.substr(0, slash);
  std::string kind = rest.substr(slash + 1);
  if (const auto s2 = kind.find('/'); s2 != std::string::npos) {
    n.rest = kind.substr(s2 + 1);
    kind = kind.substr(0, s2);
  }
  if (kind != "REQUEST" && kind != "REPLY" && kind != "CONFIG" && kind != "STATE") return {};
  n.kind = kind;
  return n;
}

std::int64_t ParseClientId(const std::string& text) {
  try {
    std::size_t used = 0;
    const bool hex = text.size() == 16 || text.rfind("0x", 0) == 0;
    const unsigned long long v = std::stoull(text, &used, hex ? 16 : 10);
    if (used == text.size() && v != 0) return static_cast<std::int64_t>(v);
  } catch (const std::exception&) {
  }
  throw LogError("client id '" + text + "': expected 16 hex digits (as `info` prints) or a decimal id");
}

void SessionLog::Add(const std::string& channel, std::int64_t log_time_us,
                     std::span<const std::uint8_t> bytes) {
  ++events_;
  if (events_ == 1 || log_time_us < first_us_) first_us_ = log_time_us;
  last_us_ = std::max(last_us_, log_time_us);
  ChannelStats& s = channels_[channel];
  if (s.messages++ == 0) s.first_us = log_time_us;
  s.last_us = log_time_us;
  s.bytes += bytes.size();
  const ChannelName name = ParseChannel(channel);
  try {
    if (name.kind == "REQUEST") {
      AddRequest(name.robot, log_time_us, bytes);
    } else if (name.kind == "REPLY") {
      AddReply(log_time_us, bytes);
    } else if (name.kind == "ANNOUNCE") {
      AddAnnounce(bytes);
    } else if (name.kind == "STATE") {
      AddState(log_time_us, bytes);
    }
  } catch (const std::exception&) {
    ++s.undecodable;  // a log holds whatever was on the bus; count it, go on
  }
}

void SessionLog::AddRequest(const std::string& robot, std::int64_t log_time_us,
                            std::span<const std::uint8_t> bytes) {
  const robotalk_msgs::package_t p = DecodePackage(bytes);
  if (!CheckPackageHeader(p).empty()) throw LogError("inconsistent package");
  const package_header_t& h = p.header;
  LoggedClient& c = clients_[h.client_id];
  if (c.id == 0) {
    c.id = h.client_id;
    c.robot = robot;
    c.first_log_us = log_time_us;
  }
  c.last_log_us = log_time_us;
  const auto key = std::make_pair(h.client_id, h.sequence);
  if (package_send_us_.count(key)) {
    ++c.retransmissions;  // executed once by the server: kept once here
    return;
  }
  package_send_us_[key] = h.send_time_us;
  ++c.packages;
  if (h.panic) ++c.panics;
  if (h.payload_size == 0 && !h.panic) ++c.heartbeats;
  c.queries += static_cast<std::uint64_t>(p.num_queries);
  if (h.panic) {
    LoggedCommand marker;  // a panic is shown, never replayed (see MakeTimeline)
    marker.client_id = h.client_id;
    marker.robot = robot;
    marker.sequence = h.sequence;
    marker.mode = -1;
    marker.send_time_us = h.send_time_us;
    marker.log_time_us = log_time_us;
    commands_.push_back(std::move(marker));
    return;
  }
  if (p.num_commands > 0) c.modes.insert(h.mode);
  if (h.mode == package_header_t::MODE_PLAYBACK) playback_ids_.insert({h.client_id, h.playback_id});
  for (const auto& wire : p.commands) {
    LoggedCommand lc;
    lc.client_id = h.client_id;
    lc.robot = robot;
    lc.sequence = h.sequence;
    lc.mode = h.mode;
    lc.playback_id = h.playback_id;
    lc.command = FromWire(wire);
    lc.start_us = wire.start_time_us;
    lc.send_time_us = h.send_time_us;
    lc.log_time_us = log_time_us;
    const auto id_key = std::make_pair(h.client_id, wire.id);
    if (command_index_.count(id_key)) continue;
    command_index_[id_key] = commands_.size();
    commands_.push_back(std::move(lc));
  }
}

void SessionLog::AddReply(std::int64_t log_time_us, std::span<const std::uint8_t> bytes) {
  (void)log_time_us;
  const robotalk_msgs::reply_package_t p = DecodeReplyPackage(bytes);
  auto client = clients_.find(p.client_id);
  if (p.ack_sequence > 0 && client != clients_.end()) {
    auto sent = package_send_us_.find({p.client_id, p.ack_sequence});
    if (sent != package_send_us_.end() && sent->second != 0) {
      // One-way latency included: min over all acks is the best estimate.
      const std::int64_t offset = p.server_receive_us - sent->second;
      auto& o = client->second.clock_offset_us;
      if (!o || offset < *o) o = offset;
    }
  }
  for (const auto& wire : p.replies) {
    Reply r = FromWire(wire);
    if (client != clients_.end() && r.values.size() >= 2 && playback_ids_.count({p.client_id, r.id})) {
      // A playback sequence's delay reply (its id is the playback id): values[1] = the start.
      client->second.playback_start_us[r.id] = static_cast<std::int64_t>(r.values[1]);
    }
    auto it = command_index_.find({p.client_id, r.id});
    if (it != command_index_.end() && !commands_[it->second].reply)
      commands_[it->second].reply = std::move(r);
  }
}

void SessionLog::AddAnnounce(std::span<const std::uint8_t> bytes) {
  if (bytes.size() > (1u << 20)) throw LogError("oversized announce");
  robotalk_msgs::announce_t a;
  if (a.decode(bytes.data(), 0, static_cast<int>(bytes.size())) < 0) throw LogError("bad announce");
  for (const auto& r : a.robots) {
    LoggedRobot& lr = robots_[{a.server_id, r.name}];
    lr.name = r.name;
    lr.driver = r.driver;
    lr.server_id = a.server_id;
    lr.config_hash = static_cast<std::uint64_t>(r.config_hash);
    lr.total_dofs = r.total_dofs;
    lr.panic_seen = lr.panic_seen || r.panic;
  }
}

void SessionLog::AddState(std::int64_t log_time_us, std::span<const std::uint8_t> bytes) {
  const robotalk_msgs::robot_state_t s = DecodeRobotState(bytes);
  StateSample sample;
  sample.robot = s.robot;
  sample.log_time_us = log_time_us;
  sample.server_time_us = s.server_time_us;
  sample.panic = s.panic;
  sample.moving = s.moving;
  sample.base.assign(std::begin(s.base), std::end(s.base));
  sample.position = s.position;
  states_.push_back(std::move(sample));
}

std::vector<LoggedRobot> SessionLog::robots() const {
  std::vector<LoggedRobot> out;
  for (const auto& [key, r] : robots_) out.push_back(r);
  std::stable_sort(out.begin(), out.end(), [](const auto& a, const auto& b) { return a.name < b.name; });
  return out;
}

std::set<std::int64_t> SessionLog::servers() const {
  std::set<std::int64_t> out;
  for (const auto& [key, r] : robots_) out.insert(key.first);
  return out;
}

std::optional<std::int64_t> SessionLog::ServerTime(const LoggedCommand& c) const {
  const LoggedClient& client = clients_.at(c.client_id);
  if (c.mode == package_header_t::MODE_PLAYBACK) {
    auto it = client.playback_start_us.find(c.playback_id);
    if (it == client.playback_start_us.end()) return std::nullopt;
    return it->second + c.start_us;
  }
  if (c.start_us != 0) return c.start_us;
  if (client.clock_offset_us) return c.send_time_us + *client.clock_offset_us;
  return std::nullopt;
}

Timeline SessionLog::MakeTimeline(const Selection& selection) const {
  Timeline t;
  std::vector<const LoggedCommand*> chosen;
  for (const LoggedCommand& c : commands_) {
    if (selection.client_id && c.client_id != *selection.client_id) continue;
    if (!selection.robot.empty() && c.robot != selection.robot) continue;
    if (c.mode == -1) {
      t.skipped.push_back("a panic from client " + Hex64(static_cast<std::uint64_t>(c.client_id)) +
                          " (never replayed)");
      continue;
    }
    if (c.command.type == CommandType::kPanicReset) {
      t.skipped.push_back("PANIC_RESET " + std::to_string(c.command.id) + " from client " +
                          Hex64(static_cast<std::uint64_t>(c.client_id)) +
                          " (a reset is an operator's decision)");
      continue;
    }
    chosen.push_back(&c);
  }
  if (chosen.empty()) {
    std::string what = selection.client_id
                           ? "client " + Hex64(static_cast<std::uint64_t>(*selection.client_id))
                           : "robot '" + selection.robot + "'";
    throw LogError("the log holds no command from " + what + " (see `robotalk-logplay info`)");
  }
  std::vector<std::int64_t> times;
  bool all_server = true;
  for (const LoggedCommand* c : chosen) {
    const auto s = ServerTime(*c);
    all_server = all_server && s.has_value();
    times.push_back(s.value_or(0));
  }
  if (all_server) {
    t.clock = "server";
  } else {
    // No replies to join clocks: one client, one kind of time, or nothing.
    std::set<std::int64_t> clients;
    std::set<int> kinds;  // 0 absolute start, 1 playback offset, 2 send time
    for (const LoggedCommand* c : chosen) {
      clients.insert(c->client_id);
      kinds.insert(c->mode == package_header_t::MODE_PLAYBACK ? 1 : c->start_us != 0 ? 0 : 2);
    }
    if (clients.size() != 1 || kinds.size() != 1) {
      throw LogError(
          "cannot put these commands on one clock: the log has no replies to join the clients' clocks "
          "(record the REPLY channels too, or pick one client with --client)");
    }
    const int kind = *kinds.begin();
    t.clock = kind == 0 ? "start times" : kind == 1 ? "playback offsets" : "client send times";
    for (std::size_t i = 0; i < chosen.size(); ++i)
      times[i] = kind == 0 ? chosen[i]->start_us : kind == 1 ? chosen[i]->start_us : chosen[i]->send_time_us;
  }
  const std::int64_t t0 = *std::min_element(times.begin(), times.end());
  for (std::size_t i = 0; i < chosen.size(); ++i)
    t.frames.push_back({static_cast<double>(times[i] - t0) * 1e-6, times[i], chosen[i]});
  std::stable_sort(t.frames.begin(), t.frames.end(),
                   [](const TimedFrame& a, const TimedFrame& b) { return a.time_us < b.time_us; });
  return t;
}

}  // namespace robotalk::logplay
