// Whole-leg joint targets of a walking humanoid from the pelvis pose and the
// soles' poses, with the project's InverseKinematics (damped least squares,
// robotalk/inverse_kinematics.h), and the whole-body centre of mass in the
// pelvis frame (to place the pelvis under the planned CoM).
//
// LegIk keeps a copy of the model with two control frames added at the
// soles ("walk_left_sole", "walk_right_sole": the sole point below each
// ankle, axes of the foot link); each leg is solved as that frame's IK with
// the pelvis as the root pose, moving only the dofs between the pelvis and
// the foot (the frame's default mask). Solutions are warm-started from the
// previous q, so a 1 kHz walk needs a few iterations per leg.
//
// Units: m, rad, world frame. Thread safety: none (one thread).
// Allocation: the model copy and the solver's buffers in the constructor;
// Solve() allocates what InverseKinematics::Solve does (one Jacobian per
// iteration). Errors: the constructor throws Error when the feet are not
// below the pelvis in the model's tree or have no set-point dofs.
#pragma once

#include "robotalk/inverse_kinematics.h"
#include "robotalk/kinematics.h"
#include "robotalk/robot_model.h"

#include <Eigen/Geometry>

#include <array>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

namespace robotalk::walking {

class LegIk {
 public:
  /// `pelvis_link` must be the first root; `feet` the left and right foot
  /// links; `sole` the sole point in each foot link's frame.
  LegIk(const RobotModel& model, std::array<int, 2> feet, std::array<Eigen::Vector3d, 2> sole);
  LegIk(const LegIk&) = delete;
  LegIk& operator=(const LegIk&) = delete;

  /// Solves both legs so that the soles reach `soles` (world) with the
  /// pelvis at `pelvis`; the leg dofs of `q` (size num_dofs) are replaced,
  /// the others kept. Returns the larger of the two residual position errors (m).
  double Solve(const Eigen::Isometry3d& pelvis, const std::array<Eigen::Isometry3d, 2>& soles,
               Eigen::VectorXd& q);
  /// Whole-body CoM in the pelvis frame for joint positions q (m).
  Eigen::Vector3d ComInPelvis(const Eigen::VectorXd& q);
  /// The soles' poses in the pelvis frame for q.
  Eigen::Isometry3d SoleInPelvis(int side, const Eigen::VectorXd& q);
  /// Per dof, 1 = a leg dof (either leg).
  std::span<const std::uint8_t> leg_mask() const { return leg_mask_; }
  const RobotModel& model() const { return *model_; }
  /// IK iterations of the last Solve() (both legs).
  int last_iterations() const { return iterations_; }

 private:
  std::unique_ptr<RobotModel> model_;
  std::unique_ptr<InverseKinematics> ik_;
  std::unique_ptr<Kinematics> kin_;
  std::array<int, 2> frame_{-1, -1};
  std::vector<std::uint8_t> leg_mask_;
  std::vector<Eigen::Isometry3d> roots_;
  int iterations_ = 0;
};

}  // namespace robotalk::walking
