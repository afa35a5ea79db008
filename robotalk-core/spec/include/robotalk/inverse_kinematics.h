// Inverse kinematics of a control frame: the joint positions that put a
// RobotModel's control frame at a world pose. Pure maths, no I/O; the
// kinematic and ode drivers solve FRAME_SETPOINT with it.
//
// Method: damped least squares on the frame's geometric Jacobian
// (Kinematics::FrameJacobian), from a starting q and given root poses:
//   e  = [p_goal - p; angle-axis(R_goal R^T)]           (m; rad)
//   dq = J^T (J J^T + lambda^2 I)^-1 e,  lambda = kDamping
// with only the dofs of the mask moving (other columns of J are zero), a mimic
// dof's column added to its leader's (mimics follow their leaders), the step
// capped at kMaxStep (norm of dq, rad or m), the position limits enforced and
// the mimics re-applied after every step. The solver keeps the best q seen by
// the cost |position error| + kMetrePerRad * |orientation error| and stops
// after kMaxIterations iterations, kPatience iterations without improvement,
// or an exact hit (both errors below 1e-7). A solution is within tolerance
// when its position error is <= kPositionTolerance (1 mm) and its
// orientation error <= kOrientationTolerance (0.01 rad). Out of reach, the
// best q is the closest pose found (a local optimum: DLS is not global).
//
// Units: metres, radians, world coordinates; q in RobotModel dof order.
//
// Thread safety: an InverseKinematics object is not thread-safe (Solve()
// writes its buffers); use one per thread. Const methods may be called
// concurrently with each other. All buffers (q, step, Jacobian, Kinematics
// poses, per-frame default masks) are allocated in the constructor; Solve()
// allocates only the 6×N matrix that Kinematics::FrameJacobian returns, once
// per iteration (at most kMaxIterations), and the message of an exception.
//
// Errors: Solve() throws robotalk::Error naming the argument and the
// bad value (q size or non-finite entry, mask size, root-pose count,
// non-finite goal, zero quaternion), and LookupError (error.h) for a frame
// index the model does not have.
//
// Copy/move: neither (refers to the model and owns a Kinematics that does).
#pragma once

#include "robotalk/dof_table.h"
#include "robotalk/kinematics.h"
#include "robotalk/robot_model.h"

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <span>
#include <vector>

namespace robotalk {

class InverseKinematics {
 public:
  /// Iteration cap per Solve().
  static constexpr int kMaxIterations = 200;
  /// Iterations without a better pose after which Solve() gives up.
  static constexpr int kPatience = 30;
  /// Within tolerance: position error <= 1 mm and orientation error <= 0.01 rad.
  static constexpr double kPositionTolerance = 1e-3;
  static constexpr double kOrientationTolerance = 1e-2;
  /// Damping lambda of the least-squares step (m or rad).
  static constexpr double kDamping = 0.05;
  /// Largest step per iteration: norm of dq, rad or m.
  static constexpr double kMaxStep = 0.3;
  /// Weight of the orientation error in the cost that picks the best pose, m/rad.
  static constexpr double kMetrePerRad = 0.1;

  /// What Solve() found. The joint positions are in solution().
  struct Result {
    /// Distance from the frame's origin to the goal position at the best q, m.
    double position_error = 0;
    /// Angle of the rotation from the frame's orientation to the goal, rad.
    double orientation_error = 0;
    /// position_error <= kPositionTolerance && orientation_error <= kOrientationTolerance.
    bool within_tolerance = false;
    /// Iterations run (each one forward kinematics + at most one step).
    int iterations = 0;
  };

  /// `model` must outlive this object.
  explicit InverseKinematics(const RobotModel& model);
  InverseKinematics(const InverseKinematics&) = delete;
  InverseKinematics& operator=(const InverseKinematics&) = delete;

  /// Moves control frame `frame` toward the world pose (`position`,
  /// `orientation`; the quaternion is normalised) starting from `q_start`
  /// (size num_dofs()). `root_poses`: one world pose per RobotModel::roots()
  /// entry, or empty for the model's (as Kinematics::Update). `mask`: one
  /// entry per dof, non-zero = the solver may move it; empty = default_mask().
  /// Mimic dofs are never moved on their own: they follow their leaders
  /// whatever the mask says. Dofs outside the mask keep their start value,
  /// except that every dof is clamped into its position limits.
  Result Solve(int frame, const Eigen::Vector3d& position, const Eigen::Quaterniond& orientation,
               const Eigen::Ref<const Eigen::VectorXd>& q_start,
               std::span<const Eigen::Isometry3d> root_poses = {}, std::span<const std::uint8_t> mask = {});

  /// The best q of the last Solve() (size num_dofs(); zeros before the
  /// first). Within the position limits, mimics applied. Overwritten by the
  /// next Solve().
  const Eigen::VectorXd& solution() const { return best_; }

  /// The dofs a frame's IK moves by default: those of the joints between the
  /// frame's link and its root that accept set-points (ServoType::kSetPoint),
  /// mimic joints excluded. One entry per dof, 1 = movable.
  std::span<const std::uint8_t> default_mask(int frame) const;
  /// True if default_mask(frame) has a movable dof (else FRAME_SETPOINT is NA).
  bool HasMovableDofs(int frame) const;

  const RobotModel& model() const { return model_; }

 private:
  const RobotModel& model_;
  Kinematics kin_;
  DofTable dofs_;                                         // per dof: limits, mimic leader
  std::vector<std::vector<std::uint8_t>> default_masks_;  // per frame
  // Scratch.
  Eigen::VectorXd q_, best_, dq_;
  Jacobian jac_;
};

}  // namespace robotalk
