// A model's per-dof limits and mimic couplings, in dof order (the order of
// RobotModel::dof_offset), built once so that solvers and drivers index flat
// arrays on their real-time paths instead of walking joints.
//
// Thread safety: immutable after construction.
#pragma once

#include "robotalk/robot_model.h"

#include <Eigen/Core>
#include <vector>

namespace robotalk {

struct DofTable {
  explicit DofTable(const RobotModel& model);

  int size() const { return static_cast<int>(lower.size()); }
  /// True when dof `i` follows a leader (a mimic joint's only dof).
  bool is_mimic(int i) const { return mimic_leader[static_cast<std::size_t>(i)] >= 0; }

  Eigen::VectorXd lower, upper;                        ///< position limits (rad | m; may be ±inf)
  Eigen::VectorXd velocity;                            ///< speed limits (rad/s | m/s; +inf = none given)
  Eigen::VectorXd effort;                              ///< effort limits (N·m | N; +inf = none given)
  std::vector<int> mimic_leader;                       ///< the leader's dof, or -1
  std::vector<double> mimic_multiplier, mimic_offset;  ///< q = multiplier · q_leader + offset
  std::vector<int> joint_of;                           ///< the joint each dof belongs to
};

}  // namespace robotalk
