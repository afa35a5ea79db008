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

  bool operator==(const StateSample&) const = default;
};

}  // namespace robotalk
