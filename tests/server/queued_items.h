// Items as the ServerDaemon hands them to a RobotDaemon, for RobotDaemon
// tests: a motion command, a trajectory waypoint and a joint-state query of
// one client; and a robot's state at rest (what a planner starts from).
#pragma once

#include "robotalk/driver.h"
#include "robotalk/robot_model.h"
#include "scheduler.h"
#include "support/test_clients.h"

#include <algorithm>
#include <cstdint>
#include <utility>
#include <vector>

namespace robotalk::testing {

inline constexpr std::int64_t kItemClient = kAlice;  ///< the client of Motion() and JointStateQuery()

inline QueuedItem Motion(CommandId id, CommandType type, std::vector<double> values, int target = -1) {
  QueuedItem item;
  item.client_id = kItemClient;
  item.command.id = id;
  item.command.type = type;
  item.command.target = target;
  item.command.num_values = static_cast<int>(values.size());
  std::copy(values.begin(), values.end(), item.command.values.begin());
  return item;
}

/// A waypoint of an interpolated package (QueuedItem::is_waypoint()): a
/// JOINT_SETPOINT (or `type`) of `target` due at `at`.
inline QueuedItem Waypoint(CommandId id, int target, TimePoint at, std::vector<double> values,
                           Interpolation interpolation = Interpolation::kCubic,
                           std::int64_t client = kItemClient,
                           CommandType type = CommandType::kJointSetPoint) {
  QueuedItem item = Motion(id, type, std::move(values), target);
  item.client_id = client;
  item.has_start_time = true;
  item.start = at;
  item.interpolation = interpolation;
  return item;
}

/// A state query of kItemClient (JOINT_STATE, BASE_POSE, ...).
inline QueuedItem StateQuery(CommandId id, QueryType type) {
  QueuedItem item;
  item.client_id = kItemClient;
  item.is_query = true;
  item.query = type;
  item.command.id = id;
  return item;
}

inline QueuedItem JointStateQuery(CommandId id) { return StateQuery(id, QueryType::kJointState); }

/// Every dof at 0, at rest.
inline RobotState Rest(const RobotModel& m) {
  RobotState s;
  s.position = Eigen::VectorXd::Zero(m.num_dofs());
  s.velocity = Eigen::VectorXd::Zero(m.num_dofs());
  s.effort = Eigen::VectorXd::Zero(m.num_dofs());
  return s;
}

}  // namespace robotalk::testing
