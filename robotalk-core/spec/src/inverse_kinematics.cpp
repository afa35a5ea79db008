#include "robotalk/inverse_kinematics.h"

#include "robotalk/error.h"

#include <Eigen/Cholesky>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace robotalk {
namespace {

std::string Where(const RobotModel& model) {
  return "InverseKinematics::Solve (robot '" + model.name() + "'): ";
}

}  // namespace

InverseKinematics::InverseKinematics(const RobotModel& model) : model_(model), kin_(model), dofs_(model) {
  const int n = model_.num_dofs();
  for (Eigen::VectorXd* v : {&q_, &best_, &dq_}) v->setZero(n);
  jac_.setZero(6, n);
  // Per control frame, the set-point joints on the path to its root. Mimic
  // joints are left out: they follow their leaders.
  for (std::size_t f = 0; f < model_.frames().size(); ++f) {
    std::vector<std::uint8_t> mask(static_cast<size_t>(n), 0);
    for (int j : model_.frame_chain(static_cast<int>(f))) {
      const Joint& joint = model_.joint(j);
      if (joint.mimic || !joint.servo_types.Has(ServoType::kSetPoint)) continue;
      for (size_t k = 0; k < joint.dofs.size(); ++k) mask[static_cast<size_t>(model_.dof_offset(j)) + k] = 1;
    }
    default_masks_.push_back(std::move(mask));
  }
}

std::span<const std::uint8_t> InverseKinematics::default_mask(int frame) const {
  model_.frame(frame);  // throws LookupError for a bad index
  return default_masks_[static_cast<size_t>(frame)];
}

bool InverseKinematics::HasMovableDofs(int frame) const {
  for (std::uint8_t m : default_mask(frame)) {
    if (m) return true;
  }
  return false;
}

InverseKinematics::Result InverseKinematics::Solve(int frame, const Eigen::Vector3d& position,
                                                   const Eigen::Quaterniond& orientation,
                                                   const Eigen::Ref<const Eigen::VectorXd>& q_start,
                                                   std::span<const Eigen::Isometry3d> root_poses,
                                                   std::span<const std::uint8_t> mask) {
  model_.frame(frame);  // throws LookupError for a bad index
  const Eigen::Index n = q_.size();
  if (q_start.size() != n) {
    throw Error(Where(model_) + "q_start has " + std::to_string(q_start.size()) + " entries, expected " +
                std::to_string(n));
  }
  if (mask.empty()) mask = default_masks_[static_cast<size_t>(frame)];
  if (static_cast<Eigen::Index>(mask.size()) != n) {
    throw Error(Where(model_) + "mask has " + std::to_string(mask.size()) + " entries, expected " +
                std::to_string(n));
  }
  if (!position.allFinite()) {
    throw Error(Where(model_) + "goal position is not finite");
  }
  const double norm = orientation.norm();
  if (!std::isfinite(norm) || norm < 1e-9) {
    throw Error(Where(model_) + "goal quaternion has norm " + std::to_string(norm) +
                ", expected a unit quaternion");
  }
  const Eigen::Matrix3d goal_r = Eigen::Quaterniond(orientation.coeffs() / norm).toRotationMatrix();

  // Damped least squares on a copy of q (method in the header). The cost
  // that picks the best pose weighs 1 rad of orientation as 0.1 m.
  // The start is clamped into the limits with its mimics applied, as every
  // later iterate is (a no-op for a state the drivers keep within limits).
  q_ = q_start.cwiseMax(dofs_.lower).cwiseMin(dofs_.upper);
  ApplyMimics(model_, q_);
  best_ = q_;
  Result best;
  double best_cost = std::numeric_limits<double>::infinity();
  int since_best = 0, it = 0;
  for (; it < kMaxIterations && since_best < kPatience; ++it) {
    kin_.Update(q_, root_poses);
    const Eigen::Isometry3d x = kin_.frame_pose(frame);
    Eigen::Matrix<double, 6, 1> e;
    e.head<3>() = position - x.translation();
    const Eigen::AngleAxisd rot_error(goal_r * x.linear().transpose());
    e.tail<3>() = rot_error.angle() * rot_error.axis();
    const double pe = e.head<3>().norm(), re = e.tail<3>().norm();
    const double cost = pe + kMetrePerRad * re;
    if (cost < best_cost - 1e-12) {
      best_cost = cost;
      best.position_error = pe;
      best.orientation_error = re;
      best_ = q_;
      since_best = 0;
    } else {
      ++since_best;
    }
    if (pe < 1e-7 && re < 1e-7) break;

    jac_ = kin_.FrameJacobian(frame);
    for (Eigen::Index i = 0; i < n; ++i) {  // a mimic dof moves with its leader
      const int leader = dofs_.mimic_leader[static_cast<size_t>(i)];
      if (leader >= 0) jac_.col(leader) += dofs_.mimic_multiplier[static_cast<size_t>(i)] * jac_.col(i);
    }
    for (Eigen::Index i = 0; i < n; ++i) {
      if (!mask[static_cast<size_t>(i)] || dofs_.mimic_leader[static_cast<size_t>(i)] >= 0)
        jac_.col(i).setZero();
    }
    Eigen::Matrix<double, 6, 6> a;
    a.noalias() = jac_ * jac_.transpose();
    a.diagonal().array() += kDamping * kDamping;
    const Eigen::Matrix<double, 6, 1> y = a.ldlt().solve(e);
    dq_.noalias() = jac_.transpose() * y;
    const double step = dq_.norm();
    if (step > kMaxStep) dq_ *= kMaxStep / step;
    q_ += dq_;
    q_ = q_.cwiseMax(dofs_.lower).cwiseMin(dofs_.upper);
    ApplyMimics(model_, q_);
  }
  best.iterations = it;
  best.within_tolerance =
      best.position_error <= kPositionTolerance && best.orientation_error <= kOrientationTolerance;
  return best;
}

}  // namespace robotalk
