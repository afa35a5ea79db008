#include "robotalk/command.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>

namespace robotalk {
namespace {

constexpr double kQuaternionTolerance = 1e-3;

std::string Upper(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(),
                 [](unsigned char c) { return static_cast<char>(std::toupper(c)); });
  std::replace(s.begin(), s.end(), '-', '_');
  return s;
}

// A name from the wire, quoted; a long one is shown by its first bytes and
// its length, so every refusal stays short whatever a client sends (the
// server keeps refusals in its reply cache).
std::string Quote(const std::string& s) {
  constexpr std::size_t kShown = 48;
  if (s.size() <= kShown + 16) return "'" + s + "'";
  std::size_t cut = kShown;
  while (cut > 0 && (static_cast<unsigned char>(s[cut]) & 0xC0) == 0x80) --cut;  // whole UTF-8 characters
  return "'" + s.substr(0, cut) + "...' (" + std::to_string(s.size()) + " bytes)";
}

// "JOINT_SETPOINT 'neck'" or "GOTO".
std::string Label(const Command& c) {
  return c.target.empty() ? ToString(c.type) : std::string(ToString(c.type)) + " " + Quote(c.target);
}

// `dofs`: the target joint's, for a command of one value per dof.
std::optional<std::string> CheckValueCount(const Command& c, std::size_t dofs = 0) {
  const CommandTraits& t = Traits(c.type);
  if (ValueCountFits(t, c.values.size(), dofs)) return std::nullopt;
  const std::string expected = t.min_values == kValuesPerDof ? std::to_string(dofs) + " value" +
                                                                   (dofs == 1 ? "" : "s") + " (one per dof)"
                                                             : ValueCountText(t);
  return Label(c) + ": expected " + expected + ", got " + std::to_string(c.values.size());
}

std::optional<std::string> CheckFinite(const Command& c, const std::vector<double>& values,
                                       const char* noun) {
  for (size_t i = 0; i < values.size(); ++i) {
    if (!std::isfinite(values[i])) {
      return Label(c) + ": " + noun + " " + std::to_string(i) + " is " +
             (std::isnan(values[i]) ? "NaN" : "infinite");
    }
  }
  return std::nullopt;
}

std::optional<std::string> CheckFinite(const Command& c) {
  if (auto bad = CheckFinite(c, c.values, "value")) return bad;
  if (auto bad = CheckFinite(c, c.velocities, "velocity")) return bad;
  return CheckFinite(c, c.accelerations, "acceleration");
}

// Every number within ±kMaxCommandMagnitude (checked after CheckFinite and the
// target's own checks, so a GOTO far away still names its workspace bound).
std::optional<std::string> CheckMagnitude(const Command& c) {
  const auto check = [&c](const std::vector<double>& values, const char* noun) -> std::optional<std::string> {
    for (std::size_t i = 0; i < values.size(); ++i) {
      if (std::abs(values[i]) <= kMaxCommandMagnitude) continue;
      char text[96];
      std::snprintf(text, sizeof text, ": %s %zu is %.4g, beyond ±%.0e", noun, i, values[i],
                    kMaxCommandMagnitude);
      return Label(c) + text;
    }
    return std::nullopt;
  };
  if (auto bad = check(c.values, "value")) return bad;
  if (auto bad = check(c.velocities, "velocity")) return bad;
  return check(c.accelerations, "acceleration");
}

// A waypoint's velocities and accelerations: none, or WaypointRateCount each.
std::optional<std::string> CheckRateCount(const Command& c, std::size_t dofs = 0) {
  const std::size_t expected = WaypointRateCount(c.type, dofs);
  const auto check = [&](const std::vector<double>& v, const char* noun) -> std::optional<std::string> {
    if (v.empty() || v.size() == expected) return std::nullopt;
    if (expected == 0)
      return Label(c) + ": takes no " + noun + " (only a JOINT_SETPOINT or FRAME_SETPOINT waypoint does)";
    return Label(c) + ": expected 0 or " + std::to_string(expected) + " " + noun + ", got " +
           std::to_string(v.size());
  };
  if (auto bad = check(c.velocities, "velocities")) return bad;
  return check(c.accelerations, "accelerations");
}

// "set-point", "speed", "force": a servo type in a refusal.
const char* ServoWord(ServoType t) {
  switch (t) {
    case ServoType::kSpeed:
      return "speed";
    case ServoType::kForce:
      return "force";
    default:
      return "set-point";
  }
}

}  // namespace

const char* ToString(CommandType t) { return Traits(t).name; }

std::string ValueCountText(const CommandTraits& t) {
  if (t.min_values == kValuesPerDof) return "one value per dof";
  const auto count = [](int n, const char* names, const char* noun) {
    return std::to_string(n) + noun + (*names ? std::string(" (") + names + ")" : "");
  };
  std::string text = count(t.min_values, t.value_names, t.min_values == 1 ? " value" : " values");
  if (t.max_values != t.min_values) text += " or " + count(t.max_values, t.max_value_names, "");
  return text;
}

const char* ToString(QueryType t) {
  switch (t) {
    case QueryType::kConfig:
      return "CONFIG";
    case QueryType::kJointState:
      return "JOINT_STATE";
    case QueryType::kLinkPoses:
      return "LINK_POSES";
    case QueryType::kFramePoses:
      return "FRAME_POSES";
    case QueryType::kBasePose:
      return "BASE_POSE";
    case QueryType::kClock:
      return "CLOCK";
    case QueryType::kStateStream:
      return "STATE_STREAM";
    case QueryType::kStateStreamCancel:
      return "STATE_STREAM_CANCEL";
    case QueryType::kCommandStatus:
      return "COMMAND_STATUS";
    case QueryType::kServerCounters:
      return "SERVER_COUNTERS";
  }
  return "UNKNOWN_QUERY";
}

std::optional<CommandType> ParseCommandType(const std::string& name) {
  const std::string n = Upper(name);
  for (const CommandTraits& t : kCommandTraits) {
    if (n == t.name || (t.alias && n == t.alias)) return t.type;
  }
  return std::nullopt;
}

std::optional<QueryType> ParseQueryType(const std::string& name) {
  const std::string n = Upper(name);
  for (int t = static_cast<int>(QueryType::kConfig); t <= static_cast<int>(QueryType::kServerCounters); ++t) {
    auto type = static_cast<QueryType>(t);
    if (n == ToString(type)) return type;
  }
  return std::nullopt;
}

std::string ToString(const StartTime& s) {
  switch (s.kind()) {
    case StartTime::Kind::kNow:
      return "now";
    case StartTime::Kind::kAt:
      return "at " + std::to_string(ToSeconds(s.time()->time_since_epoch())) + " s";
    case StartTime::Kind::kAfter:
      return "after " + std::to_string(ToSeconds(*s.offset())) + " s";
  }
  return "?";
}

namespace {

// The text of what is wrong with `c`; `signal` gets the signal to answer with.
std::optional<std::string> CommandProblem(const RobotModel& model, const Command& c,
                                          const CommandLimits& limits, Signal* signal) {
  *signal = Signal::kError;
  const CommandTraits* traits = FindCommandTraits(static_cast<int>(c.type));
  if (!traits) return "unknown command type " + std::to_string(static_cast<int>(c.type));
  if (auto bad = CheckFinite(c)) return bad;
  switch (traits->target) {
    case CommandTarget::kJoint: {
      auto j = model.FindJoint(c.target);
      if (!j)
        return std::string(traits->name) + ": robot " + Quote(model.name()) + " has no joint named " +
               Quote(c.target);
      const Joint& joint = model.joint(*j);
      if (joint.dofs.empty()) return Label(c) + ": the joint is fixed (0 dofs)";
      if (auto bad = CheckValueCount(c, joint.dofs.size())) return bad;
      if (auto bad = CheckRateCount(c, joint.dofs.size())) return bad;
      if (joint.mimic) {
        *signal = Signal::kNa;
        return Label(c) + ": the joint follows " + Quote(model.joint(joint.mimic->leader_joint).name) +
               " (mimic)";
      }
      if (traits->servo != ServoType::kNone && !joint.servo_types.Has(traits->servo)) {
        *signal = Signal::kNa;
        return Label(c) + ": the joint accepts only " + joint.servo_types.ToString() + " commands";
      }
      return std::nullopt;
    }
    case CommandTarget::kFrame: {
      auto f = model.FindFrame(c.target);
      if (!f)
        return std::string(traits->name) + ": robot " + Quote(model.name()) + " has no control frame named " +
               Quote(c.target);
      if (auto bad = CheckValueCount(c)) return bad;
      if (auto bad = CheckRateCount(c)) return bad;
      // A frame's values are a pose: x y z and a unit quaternion.
      const double norm = std::sqrt(c.values[3] * c.values[3] + c.values[4] * c.values[4] +
                                    c.values[5] * c.values[5] + c.values[6] * c.values[6]);
      if (std::abs(norm - 1) > kQuaternionTolerance) {
        return Label(c) + ": orientation quaternion has norm " + std::to_string(norm) + ", expected 1";
      }
      if (traits->servo != ServoType::kNone && !model.frame(*f).servo_types.Has(traits->servo)) {
        *signal = Signal::kNa;
        return Label(c) + ": the control frame accepts no " + ServoWord(traits->servo) + " commands";
      }
      return std::nullopt;
    }
    case CommandTarget::kBase: {
      if (!c.target.empty()) return Label(c) + ": a base command takes no target";
      if (auto bad = CheckValueCount(c)) return bad;
      if (auto bad = CheckRateCount(c)) return bad;
      if (model.roots().front().base == BaseType::kFixed) {
        *signal = Signal::kNa;
        return Label(c) + ": robot " + Quote(model.name()) + " has a fixed base";
      }
      if (c.type == CommandType::kGoto) {  // the workspace bound of a goal position
        const double distance = std::hypot(c.values[0], c.values[1]);
        if (!(distance <= limits.max_goto_distance)) {
          char text[200];
          std::snprintf(text, sizeof text,
                        "GOTO: target (%.4g, %.4g) m is %.4g m from the world origin; the bound is %.4g m",
                        c.values[0], c.values[1], distance, limits.max_goto_distance);
          return std::string(text);
        }
      }
      return std::nullopt;
    }
    case CommandTarget::kRobot:
      if (!c.target.empty()) return Label(c) + ": takes no target";
      if (auto bad = CheckRateCount(c)) return bad;
      return CheckValueCount(c);
  }
  return "unknown command type " + std::to_string(static_cast<int>(c.type));
}

std::optional<std::string> QueryProblem(const RobotModel& model, const Query& q);

}  // namespace

std::optional<Refusal> CheckCommand(const RobotModel& model, const Command& c, const CommandLimits& limits) {
  Signal signal = Signal::kError;
  if (auto problem = CommandProblem(model, c, limits, &signal)) return Refusal{signal, std::move(*problem)};
  if (auto problem = CheckMagnitude(c)) return Refusal{Signal::kError, std::move(*problem)};
  return std::nullopt;
}

std::optional<Refusal> CheckQuery(const RobotModel& model, const Query& q) {
  if (auto problem = QueryProblem(model, q)) return Refusal{Signal::kError, std::move(*problem)};
  return std::nullopt;
}

namespace {

std::optional<std::string> QueryProblem(const RobotModel& model, const Query& q) {
  if (q.type == QueryType::kStateStream && (q.period < kMinStreamPeriod || q.period > kMaxStreamPeriod)) {
    return "STATE_STREAM: period " + std::to_string(ToSeconds(q.period)) + " s is outside [" +
           std::to_string(ToSeconds(kMinStreamPeriod)) + ", " + std::to_string(ToSeconds(kMaxStreamPeriod)) +
           "] s";
  }
  if (q.target.empty()) return std::nullopt;
  switch (q.type) {
    case QueryType::kJointState:
      if (!model.FindJoint(q.target))
        return std::string("JOINT_STATE: robot ") + Quote(model.name()) + " has no joint named " +
               Quote(q.target);
      return std::nullopt;
    case QueryType::kLinkPoses:
      if (!model.FindLink(q.target))
        return std::string("LINK_POSES: robot ") + Quote(model.name()) + " has no link named " +
               Quote(q.target);
      return std::nullopt;
    case QueryType::kFramePoses:
      if (!model.FindFrame(q.target))
        return std::string("FRAME_POSES: robot ") + Quote(model.name()) + " has no control frame named " +
               Quote(q.target);
      return std::nullopt;
    default:
      return std::string(ToString(q.type)) + ": takes no target (got " + Quote(q.target) + ")";
  }
}

}  // namespace

}  // namespace robotalk
