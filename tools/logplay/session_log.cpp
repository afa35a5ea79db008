#include "session_log.h"

#include "robotalk/channels.h"
#include "robotalk/log_writer.h"
#include "robotalk/request.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string_view>

namespace robotalk::logplay {
namespace {

// The start time as its package carried it (0 = now; absolute micros; or a
// playback offset in micros).
std::int64_t StartMicros(const StartTime& s) {
  if (s.is_now()) return 0;
  return s.is_at() ? ToWireMicros(*s.time()) : ToWireMicros(*s.offset());
}

// Every time kept from a log is a wire time, |t| <= kMaxWireMicros (the
// decoders refuse larger ones; Add() and AddReply() refuse the rest), so the
// timeline's sums and differences of at most six of them cannot overflow.
static_assert(kMaxWireMicros <= std::numeric_limits<std::int64_t>::max() / 6);

// A log entry that is refused whole, with what was wrong in it.
class BadEntry : public LogError {
 public:
  using LogError::LogError;
};

std::string OutOfRange(const std::string& field, const std::string& value) {
  return field + " = " + value + " is not a time in us (finite, |t| <= " + std::to_string(kMaxWireMicros) +
         ")";
}

// A time carried as a double (a reply's values): the integer micros, or
// BadEntry naming `field` for NaN, an infinity or a value out of range.
std::int64_t MicrosFromDouble(double v, const std::string& field) {
  if (!std::isfinite(v) || std::abs(v) >= static_cast<double>(kMaxWireMicros)) {
    char text[32];
    std::snprintf(text, sizeof text, "%.17g", v);
    throw BadEntry(OutOfRange(field, text));
  }
  return static_cast<std::int64_t>(v);
}

}  // namespace

std::string Printable(std::string_view text) { return EscapeControls(text, /*ascii_only=*/true); }

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

void SessionLog::Add(const std::string& logged_channel, std::int64_t log_time_us,
                     std::span<const std::uint8_t> bytes) {
  const std::string channel = Printable(logged_channel);
  const std::uint64_t event = events_++;  // LCM's numbering: from 0
  ChannelStats& s = channels_[channel];
  ++s.messages;
  s.bytes += bytes.size();
  const auto reject = [&](const std::string& why) {
    ++s.undecodable;
    if (rejections_++ < kKeptRejections)
      rejected_.push_back("event " + std::to_string(event) + " on " + channel + ": " + why);
  };
  if (log_time_us > kMaxWireMicros || log_time_us < -kMaxWireMicros) {
    reject(OutOfRange("log timestamp", std::to_string(log_time_us)));
    return;
  }
  if (timed_events_++ == 0 || log_time_us < first_us_) first_us_ = log_time_us;
  last_us_ = timed_events_ == 1 ? log_time_us : std::max(last_us_, log_time_us);
  if (s.timed++ == 0) s.first_us = log_time_us;
  s.last_us = log_time_us;
  const std::optional<ChannelParts> name = ParseChannel(channel);
  if (!name) return;
  try {
    switch (name->kind) {
      case ChannelKind::kRequest:
        ++request_messages_;
        AddRequest(name->robot, log_time_us, bytes);
        break;
      case ChannelKind::kReply:
        AddReply(bytes);
        break;
      case ChannelKind::kAnnounce:
        AddAnnounce(bytes);
        break;
      case ChannelKind::kState:
        AddState(log_time_us, bytes);
        break;
      case ChannelKind::kHello:
        Client(DecodeHello(bytes).body.client_id, name->robot, log_time_us).hellos++;
        break;
      case ChannelKind::kHelloAnswer:
        AddHelloAnswer(bytes);
        break;
      case ChannelKind::kConfig:
        break;  // the robot's description: nothing a session's timeline needs
    }
  } catch (const std::exception& e) {
    reject(Printable(e.what()));  // a log holds whatever was on the bus; count it, name it, go on
  }
}

void SessionLog::AddDamage(const std::string& what) {
  if (rejections_++ < kKeptRejections) rejected_.push_back(what);
}

LoggedClient& SessionLog::Client(std::int64_t id, const std::string& robot, std::int64_t log_time_us) {
  LoggedClient& c = clients_[id];
  if (c.id == 0) {
    c.id = id;
    c.robot = robot;
    c.first_log_us = log_time_us;
  }
  c.last_log_us = log_time_us;
  return c;
}

void SessionLog::AddRequest(const std::string& robot, std::int64_t log_time_us,
                            std::span<const std::uint8_t> bytes) {
  const Request r = DecodeRequest(bytes);
  if (!r.header_error.empty())
    throw BadEntry("package " + std::to_string(r.sequence) + ": " + r.header_error);
  if (!r.malformed.empty())
    throw BadEntry("package " + std::to_string(r.sequence) + ", item " + std::to_string(r.malformed[0].id) +
                   ": " + r.malformed[0].reason);
  LoggedClient& c = Client(r.client_id, robot, log_time_us);
  const auto key = std::make_pair(r.client_id, r.sequence);
  if (package_send_us_.count(key)) {
    ++c.retransmissions;  // executed once by the server: kept once here
    return;
  }
  const std::int64_t send_time_us = ToWireMicros(r.send_time);
  package_send_us_[key] = send_time_us;
  ++c.packages;
  if (r.panic) ++c.panics;
  if (r.queries.empty() && r.commands.empty() && !r.panic) ++c.heartbeats;
  c.queries += r.queries.size();
  if (r.panic) {
    LoggedCommand marker;  // a panic is shown, never replayed (see MakeTimeline)
    marker.client_id = r.client_id;
    marker.robot = robot;
    marker.sequence = r.sequence;
    marker.panic = true;
    marker.send_time_us = send_time_us;
    marker.log_time_us = log_time_us;
    commands_.push_back(std::move(marker));
    return;
  }
  if (!r.commands.empty()) c.modes.insert(r.mode);
  if (r.mode == RequestMode::kPlayback) playback_ids_.insert({r.client_id, r.playback.id});
  for (const Command& command : r.commands) {
    const auto id_key = std::make_pair(r.client_id, command.id);
    if (command_index_.count(id_key)) continue;
    LoggedCommand lc;
    lc.client_id = r.client_id;
    lc.robot = robot;
    lc.sequence = r.sequence;
    lc.mode = r.mode;
    lc.playback_id = r.playback.id;
    lc.interpolation = r.interpolation;
    lc.command = command;
    lc.start_us = StartMicros(command.start_time);
    lc.send_time_us = send_time_us;
    lc.log_time_us = log_time_us;
    command_index_[id_key] = commands_.size();
    commands_.push_back(std::move(lc));
  }
}

void SessionLog::AddReply(std::span<const std::uint8_t> bytes) {
  ReplyBatch b = DecodeReplyBatch(bytes);
  if (!b.malformed.empty())
    throw BadEntry("reply " + std::to_string(b.malformed[0].id) + ": " + b.malformed[0].reason);
  auto client = clients_.find(b.client_id);
  // A playback sequence's delay reply (its id is the playback id): values[1]
  // = the start, on the server clock. Checked before anything is kept.
  std::map<std::int64_t, std::int64_t> starts;
  for (const Reply& r : b.replies) {
    if (client != clients_.end() && r.values.size() >= 2 && playback_ids_.count({b.client_id, r.id}))
      starts[r.id] = MicrosFromDouble(r.values[1], "reply " + std::to_string(r.id) + " (playback " +
                                                       std::to_string(r.id) + "'s start) values[1]");
  }
  if (b.ack_sequence > 0 && client != clients_.end()) {
    auto sent = package_send_us_.find({b.client_id, b.ack_sequence});
    if (sent != package_send_us_.end() && sent->second != 0) {
      // One-way latency included: min over all acks is the best estimate.
      const std::int64_t offset = ToWireMicros(b.server_receive) - sent->second;
      auto& o = client->second.clock_offset_us;
      if (!o || offset < *o) o = offset;
    }
  }
  for (const auto& [id, start] : starts) client->second.playback_start_us[id] = start;
  for (Reply& r : b.replies) {
    auto it = command_index_.find({b.client_id, r.id});
    if (it != command_index_.end() && !commands_[it->second].reply)
      commands_[it->second].reply = std::move(r);
  }
}

void SessionLog::AddHelloAnswer(std::span<const std::uint8_t> bytes) {
  const HelloAnswer a = DecodeHelloAnswer(bytes);
  auto client = clients_.find(a.body.client_id);
  if (client != clients_.end() && a.session_id == 0) ++client->second.hellos_refused;
}

void SessionLog::AddAnnounce(std::span<const std::uint8_t> bytes) {
  const Announcement a = DecodeAnnouncement(bytes);
  split_layout_seen_ = split_layout_seen_ || a.traffic_layout == TrafficLayout::kSplit;
  for (const RobotAnnouncement& r : a.robots) {
    LoggedRobot& lr = robots_[{a.server_id, r.name}];
    lr.name = r.name;
    lr.driver = Printable(r.driver);
    lr.server_id = a.server_id;
    lr.config_hash = r.config_hash;
    lr.total_dofs = r.total_dofs;
    lr.panic_seen = lr.panic_seen || r.panic;
  }
}

void SessionLog::AddState(std::int64_t log_time_us, std::span<const std::uint8_t> bytes) {
  robotalk::StateSample s = DecodeStateSample(bytes);
  StateSample sample;
  sample.robot = Printable(s.robot);
  sample.log_time_us = log_time_us;
  sample.server_time_us = ToWireMicros(s.server_time);
  sample.panic = s.panic;
  sample.moving = s.moving;
  sample.base = {s.base.x, s.base.y, s.base.theta, s.base.v, s.base.omega};
  sample.position = std::move(s.positions);
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
  if (c.mode == RequestMode::kPlayback) {
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
    if (c.panic) {
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
    if (request_messages_ == 0) {
      // lcm-logger hears one URL: with the split layout that is the main lane only.
      throw LogError("the log holds no request at all, so no command from " + what +
                     (split_layout_seen_
                          ? ": its server announced the split traffic layout, where requests and "
                            "replies travel on ports of their own that lcm-logger does not hear"
                          : "") +
                     "; record a session with `robotalk-logplay record` (it listens on every lane)");
    }
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
      kinds.insert(c->mode == RequestMode::kPlayback ? 1 : c->start_us != 0 ? 0 : 2);
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
