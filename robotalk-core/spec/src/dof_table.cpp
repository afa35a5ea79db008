#include "robotalk/dof_table.h"

namespace robotalk {

DofTable::DofTable(const RobotModel& model) {
  const int n = model.num_dofs();
  for (Eigen::VectorXd* v : {&lower, &upper, &velocity, &effort}) v->setZero(n);
  mimic_leader.assign(static_cast<std::size_t>(n), -1);
  mimic_multiplier.assign(static_cast<std::size_t>(n), 0.0);
  mimic_offset.assign(static_cast<std::size_t>(n), 0.0);
  joint_of.assign(static_cast<std::size_t>(n), -1);
  const auto joints = model.joints();
  for (int j = 0; j < static_cast<int>(joints.size()); ++j) {
    const Joint& joint = joints[static_cast<std::size_t>(j)];
    for (std::size_t k = 0; k < joint.dofs.size(); ++k) {
      const int i = model.dof_offset(j) + static_cast<int>(k);
      const DofLimits& lim = joint.dofs[k].limits;
      lower[i] = lim.lower;
      upper[i] = lim.upper;
      velocity[i] = lim.velocity;
      effort[i] = lim.effort;
      joint_of[static_cast<std::size_t>(i)] = j;
    }
    if (joint.mimic) {  // RobotModel guarantees a 1-dof joint and leader
      const auto i = static_cast<std::size_t>(model.dof_offset(j));
      mimic_leader[i] = model.dof_offset(joint.mimic->leader_joint);
      mimic_multiplier[i] = joint.mimic->multiplier;
      mimic_offset[i] = joint.mimic->offset;
    }
  }
}

}  // namespace robotalk
