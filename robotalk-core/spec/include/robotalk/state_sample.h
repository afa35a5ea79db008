// StateSample: one sample of a robot's broadcast state (broadcast mode,
// ROBOTALK/<robot>/STATE) as a C++ value. Its wire form is robot_state_t
// (lcmtypes/robotalk_msgs/robot_state_t.lcm); the protocol library converts
// (request.h: EncodeStateSample, DecodeStateSample) and is the one place that
// validates it: a decoded sample has equal position, velocity and effort
// counts (the model's, when the reader gives it), 7 values per frame pose,
// times in range, and every value finite unless `panic` is set (then NaN or
// inf is what a broken driver reported; the server halted the robot for it).
// A plain value type: not synchronised.
#pragma once

#include "robotalk/clock.h"

#include <array>
#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

namespace robotalk {

/// x y θ v ω of a robot's first root link: m, m, rad, m/s, rad/s (world).
struct BaseState {
  double x = 0, y = 0, theta = 0, v = 0, omega = 0;
  bool operator==(const BaseState&) const = default;
};

/// A world pose as sent on the wire: x y z (m), qw qx qy qz (unit quaternion).
using PoseValues = std::array<double, 7>;

/// The link health of the session that last moved the robot (robot_state_t's
/// link_* fields; docs/server.md, Link health).
struct LinkState {
  enum class Level : std::int8_t { kUnknown = 0, kGood = 1, kDegraded = 2, kBad = 3 };
  std::int64_t client_id = 0;  ///< 0 = nobody moved the robot since the last STOP
  Level level = Level::kUnknown;
  Duration round_trip{0};    ///< as its client reports it; 0 = not yet
  Duration jitter{0};        ///< RFC 3550 inter-arrival jitter
  double loss = 0;           ///< recent fraction of its packages lost, 0..1
  std::int64_t late = 0;     ///< its commands that began more than 5 ms late
  std::int64_t expired = 0;  ///< its commands not executed past their deadline
  bool operator==(const LinkState&) const = default;
};

/// "unknown", "good", "degraded", "bad".
inline const char* ToString(LinkState::Level level) {
  switch (level) {
    case LinkState::Level::kGood:
      return "good";
    case LinkState::Level::kDegraded:
      return "degraded";
    case LinkState::Level::kBad:
      return "bad";
    case LinkState::Level::kUnknown:
      break;
  }
  return "unknown";
}

/// One line on a link for people (robotalk watch, the web view):
/// "client 503d1a2b00000001: good, round trip 12.0 ms, jitter 1.2 ms, loss
/// 0.0 %, 0 late, 0 expired"; "" when nobody moves the robot.
inline std::string LinkSummary(const LinkState& l) {
  if (l.client_id == 0) return "";
  char buf[200];
  std::snprintf(
      buf, sizeof buf,
      "client %016llx: %s, round trip %.1f ms, jitter %.1f ms, loss %.1f %%, %lld late, %lld expired",
      static_cast<unsigned long long>(l.client_id), ToString(l.level), ToSeconds(l.round_trip) * 1e3,
      ToSeconds(l.jitter) * 1e3, l.loss * 100, static_cast<long long>(l.late),
      static_cast<long long>(l.expired));
  return buf;
}

struct StateSample {
  TimePoint server_time{};  ///< when sampled, on the server clock
  Duration period{0};       ///< the stream's period when sampled
  std::int64_t sample = 0;  ///< 1, 2, 3 ... since the stream started
  std::string robot;
  std::uint64_t config_hash = 0;  ///< the description these dofs belong to
  bool panic = false;
  bool moving = false;
  std::vector<double> positions;   ///< rad | m, one per dof in the model's dof order
  std::vector<double> velocities;  ///< rad/s | m/s
  std::vector<double> efforts;     ///< N·m | N
  BaseState base;
  std::vector<PoseValues> frame_poses;  ///< one per control frame, in model order
  LinkState link;                       ///< the motion owner's link health

  bool operator==(const StateSample&) const = default;
};

}  // namespace robotalk
