// A RobotDaemon state sample as the wire's robot_state_t.
// TODO(state codec): moves into the codec with the C++ state sample type.
#pragma once

#include "robot_daemon.h"
#include "robotalk_msgs/robot_state_t.hpp"

#include <string>

namespace robotalk {

inline robotalk_msgs::robot_state_t ToStateSample(const std::string& robot, std::uint64_t config_hash,
                                                  const RobotSample& s) {
  robotalk_msgs::robot_state_t msg{};
  msg.server_time_us = ToWireMicros(s.time);
  msg.period_us = ToWireMicros(s.period);
  msg.sample = s.sample;
  msg.robot = robot;
  msg.config_hash = static_cast<std::int64_t>(config_hash);
  msg.panic = s.panic;
  msg.moving = s.moving;
  msg.num_dofs = static_cast<std::int32_t>(s.position.size());
  msg.position.assign(s.position.data(), s.position.data() + s.position.size());
  msg.velocity.assign(s.velocity.data(), s.velocity.data() + s.velocity.size());
  msg.effort.assign(s.effort.data(), s.effort.data() + s.effort.size());
  for (int i = 0; i < 5; ++i) msg.base[i] = s.base[static_cast<std::size_t>(i)];
  if (s.frames_valid) {
    msg.num_frames = static_cast<std::int32_t>(s.frame_poses.size() / 7);
    for (std::size_t f = 0; f < s.frame_poses.size(); f += 7) {
      msg.frame_poses.emplace_back(s.frame_poses.begin() + static_cast<std::ptrdiff_t>(f),
                                   s.frame_poses.begin() + static_cast<std::ptrdiff_t>(f + 7));
    }
  }
  return msg;
}

}  // namespace robotalk
