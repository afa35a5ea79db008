#include "robotalk/kinematics.h"

#include "robotalk/error.h"

#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>

namespace robotalk {
namespace {

Eigen::Isometry3d Translation(const Eigen::Vector3d& v) {
  Eigen::Isometry3d x = Eigen::Isometry3d::Identity();
  x.translation() = v;
  return x;
}

// Only reached on the error path, so building strings here is fine.
[[noreturn]] void BadArgument(const RobotModel& model, const std::string& what) {
  throw Error("Kinematics::Update (robot '" + model.name() + "'): " + what);
}

}  // namespace

Kinematics::Kinematics(const RobotModel& model)
    : model_(model),
      link_poses_(model.links().size(), Eigen::Isometry3d::Identity()),
      dof_axes_(static_cast<size_t>(model.num_dofs()), Eigen::Vector3d::Zero()),
      dof_points_(static_cast<size_t>(model.num_dofs()), Eigen::Vector3d::Zero()) {
  // The constant ends of every joint transform, so that Update() only composes
  // the q-dependent middle: Tr(com_p + inboard) * rest ... Tr(-(com_c + outboard)).
  joint_before_dofs_.reserve(model.joints().size());
  joint_after_dofs_.reserve(model.joints().size());
  for (const Joint& joint : model.joints()) {
    const Link& parent = model.link(joint.parent_link);
    const Link& child = model.link(joint.child_link);
    Eigen::Isometry3d before = Translation(parent.com + joint.inboard);
    before.rotate(joint.rest.normalized());
    joint_before_dofs_.push_back(before);
    joint_after_dofs_.push_back(Translation(-(child.com + joint.outboard)));
  }
  for (const RootLink& root : model.roots()) default_root_poses_.push_back(root.pose_in_world.ToIsometry());
  Update(Eigen::VectorXd::Zero(model.num_dofs()));
}

void Kinematics::Update(const Eigen::Ref<const Eigen::VectorXd>& q,
                        std::span<const Eigen::Isometry3d> root_poses) {
  if (q.size() != model_.num_dofs()) {
    BadArgument(model_, "q has " + std::to_string(q.size()) + " entries, expected " +
                            std::to_string(model_.num_dofs()) + " (one per dof)");
  }
  for (Eigen::Index i = 0; i < q.size(); ++i) {
    if (!std::isfinite(q[i])) {
      std::ostringstream value;
      value << q[i];
      BadArgument(model_, "q[" + std::to_string(i) + "] is " + value.str());
    }
  }
  const auto roots = model_.roots();
  if (!root_poses.empty() && root_poses.size() != roots.size()) {
    BadArgument(model_, std::to_string(root_poses.size()) + " root poses given, expected " +
                            std::to_string(roots.size()) + " (one per root link) or none");
  }
  for (size_t r = 0; r < root_poses.size(); ++r) {
    if (!root_poses[r].matrix().allFinite()) {
      BadArgument(model_, "root pose " + std::to_string(r) + " (link '" + model_.link(roots[r].link).name +
                              "') is not finite");
    }
  }

  for (size_t r = 0; r < roots.size(); ++r) {
    link_poses_[static_cast<size_t>(roots[r].link)] =
        root_poses.empty() ? default_root_poses_[r] : root_poses[r];
  }
  const auto joints = model_.joints();
  for (const int j : model_.topological_joint_order()) {
    const auto ju = static_cast<size_t>(j);
    const Joint& joint = joints[ju];
    Eigen::Isometry3d x = link_poses_[static_cast<size_t>(joint.parent_link)] * joint_before_dofs_[ju];
    auto dof = static_cast<size_t>(model_.dof_offset(j));
    for (const Dof& d : joint.dofs) {
      // Each dof acts in the frame left by the previous ones: record its world
      // axis and a point on it before applying it.
      dof_axes_[dof] = x.linear() * d.axis;
      dof_points_[dof] = x.translation();
      const double qd = q[static_cast<Eigen::Index>(dof)];
      if (d.type == DofType::kRevolute) {
        x.rotate(Eigen::AngleAxisd(qd, d.axis));
      } else {
        x.translate(qd * d.axis);
      }
      ++dof;
    }
    link_poses_[static_cast<size_t>(joint.child_link)] = x * joint_after_dofs_[ju];
  }
}

const Eigen::Isometry3d& Kinematics::link_pose(int link) const {
  model_.link(link);  // throws LookupError for a bad index
  return link_poses_[static_cast<size_t>(link)];
}

Eigen::Isometry3d Kinematics::frame_pose(int frame) const {
  const ControlFrame& f = model_.frame(frame);
  return link_pose(f.parent_link) * f.pose_in_link.ToIsometry();
}

Jacobian Kinematics::FrameJacobian(int frame) const {
  const ControlFrame& f = model_.frame(frame);
  return PointJacobian(f.parent_link, f.pose_in_link.translation);
}

Jacobian Kinematics::PointJacobian(int link, const Eigen::Vector3d& point_in_link) const {
  const Eigen::Vector3d p = link_pose(link) * point_in_link;
  Jacobian jac = Jacobian::Zero(6, model_.num_dofs());
  for (int l = link, j = model_.parent_joint(l); j >= 0;
       l = model_.joint(j).parent_link, j = model_.parent_joint(l)) {
    const Joint& joint = model_.joint(j);
    for (int k = 0; k < static_cast<int>(joint.dofs.size()); ++k) {
      const int dof = model_.dof_offset(j) + k;
      const Eigen::Vector3d& w = dof_axes_[static_cast<size_t>(dof)];
      if (joint.dofs[static_cast<size_t>(k)].type == DofType::kRevolute) {
        jac.col(dof) << w.cross(p - dof_points_[static_cast<size_t>(dof)]), w;
      } else {
        jac.col(dof) << w, Eigen::Vector3d::Zero();
      }
    }
  }
  return jac;
}

Eigen::Vector3d Kinematics::CenterOfMass() const {
  Eigen::Vector3d weighted = Eigen::Vector3d::Zero();
  double mass = 0;
  const auto links = model_.links();
  for (size_t i = 0; i < links.size(); ++i) {
    weighted += links[i].mass * (link_poses_[i] * links[i].com);
    mass += links[i].mass;
  }
  return mass > 0 ? Eigen::Vector3d(weighted / mass) : Eigen::Vector3d::Zero();
}

void ApplyMimics(const RobotModel& model, Eigen::Ref<Eigen::VectorXd> q) {
  if (q.size() != model.num_dofs()) {
    throw Error("ApplyMimics (robot '" + model.name() + "'): q has " + std::to_string(q.size()) +
                " entries, expected " + std::to_string(model.num_dofs()));
  }
  const auto joints = model.joints();
  for (int j = 0; j < static_cast<int>(joints.size()); ++j) {
    const auto& mimic = joints[static_cast<size_t>(j)].mimic;
    if (!mimic) continue;
    // Leaders are never mimics themselves (RobotModel validates it), so the
    // order of this loop does not matter.
    q[model.dof_offset(j)] = mimic->multiplier * q[model.dof_offset(mimic->leader_joint)] + mimic->offset;
  }
}

}  // namespace robotalk
