// Small helpers shared by robot_service.cpp and robot_service_modes.cpp.
#pragma once

#include "robotalk/command.h"

#include <Eigen/Geometry>
#include <string>
#include <vector>

namespace robotalk::service_detail {

inline Reply MakeReply(CommandId id, Signal signal, std::string message, TimePoint now) {
  Reply r;
  r.id = id;
  r.signal = signal;
  r.message = std::move(message);
  r.exec_time = now;
  return r;
}

/// Appends x y z qw qx qy qz.
inline void AppendPose(const Eigen::Isometry3d& x, std::vector<double>& out) {
  const Eigen::Quaterniond q(x.linear());
  out.insert(out.end(),
             {x.translation().x(), x.translation().y(), x.translation().z(), q.w(), q.x(), q.y(), q.z()});
}

}  // namespace robotalk::service_detail
