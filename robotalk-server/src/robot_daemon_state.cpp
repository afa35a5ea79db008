// The RobotDaemon's read-out (robot_daemon.h): what in a driver's state is
// not finite, and the broadcast state samples.
#include "robot_daemon.h"

#include <Eigen/Geometry>
#include <cmath>
#include <string>

namespace robotalk {
namespace {

std::string NotFinite(double v) { return std::isnan(v) ? "NaN" : (v > 0 ? "+inf" : "-inf"); }

}  // namespace

std::optional<std::string> NonFiniteState(const RobotModel& model, const RobotState& state) {
  // The usual case, allocation-free: everything finite.
  const auto finite = [](const Eigen::VectorXd& v) { return v.allFinite(); };
  bool roots_finite = std::isfinite(state.base_v) && std::isfinite(state.base_omega);
  for (const Pose& p : state.root_poses) {
    roots_finite = roots_finite && p.translation.allFinite() && p.rotation.coeffs().allFinite();
  }
  if (finite(state.position) && finite(state.velocity) && finite(state.effort) && roots_finite) {
    return std::nullopt;
  }
  static constexpr const char* kWhat[3] = {"position", "velocity", "effort"};
  const Eigen::VectorXd* vectors[3] = {&state.position, &state.velocity, &state.effort};
  for (int j = 0; j < static_cast<int>(model.joints().size()); ++j) {
    const Joint& joint = model.joint(j);
    for (int k = 0; k < static_cast<int>(joint.dofs.size()); ++k) {
      const int i = model.dof_offset(j) + k;
      for (int w = 0; w < 3; ++w) {
        if (i < vectors[w]->size() && !std::isfinite((*vectors[w])[i])) {
          return "joint '" + joint.name + "' dof " + std::to_string(k) + " " + kWhat[w] + " is " +
                 NotFinite((*vectors[w])[i]);
        }
      }
    }
  }
  if (!std::isfinite(state.base_v)) return "base v is " + NotFinite(state.base_v);
  if (!std::isfinite(state.base_omega)) return "base omega is " + NotFinite(state.base_omega);
  for (std::size_t r = 0; r < state.root_poses.size(); ++r) {
    const Pose& p = state.root_poses[r];
    const std::string root =
        r < model.roots().size() ? "root '" + model.link(model.roots()[r].link).name + "'" : "root";
    static constexpr const char* kAxis[3] = {"x", "y", "z"};
    for (int a = 0; a < 3; ++a) {
      if (!std::isfinite(p.translation[a]))
        return root + " " + kAxis[a] + " is " + NotFinite(p.translation[a]);
    }
    if (!p.rotation.coeffs().allFinite()) return root + " orientation is not finite";
  }
  return "a value is not finite";  // sizes that do not match the model
}

std::optional<std::string> MisfitState(const RobotModel& model, const RobotState& state) {
  const Eigen::Index dofs = model.num_dofs();
  static constexpr const char* kWhat[3] = {"position", "velocity", "effort"};
  const Eigen::VectorXd* vectors[3] = {&state.position, &state.velocity, &state.effort};
  for (int w = 0; w < 3; ++w) {
    if (vectors[w]->size() != dofs) {
      return std::string(kWhat[w]) + " has " + std::to_string(vectors[w]->size()) +
             " values, the model has " + std::to_string(dofs) + " dofs";
    }
  }
  if (state.root_poses.size() != model.roots().size()) {
    return "root_poses has " + std::to_string(state.root_poses.size()) + " poses, the model has " +
           std::to_string(model.roots().size()) + " roots";
  }
  return std::nullopt;
}

std::string RobotDaemon::timing() const {
  std::lock_guard lock(mutex_);
  return timing_;
}

void RobotDaemon::FillSample(TimePoint now, Duration period) {
  RobotSample& s = sample_;
  s.time = now;
  s.period = period;
  s.sample = ++samples_;
  s.panic = panic_.in_panic();
  s.moving = state_.moving;
  s.position = state_.position;  // same sizes: copies, no allocation
  s.velocity = state_.velocity;
  s.effort = state_.effort;
  const Eigen::Isometry3d base = state_.root_poses.front().ToIsometry();
  s.base = {base.translation().x(), base.translation().y(), PlanarYaw(base), state_.base_v,
            state_.base_omega};
  s.frames_valid = true;
  if (!s.frame_poses.empty()) {
    try {
      for (std::size_t i = 0; i < roots_.size(); ++i) roots_[i] = state_.root_poses[i].ToIsometry();
      kinematics_.Update(state_.position, roots_);
      for (std::size_t f = 0; f < s.frame_poses.size() / 7; ++f) {
        WritePose7(kinematics_.frame_pose(static_cast<int>(f)), s.frame_poses.data() + 7 * f);
      }
    } catch (const std::exception&) {
      s.frames_valid = false;  // a driver reporting a non-finite state: send the rest
    }
  }
}

}  // namespace robotalk
