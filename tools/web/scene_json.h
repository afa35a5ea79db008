// What robotalk-web tells the page about a robot, as JSON (docs/web.md,
// "Messages"): the description drawn from the RoboTalk configuration, and each
// state sample turned into world poses of every link with the project's own
// forward kinematics, so the page needs no kinematics of its own.
//
// Thread safety: the free functions are pure. A StatePoser is not thread-safe
// (it owns a Kinematics buffer); use one per thread.
// Samples come validated by the codec (DecodeStateSample, request.h; the
// client decodes with its model's dof count): counts agree, every value is
// finite unless the sample is in panic (then a broken driver's NaN or inf,
// written as 0 like every non-finite number here).
// Errors: StatePoser::Pose throws ProtocolError when a sample was taken for
// another model (its dof count differs); nothing else throws except
// std::bad_alloc.
#pragma once

#include "robotalk/kinematics.h"
#include "robotalk/robot_model.h"
#include "robotalk/state_sample.h"

#include <Eigen/Geometry>
#include <nlohmann/json.hpp>

#include <optional>
#include <string>
#include <vector>

namespace robotalk::web {

/// The sides (m) of the solid box of uniform density that has the link's mass
/// and principal moments of inertia, and the rotation from the box's axes to
/// the link frame. A massless link, or moments that fit no box (numerical
/// noise, a point mass), give sides of at least `min_side`.
struct InertiaBox {
  Eigen::Vector3d sides = Eigen::Vector3d::Zero();
  Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity();
};
InertiaBox EquivalentInertiaBox(const Link& link, double min_side = 0.02);

/// Names of the dofs in dof order: the joint's name for a 1-dof joint,
/// "joint/k" (k = 0, 1, ...) for a joint with several.
std::vector<std::string> DofNames(const RobotModel& model);

/// {"name", "num_dofs", "dof_names", "links":[{name, mass, com, box, box_rotation,
/// points}], "joints":[{name, parent, child, dofs, dof_offset, mimic}],
/// "frames":[{name, link, pose}], "roots":[{link, base}]}. Poses are
/// [x, y, z, qw, qx, qy, qz]; `points` are the joint centres on the link, in
/// its frame (for drawing bones).
nlohmann::json ModelToJson(const RobotModel& model);

/// Turns state samples into world poses of every link.
class StatePoser {
 public:
  /// `model` must outlive the poser.
  explicit StatePoser(const RobotModel& model);

  /// World pose of the first root link at `sample`. The sample carries only
  /// the base's x y θ; when the model has a control frame under the first
  /// root and the sample its world pose, the root's full pose (height, tilt)
  /// is recovered from it; otherwise height and tilt are those of the last
  /// SetMeasuredRoot(), or the model's.
  Eigen::Isometry3d RootPose(const StateSample& sample);

  /// True when samples alone cannot give the root's height and tilt: a
  /// floating base without a control frame under it (a humanoid's pelvis).
  bool needs_measured_root() const { return needs_measured_root_; }
  /// The root's world pose as a LINK_POSES query answered it (its height and
  /// tilt are used; x y θ still come from each sample).
  void SetMeasuredRoot(const Eigen::Isometry3d& root) { measured_root_ = root; }

  /// {"type":"state", "robot", "sample", "t" (s, server clock), "period" (s),
  /// "panic", "moving", "base":[x,y,θ,v,ω], "q":[...], "links":[[x,y,z,qw,qx,qy,qz]...]}
  /// Values are rounded to 1e-6 to keep the text short.
  nlohmann::json Pose(const StateSample& sample);

 private:
  void CheckModel(const StateSample& sample) const;

  const RobotModel& model_;
  Kinematics kin_;
  Eigen::VectorXd q_;
  std::vector<Eigen::Isometry3d> roots_;
  int reference_frame_ = -1;  // a control frame under the first root, or -1
  bool needs_measured_root_ = false;
  std::optional<Eigen::Isometry3d> measured_root_;
};

}  // namespace robotalk::web
