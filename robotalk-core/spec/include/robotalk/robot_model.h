// RobotModel: a validated, immutable robot description (DESIGN.md §1), and
// RobotModelBuilder, which assembles one by name.
//
// Thread safety: a RobotModel is immutable after construction; concurrent
// reads from any number of threads are safe. RobotModelBuilder is not
// thread-safe.
#pragma once

#include "robotalk/model_types.h"

#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

namespace robotalk {

class RobotModel {
 public:
  /// Validates and takes the description. Links, joints and frames keep the
  /// given order (their indices). Every link without a parent joint is a root:
  /// `roots` may pose some of them; the others get a fixed identity pose.
  /// Throws ModelError naming the element and what is wrong: duplicate name,
  /// unknown link index, a link with two parent joints, a cycle, more than 6
  /// dofs, a zero or non-unit axis, lower limit above upper, non-positive
  /// velocity or effort limit, negative mass, inertia not positive-definite for
  /// a link with mass, a non-finite number, a bad mimic, or no root at all.
  RobotModel(std::string name, std::vector<Link> links, std::vector<Joint> joints,
             std::vector<ControlFrame> frames, std::vector<RootLink> roots = {});

  const std::string& name() const { return name_; }
  std::span<const Link> links() const { return links_; }
  std::span<const Joint> joints() const { return joints_; }
  std::span<const ControlFrame> frames() const { return frames_; }
  std::span<const RootLink> roots() const { return roots_; }

  const Link& link(int index) const;
  const Joint& joint(int index) const;
  const ControlFrame& frame(int index) const;

  /// Index by name, or std::nullopt.
  std::optional<int> FindLink(std::string_view name) const;
  std::optional<int> FindJoint(std::string_view name) const;
  std::optional<int> FindFrame(std::string_view name) const;
  /// Index by name; throws LookupError "robot 'r' has no joint named 'x'".
  int LinkIndex(std::string_view name) const;
  int JointIndex(std::string_view name) const;
  int FrameIndex(std::string_view name) const;

  /// Total number of dofs over all joints (size of a joint-position vector).
  int num_dofs() const { return num_dofs_; }
  /// Index of a joint's first dof in a joint-position vector.
  int dof_offset(int joint) const { return dof_offsets_.at(static_cast<size_t>(joint)); }
  /// The joint whose child is `link`, or -1 for a root link.
  int parent_joint(int link) const { return parent_joint_.at(static_cast<size_t>(link)); }
  /// The joints between control frame `frame` and its root, the frame's own
  /// link's parent joint first (what a command on the frame moves, and owns).
  std::span<const int> frame_chain(int frame) const { return frame_chains_.at(static_cast<size_t>(frame)); }
  /// Joint indices ordered parents-before-children (a valid FK sweep order).
  std::span<const int> topological_joint_order() const { return joint_order_; }
  /// The root link at the top of `link`'s subtree.
  int root_of(int link) const { return root_of_.at(static_cast<size_t>(link)); }

  /// Sum of all link masses, kg.
  double total_mass() const;

  bool operator==(const RobotModel& o) const;

 private:
  void Validate();

  std::string name_;
  std::vector<Link> links_;
  std::vector<Joint> joints_;
  std::vector<ControlFrame> frames_;
  std::vector<RootLink> roots_;
  // Derived in Validate().
  int num_dofs_ = 0;
  std::vector<int> dof_offsets_;
  std::vector<int> parent_joint_;
  std::vector<int> joint_order_;
  std::vector<std::vector<int>> frame_chains_;
  std::vector<int> root_of_;
  std::unordered_map<std::string, int> link_by_name_, joint_by_name_, frame_by_name_;
};

/// Assembles a RobotModel with links referred to by name.
///
///   RobotModelBuilder b("arm");
///   b.AddLink({.name = "base"}).AddLink({.name = "upper", .mass = 1.0, ...});
///   b.AddJoint(shoulder, "base", "upper");
///   RobotModel model = b.Build();
class RobotModelBuilder {
 public:
  explicit RobotModelBuilder(std::string robot_name) : name_(std::move(robot_name)) {}

  RobotModelBuilder& AddLink(Link link);
  /// `joint.parent_link` / `child_link` are ignored; the names are resolved in Build().
  RobotModelBuilder& AddJoint(Joint joint, std::string parent_link, std::string child_link);
  /// `frame.parent_link` is ignored; the name is resolved in Build().
  RobotModelBuilder& AddControlFrame(ControlFrame frame, std::string parent_link);
  RobotModelBuilder& SetRoot(std::string link, const Pose& pose_in_world, BaseType base = BaseType::kFixed);
  /// Makes 1-dof `joint` follow 1-dof `leader`: q = multiplier * q_leader + offset.
  RobotModelBuilder& SetMimic(std::string joint, std::string leader, double multiplier, double offset);

  /// Resolves names and validates. Throws ModelError, e.g.
  /// "joint 'elbow': unknown child link 'forearm'".
  RobotModel Build() const;

 private:
  struct NamedJoint {
    Joint joint;
    std::string parent, child;
  };
  struct NamedFrame {
    ControlFrame frame;
    std::string parent;
  };
  struct NamedRoot {
    std::string link;
    Pose pose;
    BaseType base;
  };
  struct NamedMimic {
    std::string joint, leader;
    double multiplier, offset;
  };
  std::string name_;
  std::vector<Link> links_;
  std::vector<NamedJoint> joints_;
  std::vector<NamedFrame> frames_;
  std::vector<NamedRoot> roots_;
  std::vector<NamedMimic> mimics_;
};

}  // namespace robotalk
