// A RobotDaemon state sample as the protocol's StateSample (state_sample.h),
// which the codec puts on the wire.
#pragma once

#include "robot_daemon.h"
#include "robotalk/state_sample.h"

#include <string>

namespace robotalk {

inline StateSample ToStateSample(const std::string& robot, std::uint64_t config_hash, const RobotSample& s) {
  StateSample out;
  out.server_time = s.time;
  out.period = s.period;
  out.sample = s.sample;
  out.robot = robot;
  out.config_hash = config_hash;
  out.panic = s.panic;
  out.moving = s.moving;
  out.positions.assign(s.position.data(), s.position.data() + s.position.size());
  out.velocities.assign(s.velocity.data(), s.velocity.data() + s.velocity.size());
  out.efforts.assign(s.effort.data(), s.effort.data() + s.effort.size());
  out.base = {s.base[0], s.base[1], s.base[2], s.base[3], s.base[4]};
  if (s.frames_valid) {
    for (std::size_t f = 0; f + 7 <= s.frame_poses.size(); f += 7) {
      PoseValues pose;
      std::copy(s.frame_poses.begin() + static_cast<std::ptrdiff_t>(f),
                s.frame_poses.begin() + static_cast<std::ptrdiff_t>(f + 7), pose.begin());
      out.frame_poses.push_back(pose);
    }
  }
  return out;
}

}  // namespace robotalk
