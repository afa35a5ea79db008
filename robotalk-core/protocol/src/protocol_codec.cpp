#include "protocol_codec.h"

#include "robotalk/broadcast_signature.h"
#include "robotalk/channels.h"
#include "robotalk/error.h"
#include "robotalk_msgs/command_t.hpp"
#include "wire_scanner.h"

#include <algorithm>
#include <climits>
#include <cmath>

namespace robotalk {
namespace {

// Wire codes: every row of kCommandTraits (command.h) is the command_t
// constant of its name. A constant without a row is caught by
// command_traits_test, which reads command_t.lcm.
constexpr bool SameName(const char* a, const char* b) {
  for (; *a && *a == *b; ++a, ++b) {
  }
  return *a == *b;
}
constexpr int TraitsCode(const char* name) {
  for (const CommandTraits& t : kCommandTraits) {
    if (SameName(t.name, name)) return static_cast<int>(t.type);
  }
  return -1;
}
#define ROBOTALK_WIRE_COMMAND(NAME)                                  \
  static_assert(TraitsCode(#NAME) == robotalk_msgs::command_t::NAME, \
                #NAME ": kCommandTraits (command.h) and command_t.lcm disagree")
ROBOTALK_WIRE_COMMAND(JOINT_SETPOINT);
ROBOTALK_WIRE_COMMAND(JOINT_SPEED);
ROBOTALK_WIRE_COMMAND(JOINT_FORCE);
ROBOTALK_WIRE_COMMAND(FRAME_SETPOINT);
ROBOTALK_WIRE_COMMAND(GOTO);
ROBOTALK_WIRE_COMMAND(SETSPEED);
ROBOTALK_WIRE_COMMAND(STOP);
ROBOTALK_WIRE_COMMAND(PANIC_RESET);
#undef ROBOTALK_WIRE_COMMAND

// Smallest encodings of the array elements (an empty string takes 5 bytes).
constexpr std::int64_t kMinQueryBytes = 8 + 1 + kLcmStringOverhead + 8 + 8;
constexpr std::int64_t kMinCommandBytes = 8 + 1 + 8 + kLcmStringOverhead + 2 + 2 + 2;
constexpr std::int64_t kMinReplyBytes = 8 + 1 + kLcmStringOverhead + 8 + 8 + 4;

void ScanPackage(WireScanner& s) {
  s.Skip(2 + 8 + 8 + 8 + 1 + 1 + 4 + 1 + 8 + 4 + 8 + 8 + 1 + 8 + 8, "header");
  const std::int32_t nq = s.Count("num_queries", kMinQueryBytes);
  for (std::int32_t i = 0; i < nq; ++i) {
    s.Skip(8 + 1, "query");
    s.String("query.target");
    s.Skip(8 + 8, "query.period_us, about_id");
  }
  const std::int32_t nc = s.Count("num_commands", kMinCommandBytes);
  for (std::int32_t i = 0; i < nc; ++i) {
    s.Skip(8 + 1 + 8, "command");
    s.String("command.target");
    s.Skip(std::int64_t{8} * s.Count16("command.num_values", 8), "command.values");
    s.Skip(std::int64_t{8} * s.Count16("command.num_velocities", 8), "command.velocities");
    s.Skip(std::int64_t{8} * s.Count16("command.num_accelerations", 8), "command.accelerations");
  }
  s.Skip(kMacBytesOnWire, "mac");
}

void ScanReplyPackage(WireScanner& s) {
  s.Skip(2 + 8 + 8 + 8 + 1 + 1, "header");
  s.String("panic_refusal");
  s.Skip(8 + 8 + 8, "header times");
  const std::int32_t nr = s.Count("num_replies", kMinReplyBytes);
  for (std::int32_t i = 0; i < nr; ++i) {
    s.Skip(8 + 1, "reply");
    s.String("reply.message");
    s.Skip(8 + 8, "reply times");
    s.Skip(std::int64_t{8} * s.Count("reply.num_values", 8), "reply.values");
  }
  s.Skip(kMacBytesOnWire, "mac");
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
  s.Skip(8 + 1 + 8 + 8 + 8 + 8 + 8, "link");
}

}  // namespace

namespace {

using Header = robotalk_msgs::package_header_t;

std::string CommandField(std::int64_t id, const char* field) {
  return "command " + std::to_string(id) + ": " + field;
}

std::int64_t StartToWire(const Command& c) {
  const StartTime& s = c.start_time;
  if (s.is_now()) return 0;
  if (s.is_at()) {
    const std::int64_t us = ToWireMicros(*s.time());
    if (us < 0) {
      throw ProtocolError(CommandField(c.id, "start time ") + std::to_string(us) +
                          " us is before the server clock's epoch");
    }
    return us;
  }
  const std::int64_t us = ToWireMicros(*s.offset());
  if (us < 0)
    throw ProtocolError(CommandField(c.id, "negative playback offset ") + std::to_string(us) + " us");
  return us;
}

StartTime StartFromWire(const robotalk_msgs::command_t& w, std::int8_t mode) {
  if (w.start_time_us < 0) {
    throw ProtocolError(CommandField(w.id, "negative start time ") + std::to_string(w.start_time_us) + " us");
  }
  const std::string field = CommandField(w.id, "start_time_us");
  if (mode == Header::MODE_PLAYBACK) return StartTime::After(DurationFromWireMicros(w.start_time_us, field));
  if (w.start_time_us == 0) return StartTime::Now();
  return StartTime::At(FromWireMicros(w.start_time_us, field));
}

std::string StateLabel(const robotalk_msgs::robot_state_t& w) {
  return "robot_state '" + w.robot + "' sample " + std::to_string(w.sample) + ": ";
}

void CheckFiniteValues(const std::string& label, const char* field, const double* v, std::size_t n) {
  for (std::size_t i = 0; i < n; ++i) {
    if (!std::isfinite(v[i])) {
      throw ProtocolError(label + field + "[" + std::to_string(i) + "] is " +
                          (std::isnan(v[i]) ? "NaN" : "infinite"));
    }
  }
}

void CheckArraySize(const std::string& label, const char* field, std::size_t size, std::int32_t count,
                    const char* count_field) {
  if (count < 0 || size != static_cast<std::size_t>(count)) {
    throw ProtocolError(label + field + " has " + std::to_string(size) + " values but " + count_field +
                        " is " + std::to_string(count));
  }
}

}  // namespace

robotalk_msgs::command_t ToWire(const Command& c) {
  robotalk_msgs::command_t w{};
  w.id = c.id;
  w.type = static_cast<std::int8_t>(c.type);
  w.start_time_us = StartToWire(c);
  w.target = c.target;
  if (c.values.size() > static_cast<std::size_t>(INT16_MAX)) {
    throw ProtocolError(CommandField(c.id, "") + std::to_string(c.values.size()) + " values (at most " +
                        std::to_string(INT16_MAX) + ")");
  }
  w.num_values = static_cast<std::int16_t>(c.values.size());
  w.values = c.values;
  // CheckCommand bounds these to 7 each; a client's own bad count is refused
  // there with its name, so only the int16 range matters here.
  if (c.velocities.size() > static_cast<std::size_t>(INT16_MAX) ||
      c.accelerations.size() > static_cast<std::size_t>(INT16_MAX)) {
    throw ProtocolError(CommandField(c.id, "too many velocities or accelerations"));
  }
  w.num_velocities = static_cast<std::int16_t>(c.velocities.size());
  w.velocities = c.velocities;
  w.num_accelerations = static_cast<std::int16_t>(c.accelerations.size());
  w.accelerations = c.accelerations;
  return w;
}

robotalk_msgs::command_t ToWire(const Command& c, std::int8_t package_mode) {
  const bool playback = package_mode == Header::MODE_PLAYBACK;
  if (playback && c.start_time.is_at()) {
    throw ProtocolError(CommandField(c.id, "a PLAYBACK package carries offsets (StartTime::After), not ") +
                        ToString(c.start_time));
  }
  if (!playback && c.start_time.is_after()) {
    throw ProtocolError(CommandField(c.id, "only a PLAYBACK package carries offsets; got ") +
                        ToString(c.start_time));
  }
  return ToWire(c);
}

robotalk_msgs::query_t ToWire(const Query& q) {
  robotalk_msgs::query_t w{};
  w.id = q.id;
  w.type = static_cast<std::int8_t>(q.type);
  w.target = q.target;
  w.period_us = ToWireMicros(q.period);
  w.about_id = q.about;
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

Command FromWire(const robotalk_msgs::command_t& w) { return FromWire(w, Header::MODE_DIRECT); }

Command FromWire(const robotalk_msgs::command_t& w, std::int8_t package_mode) {
  if (!FindCommandTraits(w.type)) {
    throw ProtocolError("command " + std::to_string(w.id) + ": unknown command type " +
                        std::to_string(w.type));
  }
  Command c;
  c.id = w.id;
  c.type = static_cast<CommandType>(w.type);
  c.start_time = StartFromWire(w, package_mode);
  c.target = w.target;
  c.values = w.values;
  c.velocities = w.velocities;
  c.accelerations = w.accelerations;
  return c;
}

Query FromWire(const robotalk_msgs::query_t& w) {
  if (w.type < 1 || w.type > static_cast<std::int8_t>(QueryType::kServerCounters)) {
    throw ProtocolError("query " + std::to_string(w.id) + ": unknown query type " + std::to_string(w.type));
  }
  if (w.period_us < 0) {
    throw ProtocolError("query " + std::to_string(w.id) + ": negative period " + std::to_string(w.period_us) +
                        " us");
  }
  return Query{w.id, static_cast<QueryType>(w.type), w.target,
               DurationFromWireMicros(w.period_us, "query " + std::to_string(w.id) + ": period_us"),
               w.about_id};
}

Reply FromWire(const robotalk_msgs::reply_t& w) {
  auto signal = SignalFromWire(w.signal);
  if (!signal)
    throw ProtocolError("reply " + std::to_string(w.id) + ": unknown signal " + std::to_string(w.signal));
  const std::string label = "reply " + std::to_string(w.id) + ": ";
  Reply r;
  r.id = w.id;
  r.signal = *signal;
  r.message = w.message;
  r.exec_time = FromWireMicros(w.exec_time_us, label + "exec_time_us");
  r.lateness = DurationFromWireMicros(w.lateness_us, label + "lateness_us");
  r.values = w.values;
  return r;
}

StateSample FromWire(const robotalk_msgs::robot_state_t& w, int expected_dofs) {
  // Anyone's datagram: its robot name reaches terminals (`watch`), logs and
  // robotalk-web's, robotalk-ros2's and logplay's tables. The one rule of
  // ANNOUNCE and the commands (RobotNameProblem) first, before any text
  // quotes the name (StateLabel).
  if (const std::string why = RobotNameProblem(w.robot); !why.empty())
    throw ProtocolError("robot_state sample " + std::to_string(w.sample) + ": robot: " + why);
  const std::string label = StateLabel(w);
  CheckArraySize(label, "position", w.position.size(), w.num_dofs, "num_dofs");
  CheckArraySize(label, "velocity", w.velocity.size(), w.num_dofs, "num_dofs");
  CheckArraySize(label, "effort", w.effort.size(), w.num_dofs, "num_dofs");
  CheckArraySize(label, "frame_poses", w.frame_poses.size(), w.num_frames, "num_frames");
  if (expected_dofs >= 0 && w.num_dofs != expected_dofs) {
    throw ProtocolError(label + "num_dofs is " + std::to_string(w.num_dofs) + ", the model has " +
                        std::to_string(expected_dofs));
  }
  if (w.period_us < 0) throw ProtocolError(label + "negative period_us " + std::to_string(w.period_us));
  if (w.sample < 0) throw ProtocolError(label + "negative sample number");
  // A sample in panic may carry what a broken driver reported (NaN, inf):
  // the server halted the robot for it (issue 19; docs/protocol.md).
  const bool finite = !w.panic;
  if (finite) {
    CheckFiniteValues(label, "position", w.position.data(), w.position.size());
    CheckFiniteValues(label, "velocity", w.velocity.data(), w.velocity.size());
    CheckFiniteValues(label, "effort", w.effort.data(), w.effort.size());
    CheckFiniteValues(label, "base", w.base, 5);
  }
  StateSample s;
  s.frame_poses.reserve(w.frame_poses.size());
  for (std::size_t i = 0; i < w.frame_poses.size(); ++i) {
    if (w.frame_poses[i].size() != 7)
      throw ProtocolError(label + "frame_poses[" + std::to_string(i) + "] is not 7 values");
    if (finite) {
      CheckFiniteValues(label, ("frame_poses[" + std::to_string(i) + "]").c_str(), w.frame_poses[i].data(),
                        7);
    }
    PoseValues pose{};
    std::copy(w.frame_poses[i].begin(), w.frame_poses[i].end(), pose.begin());
    s.frame_poses.push_back(pose);
  }
  s.server_time = FromWireMicros(w.server_time_us, label + "server_time_us");
  s.period = DurationFromWireMicros(w.period_us, label + "period_us");
  s.sample = w.sample;
  s.robot = w.robot;
  s.config_hash = static_cast<std::uint64_t>(w.config_hash);
  s.panic = w.panic;
  s.moving = w.moving;
  s.positions = w.position;
  s.velocities = w.velocity;
  s.efforts = w.effort;
  s.base = BaseState{w.base[0], w.base[1], w.base[2], w.base[3], w.base[4]};
  if (w.link_level < robotalk_msgs::robot_state_t::LINK_UNKNOWN ||
      w.link_level > robotalk_msgs::robot_state_t::LINK_BAD) {
    throw ProtocolError(label + "unknown link_level " + std::to_string(w.link_level));
  }
  if (!std::isfinite(w.link_loss) || w.link_loss < 0 || w.link_loss > 1) {
    throw ProtocolError(label + "link_loss " + std::to_string(w.link_loss) + " is not in [0, 1]");
  }
  for (const auto& [name, value] :
       {std::pair{"link_round_trip_us", w.link_round_trip_us}, std::pair{"link_jitter_us", w.link_jitter_us},
        std::pair{"link_late", w.link_late}, std::pair{"link_expired", w.link_expired}}) {
    if (value < 0) throw ProtocolError(label + name + " " + std::to_string(value) + " is negative");
  }
  s.link = {.client_id = w.link_client_id,
            .level = static_cast<LinkState::Level>(w.link_level),
            .round_trip = DurationFromWireMicros(w.link_round_trip_us, label + "link_round_trip_us"),
            .jitter = DurationFromWireMicros(w.link_jitter_us, label + "link_jitter_us"),
            .loss = w.link_loss,
            .late = w.link_late,
            .expired = w.link_expired};
  return s;
}

robotalk_msgs::robot_state_t ToWire(const StateSample& s) {
  robotalk_msgs::robot_state_t w{};
  w.server_time_us = ToWireMicros(s.server_time);
  w.period_us = ToWireMicros(s.period);
  w.sample = s.sample;
  w.robot = s.robot;
  w.config_hash = static_cast<std::int64_t>(s.config_hash);
  w.panic = s.panic;
  w.moving = s.moving;
  if (s.velocities.size() != s.positions.size() || s.efforts.size() != s.positions.size()) {
    throw ProtocolError("robot_state '" + s.robot + "': " + std::to_string(s.positions.size()) +
                        " positions, " + std::to_string(s.velocities.size()) + " velocities, " +
                        std::to_string(s.efforts.size()) + " efforts (must be equal)");
  }
  w.num_dofs = static_cast<std::int32_t>(s.positions.size());
  w.position = s.positions;
  w.velocity = s.velocities;
  w.effort = s.efforts;
  w.base[0] = s.base.x;
  w.base[1] = s.base.y;
  w.base[2] = s.base.theta;
  w.base[3] = s.base.v;
  w.base[4] = s.base.omega;
  w.num_frames = static_cast<std::int32_t>(s.frame_poses.size());
  for (const PoseValues& p : s.frame_poses) w.frame_poses.emplace_back(p.begin(), p.end());
  w.link_client_id = s.link.client_id;
  w.link_level = static_cast<std::int8_t>(s.link.level);
  w.link_round_trip_us = ToWireMicros(s.link.round_trip);
  w.link_jitter_us = ToWireMicros(s.link.jitter);
  w.link_loss = s.link.loss;
  w.link_late = s.link.late;
  w.link_expired = s.link.expired;
  return w;
}

robotalk_msgs::package_t DecodePackage(std::span<const std::uint8_t> bytes) {
  return DecodeChecked<robotalk_msgs::package_t>(bytes, "DecodePackage", kMaxLcmMessageBytes, &ScanPackage);
}

robotalk_msgs::reply_package_t DecodeReplyPackage(std::span<const std::uint8_t> bytes) {
  return DecodeChecked<robotalk_msgs::reply_package_t>(bytes, "DecodeReplyPackage", kMaxLcmMessageBytes,
                                                       &ScanReplyPackage);
}

std::int8_t CheckedPanicStatus(const robotalk_msgs::reply_package_t& p) {
  using R = robotalk_msgs::reply_package_t;
  if (p.panic_status != R::PANIC_NONE && p.panic_status != R::PANIC_TAKEN &&
      p.panic_status != R::PANIC_REFUSED) {
    throw ProtocolError("reply package: unknown panic_status " + std::to_string(p.panic_status));
  }
  return p.panic_status;
}

robotalk_msgs::robot_state_t DecodeRobotState(std::span<const std::uint8_t> bytes) {
  // A keyed server's signature suffix: verified (or not) by the caller.
  return DecodeChecked<robotalk_msgs::robot_state_t>(WithoutSignature(bytes), "DecodeRobotState",
                                                     kMaxLcmMessageBytes, &ScanRobotState);
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
    if (!TryDurationFromWireMicros(h.playback_duration_us)) {
      return "package: playback_duration_us " + std::to_string(h.playback_duration_us) +
             " us is out of range";
    }
    if (h.playback_id == 0) return "package: PLAYBACK id 0 is reserved";
  }
  if (h.interpolation < robotalk_msgs::package_header_t::INTERPOLATION_STEP ||
      h.interpolation > robotalk_msgs::package_header_t::INTERPOLATION_QUINTIC) {
    return "package: unknown interpolation " + std::to_string(h.interpolation) +
           " (0 step, 1 linear, 2 cubic, 3 quintic)";
  }
  if (h.max_late_us < robotalk_msgs::package_header_t::MAX_LATE_NEVER) {
    return "package: max_late_us " + std::to_string(h.max_late_us) +
           " is negative (0 = the server's default, -1 = never)";
  }
  if (h.max_late_us > 0 && !TryDurationFromWireMicros(h.max_late_us)) {
    return "package: max_late_us " + std::to_string(h.max_late_us) + " us is out of range";
  }
  if (h.round_trip_us < 0 || !TryDurationFromWireMicros(h.round_trip_us)) {
    return "package: round_trip_us " + std::to_string(h.round_trip_us) + " is negative or out of range";
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
