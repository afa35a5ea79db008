// Leg inverse kinematics: see leg_ik.h.
#include "walking/leg_ik.h"

#include "robotalk/error.h"

#include <algorithm>

namespace robotalk::walking {
namespace {

std::unique_ptr<RobotModel> WithSoles(const RobotModel& m, std::array<int, 2> feet,
                                      std::array<Eigen::Vector3d, 2> sole) {
  std::vector<ControlFrame> frames(m.frames().begin(), m.frames().end());
  const char* names[2] = {"walk_left_sole", "walk_right_sole"};
  for (int s = 0; s < 2; ++s) {
    ControlFrame f;
    f.name = names[s];
    f.parent_link = feet[static_cast<size_t>(s)];
    f.pose_in_link.translation = sole[static_cast<size_t>(s)];
    f.servo_types = ServoTypes(ServoType::kSetPoint);
    frames.push_back(f);
  }
  return std::make_unique<RobotModel>(m.name(), std::vector<Link>(m.links().begin(), m.links().end()),
                                      std::vector<Joint>(m.joints().begin(), m.joints().end()),
                                      std::move(frames),
                                      std::vector<RootLink>(m.roots().begin(), m.roots().end()));
}

}  // namespace

LegIk::LegIk(const RobotModel& model, std::array<int, 2> feet, std::array<Eigen::Vector3d, 2> sole)
    : model_(WithSoles(model, feet, sole)),
      ik_(std::make_unique<InverseKinematics>(*model_)),
      kin_(std::make_unique<Kinematics>(*model_)) {
  const int n = model_->num_dofs();
  leg_mask_.assign(static_cast<size_t>(n), 0);
  for (int s = 0; s < 2; ++s) {
    frame_[static_cast<size_t>(s)] = static_cast<int>(model_->frames().size()) - 2 + s;
    if (!ik_->HasMovableDofs(frame_[static_cast<size_t>(s)])) {
      throw Error("LegIk: foot link '" + model_->link(feet[static_cast<size_t>(s)]).name +
                  "' has no set-point joint between it and the root of '" + model_->name() + "'");
    }
    const auto mask = ik_->default_mask(frame_[static_cast<size_t>(s)]);
    for (int i = 0; i < n; ++i) leg_mask_[static_cast<size_t>(i)] |= mask[static_cast<size_t>(i)];
  }
  roots_.assign(model_->roots().size(), Eigen::Isometry3d::Identity());
}

double LegIk::Solve(const Eigen::Isometry3d& pelvis, const std::array<Eigen::Isometry3d, 2>& soles,
                    Eigen::VectorXd& q) {
  roots_.front() = pelvis;
  double worst = 0;
  iterations_ = 0;
  for (int s = 0; s < 2; ++s) {
    const Eigen::Isometry3d& goal = soles[static_cast<size_t>(s)];
    const InverseKinematics::Result r = ik_->Solve(frame_[static_cast<size_t>(s)], goal.translation(),
                                                   Eigen::Quaterniond(goal.linear()), q, roots_);
    const auto mask = ik_->default_mask(frame_[static_cast<size_t>(s)]);
    const Eigen::VectorXd& best = ik_->solution();
    for (Eigen::Index i = 0; i < q.size(); ++i) {
      if (mask[static_cast<size_t>(i)]) q[i] = best[i];
    }
    worst = std::max(worst, r.position_error);
    iterations_ += r.iterations;
  }
  return worst;
}

Eigen::Vector3d LegIk::ComInPelvis(const Eigen::VectorXd& q) {
  roots_.front() = Eigen::Isometry3d::Identity();
  kin_->Update(q, roots_);
  return kin_->CenterOfMass();
}

Eigen::Isometry3d LegIk::SoleInPelvis(int side, const Eigen::VectorXd& q) {
  roots_.front() = Eigen::Isometry3d::Identity();
  kin_->Update(q, roots_);
  return kin_->frame_pose(frame_[static_cast<size_t>(side)]);
}

}  // namespace robotalk::walking
