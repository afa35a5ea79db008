// The codec of whole packages (request.h): the only place besides
// protocol_codec.cpp that knows the LCM wire structs.
#include "protocol_codec.h"
#include "robotalk/broadcast_signature.h"
#include "robotalk/channels.h"
#include "robotalk/error.h"
#include "robotalk/request.h"
#include "robotalk/transport.h"
#include "robotalk_msgs/announce_t.hpp"
#include "robotalk_msgs/hello_answer_t.hpp"
#include "robotalk_msgs/hello_t.hpp"
#include "robotalk_msgs/root_link_t.hpp"
#include "wire_scanner.h"

#include <algorithm>
#include <cstring>
#include <utility>

namespace robotalk {
namespace {

template <std::size_t N>
void CopyBytes(std::array<std::uint8_t, N>& to, const std::uint8_t (&from)[N]) {
  std::memcpy(to.data(), from, N);
}
template <std::size_t N>
void CopyBytes(std::uint8_t (&to)[N], const std::array<std::uint8_t, N>& from) {
  std::memcpy(to, from.data(), N);
}

// A hello or its answer (DecodeChecked), with their version and client id checked.
template <typename Msg, typename ScanBody>
Msg DecodeHandshake(std::span<const std::uint8_t> bytes, const char* function, ScanBody&& scan_body) {
  const Msg m = DecodeChecked<Msg>(bytes, function, kMaxSmallMessageBytes, std::forward<ScanBody>(scan_body));
  if (m.protocol_version != kProtocolVersion) {
    throw ProtocolError(std::string(function) + ": protocol version " + std::to_string(m.protocol_version) +
                        " is not supported (this side speaks " + std::to_string(kProtocolVersion) + ")");
  }
  if (m.client_id == 0) throw ProtocolError(std::string(function) + ": client id 0 is reserved");
  return m;
}

}  // namespace

std::vector<CommandId> Request::item_ids() const {
  std::vector<CommandId> ids;
  ids.reserve(queries.size() + commands.size() + malformed.size());
  for (const Query& q : queries) ids.push_back(q.id);
  for (const Command& c : commands) ids.push_back(c.id);
  for (const MalformedItem& m : malformed) ids.push_back(m.id);
  return ids;
}

Request DecodeRequest(std::span<const std::uint8_t> bytes) {
  const robotalk_msgs::package_t p = DecodePackage(bytes);
  const auto& h = p.header;
  Request r;
  r.client_id = h.client_id;
  r.session_id = h.session_id;
  r.sequence = h.sequence;
  r.send_time = FromWireMicros(h.send_time_us, "package: send_time_us");
  r.panic = h.panic;
  r.header_error = CheckPackageHeader(p);
  r.mode = static_cast<RequestMode>(h.mode);
  if (r.header_error.empty()) {
    r.interpolation = static_cast<Interpolation>(h.interpolation);
    if (h.max_late_us == robotalk_msgs::package_header_t::MAX_LATE_NEVER) {
      r.max_late = kMaxLateNever;
    } else {
      r.max_late = DurationFromWireMicros(h.max_late_us, "package: max_late_us");
    }
    r.round_trip = DurationFromWireMicros(h.round_trip_us, "package: round_trip_us");
  }
  if (r.mode == RequestMode::kPlayback && r.header_error.empty()) {
    r.playback = {h.playback_id, h.playback_frames,
                  DurationFromWireMicros(h.playback_duration_us, "package: playback_duration_us")};
  }
  for (const auto& q : p.queries) {
    try {
      r.queries.push_back(FromWire(q));
    } catch (const ProtocolError& e) {
      r.malformed.push_back({q.id, e.what()});
    }
  }
  for (const auto& c : p.commands) {
    try {
      r.commands.push_back(FromWire(c, h.mode));
    } catch (const ProtocolError& e) {
      r.malformed.push_back({c.id, e.what()});
    }
  }
  r.mac = ReadMacField(bytes);
  return r;
}

std::vector<std::uint8_t> EncodeRequest(const Request& r) {
  robotalk_msgs::package_t p{};
  auto& h = p.header;
  h.protocol_version = kProtocolVersion;
  h.client_id = r.client_id;
  h.session_id = r.session_id;
  h.sequence = r.sequence;
  h.send_time_us = ToWireMicros(r.send_time);
  h.panic = r.panic;
  h.mode = static_cast<std::int8_t>(r.mode);
  if (r.mode == RequestMode::kPlayback) {
    h.playback_id = r.playback.id;
    h.playback_frames = static_cast<std::int32_t>(r.playback.frames);
    h.playback_duration_us = ToWireMicros(r.playback.duration);
  }
  h.interpolation = static_cast<std::int8_t>(r.interpolation);
  if (r.max_late == kMaxLateNever) {
    h.max_late_us = robotalk_msgs::package_header_t::MAX_LATE_NEVER;
  } else if (r.max_late < Duration::zero()) {
    throw ProtocolError("package: negative max_late " + std::to_string(ToSeconds(r.max_late)) + " s");
  } else {
    // 0 on the wire is the robot's default: a positive limit below the wire's
    // microsecond travels as 1 µs, never as that (looser) default.
    h.max_late_us = r.max_late > Duration::zero() ? std::max<std::int64_t>(1, ToWireMicros(r.max_late)) : 0;
  }
  h.round_trip_us = r.round_trip > Duration::zero() ? ToWireMicros(r.round_trip) : 0;
  for (const Query& q : r.queries) p.queries.push_back(ToWire(q));
  for (const Command& c : r.commands) p.commands.push_back(ToWire(c, h.mode));
  p.num_queries = static_cast<std::int32_t>(p.queries.size());
  p.num_commands = static_cast<std::int32_t>(p.commands.size());
  const bool commands = p.num_commands > 0;  // a package mixing both is refused by the server
  h.payload_type = commands ? robotalk_msgs::package_header_t::PAYLOAD_COMMANDS
                            : robotalk_msgs::package_header_t::PAYLOAD_QUERIES;
  h.payload_size = commands ? p.num_commands : p.num_queries;
  CopyBytes(p.mac, r.mac);
  return EncodeMessage(p);
}

std::vector<std::uint8_t> EncodeReplyBatch(const ReplyBatch& b) {
  robotalk_msgs::reply_package_t p{};
  p.protocol_version = kProtocolVersion;
  p.client_id = b.client_id;
  p.server_id = b.server_id;
  p.session_id = b.session_id;
  p.session_status = static_cast<std::int8_t>(b.session_status);
  p.panic_status = static_cast<std::int8_t>(b.panic);
  p.panic_refusal = b.panic_refusal;
  p.ack_sequence = b.ack_sequence;
  p.server_receive_us = ToWireMicros(b.server_receive);
  p.server_send_us = ToWireMicros(b.server_send);
  p.replies.reserve(b.replies.size());
  for (const Reply& r : b.replies) p.replies.push_back(ToWire(r));
  p.num_replies = static_cast<std::int32_t>(p.replies.size());
  CopyBytes(p.mac, b.mac);
  return EncodeMessage(p);
}

namespace {

// A keyed server signs a SESSION_UNKNOWN answer (it has no session key to
// seal it with): the message, then the signature suffix (broadcast_signature.h).
robotalk_msgs::reply_package_t DecodeReplyPackageOrSigned(std::span<const std::uint8_t> bytes) {
  try {
    return DecodeReplyPackage(bytes);
  } catch (const ProtocolError&) {
    if (!SignatureSuffix(bytes)) throw;
  }
  const robotalk_msgs::reply_package_t p = DecodeReplyPackage(WithoutSignature(bytes));
  if (p.session_status != robotalk_msgs::reply_package_t::SESSION_UNKNOWN) {
    throw ProtocolError("DecodeReplyBatch: a signature suffix after a reply package of a session");
  }
  return p;
}

}  // namespace

ReplyBatch DecodeReplyBatch(std::span<const std::uint8_t> bytes) {
  const robotalk_msgs::reply_package_t p = DecodeReplyPackageOrSigned(bytes);
  if (p.protocol_version != kProtocolVersion) {
    throw ProtocolError("DecodeReplyBatch: protocol version " + std::to_string(p.protocol_version) +
                        " is not supported (this side speaks " + std::to_string(kProtocolVersion) + ")");
  }
  ReplyBatch b;
  b.client_id = p.client_id;
  b.server_id = p.server_id;
  b.session_id = p.session_id;
  if (p.session_status != robotalk_msgs::reply_package_t::SESSION_OK &&
      p.session_status != robotalk_msgs::reply_package_t::SESSION_UNKNOWN) {
    throw ProtocolError("DecodeReplyBatch: unknown session status " + std::to_string(p.session_status));
  }
  b.session_status = static_cast<SessionStatus>(p.session_status);
  b.panic = static_cast<PanicStatus>(CheckedPanicStatus(p));
  b.panic_refusal = p.panic_refusal;
  b.ack_sequence = p.ack_sequence;
  b.server_receive = FromWireMicros(p.server_receive_us, "reply package: server_receive_us");
  b.server_send = FromWireMicros(p.server_send_us, "reply package: server_send_us");
  for (const auto& r : p.replies) {
    try {
      b.replies.push_back(FromWire(r));
    } catch (const ProtocolError& e) {
      b.malformed.push_back({r.id, e.what()});
    }
  }
  CopyBytes(b.mac, p.mac);
  return b;
}

std::vector<std::uint8_t> EncodeAnnouncement(const Announcement& a) {
  robotalk_msgs::announce_t m{};
  m.protocol_version = kProtocolVersion;
  m.server_id = a.server_id;
  m.server_time_us = ToWireMicros(a.server_time);
  m.uptime_us = ToWireMicros(a.uptime);
  m.url_hint = a.url_hint;
  m.traffic_layout = static_cast<std::int8_t>(a.traffic_layout);
  m.keyed = a.keyed;
  for (const RobotAnnouncement& r : a.robots) {
    robotalk_msgs::robot_info_t info{};
    info.name = r.name;
    info.driver = r.driver;
    info.config_hash = static_cast<std::int64_t>(r.config_hash);
    info.total_dofs = r.total_dofs;
    info.base_type = static_cast<std::int8_t>(r.base_type);
    info.panic = r.panic;
    info.num_clients = r.num_clients;
    m.robots.push_back(info);
  }
  m.num_robots = static_cast<std::int32_t>(m.robots.size());
  return EncodeMessage(m);
}

std::vector<std::uint8_t> EncodeStateSample(const StateSample& sample) {
  return EncodeMessage(ToWire(sample));
}

StateSample DecodeStateSample(std::span<const std::uint8_t> bytes, int expected_dofs) {
  return FromWire(DecodeRobotState(bytes), expected_dofs);
}

Announcement DecodeAnnouncement(std::span<const std::uint8_t> bytes) {
  // A keyed server's signature suffix: verified (or not) by the caller. (A
  // string length of 0 in an ANNOUNCE made LCM's decoder throw through its C
  // callback, found by tests/fuzz: DecodeChecked walks it first.)
  const auto m = DecodeChecked<robotalk_msgs::announce_t>(
      WithoutSignature(bytes), "DecodeAnnouncement", kMaxSmallMessageBytes, [](WireScanner& scan) {
        scan.Skip(2 + 8 + 8 + 8, "header");
        scan.String("url_hint");
        scan.Skip(1 + 1, "traffic_layout, keyed");
        constexpr std::int64_t kMinRobotBytes = 2 * kLcmStringOverhead + 8 + 4 + 1 + 1 + 4;
        const std::int32_t robots = scan.Count("num_robots", kMinRobotBytes);
        for (std::int32_t i = 0; i < robots; ++i) {
          scan.String("robot.name");
          scan.String("robot.driver");
          scan.Skip(8 + 4 + 1 + 1 + 4, "robot fields");
        }
      });
  const auto fail = [](const char* field, const std::string& what) {
    throw ProtocolError(std::string("DecodeAnnouncement: ") + field + ": " + what);
  };
  // Anyone's datagram: its texts reach terminals (`robotalk robots`), logs
  // and robotalk-web's and robotalk-ros2's tables. A name no server can
  // serve (RobotNameProblem), or a driver or URL hint not in printable ASCII
  // (a terminal escape, C0 or UTF-8-encoded C1; a line break forging a log
  // line), is refused here, for every reader.
  const auto printable = [&](const char* field, const std::string& text) {
    for (const char c : text) {
      const auto u = static_cast<unsigned char>(c);
      if (u < 0x20 || u >= 0x7f) fail(field, "not printable ASCII (byte " + std::to_string(u) + ")");
    }
  };
  printable("url_hint", m.url_hint);
  for (const auto& r : m.robots) {
    if (const std::string why = RobotNameProblem(r.name); !why.empty()) fail("robot.name", why);
    printable("robot.driver", r.driver);
  }
  Announcement a;
  a.server_id = m.server_id;
  a.server_time = FromWireMicros(m.server_time_us, "announce: server_time_us");
  a.uptime = DurationFromWireMicros(m.uptime_us, "announce: uptime_us");
  a.url_hint = m.url_hint;
  if (m.traffic_layout != robotalk_msgs::announce_t::TRAFFIC_SINGLE &&
      m.traffic_layout != robotalk_msgs::announce_t::TRAFFIC_SPLIT) {
    fail("traffic_layout", "unknown value " + std::to_string(m.traffic_layout));
  }
  a.traffic_layout = static_cast<TrafficLayout>(m.traffic_layout);
  a.keyed = m.keyed != 0;
  for (const auto& r : m.robots) {
    if (r.base_type < robotalk_msgs::root_link_t::BASE_FIXED ||
        r.base_type > robotalk_msgs::root_link_t::BASE_FLOATING) {
      fail("robot.base_type", "unknown value " + std::to_string(r.base_type));
    }
    a.robots.push_back({r.name, r.driver, static_cast<std::uint64_t>(r.config_hash), r.total_dofs,
                        static_cast<BaseType>(r.base_type), r.panic != 0, r.num_clients});
  }
  return a;
}

std::vector<std::uint8_t> EncodeHello(const Hello& hello) {
  robotalk_msgs::hello_t m{};
  m.protocol_version = kProtocolVersion;
  m.client_id = hello.body.client_id;
  CopyBytes(m.client_nonce, hello.body.client_nonce);
  m.keyed = hello.keyed;
  CopyBytes(m.client_key, hello.body.client_key.bytes);
  CopyBytes(m.client_kx, hello.body.client_kx);
  CopyBytes(m.signature, hello.body.signature);
  return EncodeMessage(m);
}

Hello DecodeHello(std::span<const std::uint8_t> bytes) {
  const auto m = DecodeHandshake<robotalk_msgs::hello_t>(
      bytes, "DecodeHello", [](WireScanner& scan) { scan.Skip(2 + 8 + 16 + 1 + 32 + 32 + 64, "fields"); });
  Hello h;
  h.keyed = m.keyed != 0;
  h.body.client_id = m.client_id;
  CopyBytes(h.body.client_nonce, m.client_nonce);
  CopyBytes(h.body.client_key.bytes, m.client_key);
  CopyBytes(h.body.client_kx, m.client_kx);
  CopyBytes(h.body.signature, m.signature);
  return h;
}

std::vector<std::uint8_t> EncodeHelloAnswer(const HelloAnswer& a) {
  robotalk_msgs::hello_answer_t m{};
  m.protocol_version = kProtocolVersion;
  m.client_id = a.body.client_id;
  CopyBytes(m.client_nonce, a.body.client_nonce);
  m.server_id = a.server_id;
  m.session_id = a.session_id;
  m.refusal = a.refusal;
  m.keyed = a.keyed;
  CopyBytes(m.instance_nonce, a.body.instance_nonce);
  CopyBytes(m.server_nonce, a.body.server_nonce);
  CopyBytes(m.server_kx, a.body.server_kx);
  CopyBytes(m.server_key, a.body.server_key.bytes);
  CopyBytes(m.signature, a.body.signature);
  return EncodeMessage(m);
}

HelloAnswer DecodeHelloAnswer(std::span<const std::uint8_t> bytes) {
  const auto m =
      DecodeHandshake<robotalk_msgs::hello_answer_t>(bytes, "DecodeHelloAnswer", [](WireScanner& scan) {
        scan.Skip(2 + 8 + 16 + 8 + 8, "fields");
        scan.String("refusal");
        scan.Skip(1 + 16 + 16 + 32 + 32 + 64, "keyed fields");
      });
  if (m.session_id < 0) throw ProtocolError("DecodeHelloAnswer: negative session id");
  HelloAnswer a;
  a.server_id = m.server_id;
  a.session_id = m.session_id;
  a.refusal = m.refusal;
  a.keyed = m.keyed != 0;
  a.body.client_id = m.client_id;
  CopyBytes(a.body.client_nonce, m.client_nonce);
  CopyBytes(a.body.instance_nonce, m.instance_nonce);
  CopyBytes(a.body.server_nonce, m.server_nonce);
  CopyBytes(a.body.server_kx, m.server_kx);
  CopyBytes(a.body.server_key.bytes, m.server_key);
  CopyBytes(a.body.signature, m.signature);
  return a;
}

namespace {
void CheckMacRoom(std::size_t size) {
  if (size < kMacBytes) {
    throw ProtocolError("package of " + std::to_string(size) + " bytes is shorter than its " +
                        std::to_string(kMacBytes) + "-byte MAC");
  }
}
}  // namespace

std::span<const std::uint8_t> MacCoveredBytes(std::span<const std::uint8_t> bytes) {
  CheckMacRoom(bytes.size());
  return bytes.first(bytes.size() - kMacBytes);
}

Mac ReadMacField(std::span<const std::uint8_t> bytes) {
  CheckMacRoom(bytes.size());
  Mac mac{};
  std::memcpy(mac.data(), bytes.data() + bytes.size() - kMacBytes, kMacBytes);
  return mac;
}

void WriteMacField(std::span<std::uint8_t> bytes, const Mac& mac) {
  CheckMacRoom(bytes.size());
  std::memcpy(bytes.data() + bytes.size() - kMacBytes, mac.data(), kMacBytes);
}

}  // namespace robotalk
