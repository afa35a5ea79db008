#include "scene_json.h"

#include "robotalk/error.h"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>

namespace robotalk::web {
namespace {

double Round6(double v) { return std::isfinite(v) ? std::round(v * 1e6) / 1e6 : 0.0; }

nlohmann::json Vec(const Eigen::Vector3d& v) { return {Round6(v.x()), Round6(v.y()), Round6(v.z())}; }

nlohmann::json PoseJson(const Eigen::Isometry3d& x) {
  const Eigen::Quaterniond r(x.linear());
  const Eigen::Vector3d& t = x.translation();
  return {Round6(t.x()), Round6(t.y()), Round6(t.z()), Round6(r.w()),
          Round6(r.x()), Round6(r.y()), Round6(r.z())};
}

}  // namespace

InertiaBox EquivalentInertiaBox(const Link& link, double min_side) {
  InertiaBox box;
  box.sides = Eigen::Vector3d::Constant(min_side);
  if (!(link.mass > 0) || !link.inertia.allFinite()) return box;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(link.inertia);
  if (eig.info() != Eigen::Success) return box;
  const Eigen::Vector3d I = eig.eigenvalues();
  // A uniform box of sides a, b, c: Ixx = m (b² + c²) / 12, and so on; solved
  // for the squares: a² = 6 (Iyy + Izz − Ixx) / m.
  for (int i = 0; i < 3; ++i) {
    const double sq = 6.0 * (I.sum() - 2.0 * I[i]) / link.mass;
    box.sides[i] = std::max(min_side, std::sqrt(std::max(0.0, sq)));
  }
  Eigen::Matrix3d axes = eig.eigenvectors();
  if (axes.determinant() < 0) axes.col(2) = -axes.col(2);  // a rotation, not a reflection
  box.rotation = Eigen::Quaterniond(axes).normalized();
  return box;
}

std::vector<std::string> DofNames(const RobotModel& model) {
  std::vector<std::string> names;
  names.reserve(static_cast<size_t>(model.num_dofs()));
  for (const Joint& j : model.joints()) {
    for (size_t k = 0; k < j.dofs.size(); ++k)
      names.push_back(j.dofs.size() == 1 ? j.name : j.name + "/" + std::to_string(k));
  }
  return names;
}

nlohmann::json ModelToJson(const RobotModel& model) {
  nlohmann::json links = nlohmann::json::array();
  for (const Link& l : model.links()) {
    const InertiaBox box = EquivalentInertiaBox(l);
    const Eigen::Quaterniond& r = box.rotation;
    links.push_back({{"name", l.name},
                     {"mass", l.mass},
                     {"com", Vec(l.com)},
                     {"box", Vec(box.sides)},
                     {"box_rotation", {Round6(r.w()), Round6(r.x()), Round6(r.y()), Round6(r.z())}},
                     {"points", nlohmann::json::array()}});
  }
  nlohmann::json joints = nlohmann::json::array();
  int index = 0;
  for (const Joint& j : model.joints()) {
    // Joint centres: com + inboard on the parent, com + outboard on the child.
    links[static_cast<size_t>(j.parent_link)]["points"].push_back(
        Vec(model.link(j.parent_link).com + j.inboard));
    links[static_cast<size_t>(j.child_link)]["points"].push_back(
        Vec(model.link(j.child_link).com + j.outboard));
    nlohmann::json dofs = nlohmann::json::array();
    for (const Dof& d : j.dofs) {
      dofs.push_back({{"type", ToString(d.type)},
                      {"axis", Vec(d.axis)},
                      {"lower", d.limits.lower},    // JsonText writes an absent (infinite)
                      {"upper", d.limits.upper}});  // limit as null
    }
    nlohmann::json joint = {{"name", j.name},
                            {"parent", j.parent_link},
                            {"child", j.child_link},
                            {"dofs", dofs},
                            {"dof_offset", model.dof_offset(index)},
                            {"mimic", j.mimic.has_value()}};
    joints.push_back(joint);
    ++index;
  }
  nlohmann::json frames = nlohmann::json::array();
  for (const ControlFrame& f : model.frames())
    frames.push_back(
        {{"name", f.name}, {"link", f.parent_link}, {"pose", PoseJson(f.pose_in_link.ToIsometry())}});
  nlohmann::json roots = nlohmann::json::array();
  for (const RootLink& r : model.roots()) roots.push_back({{"link", r.link}, {"base", ToString(r.base)}});
  return {{"name", model.name()},
          {"num_dofs", model.num_dofs()},
          {"dof_names", DofNames(model)},
          {"links", links},
          {"joints", joints},
          {"frames", frames},
          {"roots", roots}};
}

StatePoser::StatePoser(const RobotModel& model)
    : model_(model), kin_(model), q_(Eigen::VectorXd::Zero(model.num_dofs())) {
  for (const RootLink& r : model.roots()) roots_.push_back(r.pose_in_world.ToIsometry());
  const int first_root = model.roots().front().link;
  for (size_t f = 0; f < model.frames().size(); ++f) {
    if (model.root_of(model.frames()[f].parent_link) == first_root) {
      reference_frame_ = static_cast<int>(f);
      break;
    }
  }
  needs_measured_root_ = reference_frame_ < 0 && model.roots().front().base == BaseType::kFloating;
}

// Not a check of the wire (the codec made those): the poser indexes its own
// model's dofs with the sample's values.
void StatePoser::CheckModel(const StateSample& s) const {
  const auto n = static_cast<size_t>(model_.num_dofs());
  if (s.positions.size() != n) {
    throw ProtocolError("StatePoser: sample of robot '" + s.robot + "' has " +
                        std::to_string(s.positions.size()) + " dofs, its model " + std::to_string(n));
  }
}

Eigen::Isometry3d StatePoser::RootPose(const StateSample& s) {
  CheckModel(s);
  for (Eigen::Index i = 0; i < q_.size(); ++i) q_[i] = s.positions[static_cast<size_t>(i)];
  const bool have_frame = reference_frame_ >= 0 && s.frame_poses.size() == model_.frames().size();
  if (have_frame) {
    const auto& p = s.frame_poses[static_cast<size_t>(reference_frame_)];
    Eigen::Isometry3d frame_world = Eigen::Isometry3d::Identity();
    frame_world.translation() << p[0], p[1], p[2];
    const Eigen::Quaterniond r(p[3], p[4], p[5], p[6]);
    if (frame_world.translation().allFinite() && std::abs(r.norm() - 1.0) < 1e-3) {
      frame_world.linear() = r.normalized().toRotationMatrix();
      roots_.front() = Eigen::Isometry3d::Identity();
      kin_.Update(q_, roots_);
      // frame_world = root_world * frame_in_root  =>  root_world = frame_world * frame_in_root⁻¹
      return frame_world * kin_.frame_pose(reference_frame_).inverse();
    }
  }
  // x y θ from the sample, height and the rest of the rotation from the last
  // measured root pose, or from the model.
  const Eigen::Isometry3d ref =
      measured_root_ ? *measured_root_ : model_.roots().front().pose_in_world.ToIsometry();
  const Eigen::Matrix3d r0 = ref.linear();
  const double theta0 = std::atan2(r0(1, 0), r0(0, 0));
  Eigen::Isometry3d root = Eigen::Isometry3d::Identity();
  root.translation() << s.base.x, s.base.y, ref.translation().z();
  root.linear() = Eigen::AngleAxisd(s.base.theta - theta0, Eigen::Vector3d::UnitZ()) * r0;
  return root;
}

nlohmann::json StatePoser::Pose(const StateSample& s) {
  const Eigen::Isometry3d root = RootPose(s);  // also checks the sample and fills q_
  roots_.front() = root;
  kin_.Update(q_, roots_);
  nlohmann::json links = nlohmann::json::array();
  for (size_t l = 0; l < model_.links().size(); ++l)
    links.push_back(PoseJson(kin_.link_pose(static_cast<int>(l))));
  nlohmann::json q = nlohmann::json::array();
  for (double v : s.positions) q.push_back(Round6(v));
  nlohmann::json base = nlohmann::json::array();
  for (double v : {s.base.x, s.base.y, s.base.theta, s.base.v, s.base.omega}) base.push_back(Round6(v));
  return {{"type", "state"},
          {"robot", s.robot},
          {"sample", s.sample},
          {"t", static_cast<double>(ToWireMicros(s.server_time)) * 1e-6},
          {"period", static_cast<double>(ToWireMicros(s.period)) * 1e-6},
          {"panic", s.panic},
          {"moving", s.moving},
          {"link", LinkSummary(s.link)},
          {"link_level", ToString(s.link.level)},
          {"base", base},
          {"q", q},
          {"links", links}};
}

}  // namespace robotalk::web
