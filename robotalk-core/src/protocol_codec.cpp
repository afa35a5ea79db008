#include "robotalk/protocol_codec.h"

#include "robotalk/error.h"
#include "wire_scanner.h"

#include <climits>

namespace robotalk {
namespace {

// Smallest encodings of the array elements (an empty string takes 5 bytes).
constexpr std::int64_t kMinQueryBytes = 8 + 1 + kLcmStringOverhead + 8;
constexpr std::int64_t kMinCommandBytes = 8 + 1 + 8 + kLcmStringOverhead + 2;
constexpr std::int64_t kMinReplyBytes = 8 + 1 + kLcmStringOverhead + 8 + 8 + 4;

void ScanPackage(WireScanner& s) {
  s.Skip(2 + 8 + 8 + 8 + 1 + 1 + 4 + 1 + 8 + 4 + 8, "header");
  const std::int32_t nq = s.Count("num_queries", kMinQueryBytes);
  for (std::int32_t i = 0; i < nq; ++i) {
    s.Skip(8 + 1, "query");
    s.String("query.target");
    s.Skip(8, "query.period_us");
  }
  const std::int32_t nc = s.Count("num_commands", kMinCommandBytes);
  for (std::int32_t i = 0; i < nc; ++i) {
    s.Skip(8 + 1 + 8, "command");
    s.String("command.target");
    s.Skip(std::int64_t{8} * s.Count16("command.num_values", 8), "command.values");
  }
}

void ScanReplyPackage(WireScanner& s) {
  s.Skip(2 + 8 + 8 + 8 + 8, "header");
  const std::int32_t nr = s.Count("num_replies", kMinReplyBytes);
  for (std::int32_t i = 0; i < nr; ++i) {
    s.Skip(8 + 1, "reply");
    s.String("reply.message");
    s.Skip(8 + 8, "reply times");
    s.Skip(std::int64_t{8} * s.Count("reply.num_values", 8), "reply.values");
  }
}

void ScanRobotState(WireScanner& s) {
  s.Skip(8 + 8 + 8, "times");
  s.String("robot");
  s.Skip(8 + 1 + 1, "config_hash, panic, moving");
  const std::int32_t dofs = s.Count("num_dofs", 3 * 8);
  s.Skip(std::int64_t{3 * 8} * dofs, "position, velocity, effort");
  s.Skip(5 * 8, "base");
  const std::int32_t frames = s.Count("num_frames", 7 * 8);
  s.Skip(std::int64_t{7 * 8} * frames, "frame_poses");
}

template <typename Msg>
Msg DecodeChecked(std::span<const std::uint8_t> bytes, const char* function, void (*scan)(WireScanner&)) {
  if (bytes.size() > static_cast<size_t>(INT32_MAX))
    throw ProtocolError(std::string(function) + ": message too large");
  WireScanner s(function, bytes);
  // The fingerprint first: a message of another type gives a clear error.
  if (s.Int64("fingerprint") != Msg::getHash())
    s.Fail("fingerprint", "does not match (another message type?)");
  scan(s);
  s.ExpectEnd();
  Msg msg{};
  if (msg.decode(bytes.data(), 0, static_cast<int>(bytes.size())) != static_cast<int>(bytes.size())) {
    s.Fail("message", "LCM decode failed");
  }
  return msg;
}

}  // namespace

robotalk_msgs::command_t ToWire(const Command& c) {
  robotalk_msgs::command_t w{};
  w.id = c.id;
  w.type = static_cast<std::int8_t>(c.type);
  w.start_time_us = c.start_time ? ToWireMicros(*c.start_time) : 0;
  w.target = c.target;
  w.num_values = static_cast<std::int16_t>(c.values.size());
  w.values = c.values;
  return w;
}

robotalk_msgs::query_t ToWire(const Query& q) {
  robotalk_msgs::query_t w{};
  w.id = q.id;
  w.type = static_cast<std::int8_t>(q.type);
  w.target = q.target;
  w.period_us = ToWireMicros(q.period);
  return w;
}

robotalk_msgs::reply_t ToWire(const Reply& r) {
  robotalk_msgs::reply_t w{};
  w.id = r.id;
  w.signal = static_cast<std::int8_t>(r.signal);
  w.message = r.message;
  w.exec_time_us = ToWireMicros(r.exec_time);
  w.lateness_us = ToWireMicros(r.lateness);
  w.num_values = static_cast<std::int32_t>(r.values.size());
  w.values = r.values;
  return w;
}

Command FromWire(const robotalk_msgs::command_t& w) {
  if (w.type < 1 || w.type > static_cast<std::int8_t>(CommandType::kPanicReset)) {
    throw ProtocolError("command " + std::to_string(w.id) + ": unknown command type " +
                        std::to_string(w.type));
  }
  if (w.start_time_us < 0) {
    throw ProtocolError("command " + std::to_string(w.id) + ": negative start time " +
                        std::to_string(w.start_time_us) + " us");
  }
  Command c;
  c.id = w.id;
  c.type = static_cast<CommandType>(w.type);
  if (w.start_time_us != 0) c.start_time = FromWireMicros(w.start_time_us);
  c.target = w.target;
  c.values = w.values;
  return c;
}

Query FromWire(const robotalk_msgs::query_t& w) {
  if (w.type < 1 || w.type > static_cast<std::int8_t>(QueryType::kStateStreamCancel)) {
    throw ProtocolError("query " + std::to_string(w.id) + ": unknown query type " + std::to_string(w.type));
  }
  if (w.period_us < 0) {
    throw ProtocolError("query " + std::to_string(w.id) + ": negative period " + std::to_string(w.period_us) +
                        " us");
  }
  return Query{w.id, static_cast<QueryType>(w.type), w.target, std::chrono::microseconds(w.period_us)};
}

Reply FromWire(const robotalk_msgs::reply_t& w) {
  auto signal = SignalFromWire(w.signal);
  if (!signal)
    throw ProtocolError("reply " + std::to_string(w.id) + ": unknown signal " + std::to_string(w.signal));
  Reply r;
  r.id = w.id;
  r.signal = *signal;
  r.message = w.message;
  r.exec_time = FromWireMicros(w.exec_time_us);
  r.lateness = std::chrono::microseconds(w.lateness_us);
  r.values = w.values;
  return r;
}

robotalk_msgs::package_t DecodePackage(std::span<const std::uint8_t> bytes) {
  return DecodeChecked<robotalk_msgs::package_t>(bytes, "DecodePackage", &ScanPackage);
}

robotalk_msgs::reply_package_t DecodeReplyPackage(std::span<const std::uint8_t> bytes) {
  return DecodeChecked<robotalk_msgs::reply_package_t>(bytes, "DecodeReplyPackage", &ScanReplyPackage);
}

robotalk_msgs::robot_state_t DecodeRobotState(std::span<const std::uint8_t> bytes) {
  return DecodeChecked<robotalk_msgs::robot_state_t>(bytes, "DecodeRobotState", &ScanRobotState);
}

std::string CheckPackageHeader(const robotalk_msgs::package_t& p) {
  const auto& h = p.header;
  if (h.protocol_version != kProtocolVersion) {
    return "package: protocol version " + std::to_string(h.protocol_version) +
           " is not supported (server speaks " + std::to_string(kProtocolVersion) + ")";
  }
  if (h.client_id == 0) return "package: client id 0 is reserved";
  if (h.mode < robotalk_msgs::package_header_t::MODE_DIRECT ||
      h.mode > robotalk_msgs::package_header_t::MODE_PLAYBACK) {
    return "package: unknown mode " + std::to_string(h.mode);
  }
  if (h.mode == robotalk_msgs::package_header_t::MODE_PLAYBACK) {
    if (p.num_queries > 0) return "package: a PLAYBACK package carries commands only";
    if (h.playback_frames < 1)
      return "package: PLAYBACK declares " + std::to_string(h.playback_frames) + " frames";
    if (h.playback_duration_us < 0) return "package: PLAYBACK declares a negative duration";
    if (h.playback_id == 0) return "package: PLAYBACK id 0 is reserved";
  }
  if (h.sequence <= 0) return "package: sequence " + std::to_string(h.sequence) + " is not positive";
  if (p.num_queries > 0 && p.num_commands > 0) {
    return "package: mixes " + std::to_string(p.num_queries) + " queries and " +
           std::to_string(p.num_commands) + " commands; a package carries one or the other";
  }
  const bool panic_only = h.panic && p.num_queries == 0 && p.num_commands == 0;
  if (h.payload_type == robotalk_msgs::package_header_t::PAYLOAD_QUERIES) {
    if (p.num_commands > 0) return "package: payload type QUERIES but it carries commands";
    if (h.payload_size != p.num_queries) {
      return "package: header payload size " + std::to_string(h.payload_size) + " but " +
             std::to_string(p.num_queries) + " queries";
    }
  } else if (h.payload_type == robotalk_msgs::package_header_t::PAYLOAD_COMMANDS) {
    if (p.num_queries > 0) return "package: payload type COMMANDS but it carries queries";
    if (h.payload_size != p.num_commands) {
      return "package: header payload size " + std::to_string(h.payload_size) + " but " +
             std::to_string(p.num_commands) + " commands";
    }
  } else if (!panic_only) {
    return "package: unknown payload type " + std::to_string(h.payload_type);
  }
  return "";
}

}  // namespace robotalk
