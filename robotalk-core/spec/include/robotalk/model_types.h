// The value types of the RoboTalk motion specification (DESIGN.md §1): links,
// degrees of freedom, joints, control frames and root links. They are plain
// structs; RobotModel validates a set of them and makes them immutable.
//
// Frames and conventions (docs/specification.md has figures in words):
// - Every link has a body-fixed frame ("link frame"). Its centre of mass `com`
//   is given in that frame; its inertia tensor is about the COM, expressed in
//   the link frame's axes.
// - A joint connects a parent link to a child link. `inboard` is the vector from
//   the parent's COM to the joint centre, in the parent's link frame; `outboard`
//   is the vector from the child's COM to the joint centre, in the child's link
//   frame. `rest` is the joint's constant rotation (parent axes -> joint axes
//   when all dofs are zero). The dofs then act one after another, each about or
//   along its axis expressed in the frame left by the previous dofs:
//     X_parent_child(q) = Tr(com_p + inboard) * rest * M_0(q_0) ... M_k(q_k)
//                         * Tr(-(com_c + outboard))
// - Units are SI: m, rad, kg, kg·m², m/s, rad/s, N, N·m.
#pragma once

#include <Eigen/Geometry>

#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <vector>

namespace robotalk {

/// Servo command types an actuator accepts (paper §III-C). A bit set.
enum class ServoType : std::uint8_t {
  kNone = 0,
  kSetPoint = 1 << 0,  ///< position (joint) or pose (control frame) set-point
  kSpeed = 1 << 1,     ///< velocity command
  kForce = 1 << 2,     ///< force / torque command
};

/// A set of ServoType flags.
class ServoTypes {
 public:
  constexpr ServoTypes() = default;
  constexpr ServoTypes(ServoType t) : bits_(static_cast<std::uint8_t>(t)) {}  // NOLINT
  static constexpr ServoTypes FromBits(std::uint8_t bits) { return ServoTypes(bits & 0x7); }
  static constexpr ServoTypes All() { return FromBits(0x7); }

  constexpr bool Has(ServoType t) const { return (bits_ & static_cast<std::uint8_t>(t)) != 0; }
  constexpr bool empty() const { return bits_ == 0; }
  constexpr std::uint8_t bits() const { return bits_; }
  constexpr ServoTypes operator|(ServoTypes o) const { return ServoTypes(bits_ | o.bits_); }
  constexpr bool operator==(const ServoTypes&) const = default;

  /// "setpoint speed force" (space separated, in that order), or "none".
  std::string ToString() const;
  /// Parses the format of ToString(); also accepts "set-point", "position",
  /// "velocity", "effort", "torque" and separators ',' '|'. Throws ModelError
  /// naming the unknown word.
  static ServoTypes Parse(const std::string& text);

 private:
  constexpr explicit ServoTypes(int bits) : bits_(static_cast<std::uint8_t>(bits)) {}
  std::uint8_t bits_ = 0;
};

constexpr ServoTypes operator|(ServoType a, ServoType b) { return ServoTypes(a) | ServoTypes(b); }

/// A rigid transform stored as translation + unit quaternion, so that it
/// survives encoding bit for bit (an Isometry3d's matrix would not).
struct Pose {
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();
  Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity();

  Eigen::Isometry3d ToIsometry() const;
  static Pose FromIsometry(const Eigen::Isometry3d& x);
  bool operator==(const Pose& o) const;
};

/// A rigid body. Mass 0 means a massless frame-like link (no inertia needed).
struct Link {
  std::string name;
  double mass = 0.0;                                  ///< kg, >= 0
  Eigen::Vector3d com = Eigen::Vector3d::Zero();      ///< m, in the link frame
  Eigen::Matrix3d inertia = Eigen::Matrix3d::Zero();  ///< kg·m², about the COM
  bool operator==(const Link&) const = default;
};

enum class DofType : std::uint8_t { kRevolute = 0, kPrismatic = 1 };

/// Limits of one dof. Infinite values mean "no limit"; a continuous revolute
/// joint has infinite position limits.
struct DofLimits {
  static constexpr double kInf = std::numeric_limits<double>::infinity();
  double lower = -kInf;    ///< rad or m
  double upper = kInf;     ///< rad or m
  double velocity = kInf;  ///< rad/s or m/s, > 0
  double effort = kInf;    ///< N·m or N, > 0
  bool operator==(const DofLimits&) const = default;
};

/// One degree of freedom of a joint.
struct Dof {
  DofType type = DofType::kRevolute;
  Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();  ///< unit vector, joint frame
  DofLimits limits;
  bool operator==(const Dof&) const = default;
};

/// A 1-dof joint whose position follows another 1-dof joint:
/// q = multiplier * q_leader + offset (URDF <mimic>).
struct Mimic {
  int leader_joint = -1;  ///< index into RobotModel::joints()
  double multiplier = 1.0;
  double offset = 0.0;
  bool operator==(const Mimic&) const = default;
};

/// The most dofs a joint has (a free joint): RobotModelBuilder refuses more,
/// and so does the CONFIG decoder.
inline constexpr int kMaxDofsPerJoint = 6;

/// A joint with 0 (fixed) to kMaxDofsPerJoint (free) dofs.
struct Joint {
  std::string name;
  int parent_link = -1;                                      ///< index into RobotModel::links()
  int child_link = -1;                                       ///< index into RobotModel::links()
  Eigen::Vector3d inboard = Eigen::Vector3d::Zero();         ///< m, parent COM -> joint, parent axes
  Eigen::Vector3d outboard = Eigen::Vector3d::Zero();        ///< m, child COM -> joint, child axes
  Eigen::Quaterniond rest = Eigen::Quaterniond::Identity();  ///< rotation at q = 0
  std::vector<Dof> dofs;
  ServoTypes servo_types;
  std::optional<Mimic> mimic;
  bool operator==(const Joint& o) const;
};

/// A frame fixed to a link: end effector, tool, camera optical frame.
struct ControlFrame {
  std::string name;
  int parent_link = -1;  ///< index into RobotModel::links()
  Pose pose_in_link;     ///< in the link frame
  ServoTypes servo_types;
  bool operator==(const ControlFrame&) const = default;
};

/// How a root link may move in the world.
enum class BaseType : std::uint8_t {
  kFixed = 0,         ///< bolted to the world (an arm on a table)
  kDifferential = 1,  ///< non-holonomic planar base: SETSPEED(v, ω), GOTO(x, y, θ)
  kHolonomic = 2,     ///< planar base that may move sideways
  kFloating = 3,      ///< free-floating in 6 dofs (a humanoid's pelvis)
};

/// A link without parent joint, posed in the world frame.
struct RootLink {
  int link = -1;       ///< index into RobotModel::links()
  Pose pose_in_world;  ///< of its link frame
  BaseType base = BaseType::kFixed;
  bool operator==(const RootLink&) const = default;
};

/// Short lowercase names used in files and on the command line.
const char* ToString(DofType t);
const char* ToString(BaseType t);
/// Parses "fixed", "differential", "holonomic", "floating"; throws ModelError.
BaseType ParseBaseType(const std::string& text);

}  // namespace robotalk
