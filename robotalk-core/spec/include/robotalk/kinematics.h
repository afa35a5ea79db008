// Forward kinematics, control-frame Jacobians and centre of mass of a
// RobotModel, with Eigen.
//
// Thread safety: a Kinematics object is not thread-safe (Update() writes its
// buffers); use one per thread. All buffers are allocated in the constructor,
// so Update() and the pose accessors do not allocate (except to build the
// message of an exception). The Jacobian functions return a new matrix.
//
// Errors: Update() throws robotalk::Error for bad input; the accessors
// throw LookupError (error.h) for an index the model does not have.
#pragma once

#include "robotalk/robot_model.h"

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <span>
#include <vector>

namespace robotalk {

/// 6×N geometric Jacobian: rows 0-2 the linear velocity of the frame origin,
/// rows 3-5 the angular velocity, both in world coordinates; one column per
/// dof of the model (N = RobotModel::num_dofs()). Only dofs of joints between
/// the point's link and its root have non-zero columns: a revolute dof gives
/// [w × (p - o); w], a prismatic one [w; 0], with w its world axis and o a point
/// on that axis. Every dof is treated as independent: for a mimic joint, add
/// multiplier × its column to its leader's column to get the velocity in terms
/// of the leader alone.
using Jacobian = Eigen::Matrix<double, 6, Eigen::Dynamic>;

class Kinematics {
 public:
  /// `model` must outlive this object. Poses start at q = 0.
  explicit Kinematics(const RobotModel& model);

  /// Computes every link pose for joint positions `q` (size num_dofs(), in
  /// dof_offset order). `root_poses`, if not empty, gives one world pose per
  /// RobotModel::roots() entry (same order); otherwise the model's are used.
  /// Throws robotalk::Error naming the bad size, the non-finite entry or
  /// the bad root-pose count. Pass a vector or a contiguous block: an Eigen
  /// expression would be evaluated into a temporary, which allocates.
  void Update(const Eigen::Ref<const Eigen::VectorXd>& q, std::span<const Eigen::Isometry3d> root_poses = {});

  /// World pose of a link's frame (not its COM) for the last Update().
  /// The reference stays valid for the object's lifetime.
  const Eigen::Isometry3d& link_pose(int link) const;
  /// World pose of a control frame for the last Update().
  Eigen::Isometry3d frame_pose(int frame) const;
  /// Geometric Jacobian of a control frame's origin (see Jacobian).
  Jacobian FrameJacobian(int frame) const;
  /// Geometric Jacobian of a point fixed to `link`, given in the link frame.
  Jacobian PointJacobian(int link, const Eigen::Vector3d& point_in_link) const;
  /// Whole-body centre of mass in the world, m. Zero vector if the robot is massless.
  Eigen::Vector3d CenterOfMass() const;

  const RobotModel& model() const { return model_; }

 private:
  const RobotModel& model_;
  // Per joint, the constant parts of X_parent_child either side of the dofs:
  // Tr(com_p + inboard) * rest, and Tr(-(com_c + outboard)).
  std::vector<Eigen::Isometry3d> joint_before_dofs_, joint_after_dofs_;
  // Per RobotModel::roots() entry, its model pose.
  std::vector<Eigen::Isometry3d> default_root_poses_;
  std::vector<Eigen::Isometry3d> link_poses_;
  // Per dof, for the Jacobian: world axis and a point on it.
  std::vector<Eigen::Vector3d> dof_axes_, dof_points_;
};

/// Fills the dofs of mimic joints from their leaders: q[m] = k * q[leader] + c.
/// Throws robotalk::Error if q.size() != model.num_dofs().
void ApplyMimics(const RobotModel& model, Eigen::Ref<Eigen::VectorXd> q);

}  // namespace robotalk
