#include "robotalk/robot_model.h"

#include "robotalk/error.h"
#include "robotalk/log_writer.h"  // EscapeControls

#include <Eigen/Eigenvalues>
#include <cmath>
#include <optional>
#include <sstream>

namespace robotalk {
namespace {

constexpr double kUnitTolerance = 1e-6;

std::string Quote(std::string_view s) { return "'" + std::string(s) + "'"; }

[[noreturn]] void Fail(const std::string& robot, const std::string& what) {
  throw ModelError("robot " + Quote(robot) + ": " + what);
}

template <typename Derived>
bool AllFinite(const Eigen::MatrixBase<Derived>& m) {
  return m.allFinite();
}

std::string Vec(const Eigen::Vector3d& v) {
  std::ostringstream s;
  s << "(" << v.x() << ", " << v.y() << ", " << v.z() << ")";
  return s.str();
}

// The code points of `text` (UTF-8), or nullopt when it is not UTF-8: a
// byte no character begins with, a lone continuation byte, a truncated
// character, an overlong form, a surrogate, past U+10FFFF.
std::optional<std::vector<char32_t>> CodePoints(std::string_view text) {
  std::vector<char32_t> out;
  for (std::size_t i = 0; i < text.size();) {
    const auto b = static_cast<unsigned char>(text[i]);
    const int n = b < 0x80 ? 1 : (b & 0xe0) == 0xc0 ? 2 : (b & 0xf0) == 0xe0 ? 3 : (b & 0xf8) == 0xf0 ? 4 : 0;
    if (n == 0 || i + static_cast<std::size_t>(n) > text.size()) return std::nullopt;
    char32_t c = n == 1 ? b : b & (0x7f >> n);
    for (int k = 1; k < n; ++k) {
      const auto next = static_cast<unsigned char>(text[i + static_cast<std::size_t>(k)]);
      if ((next & 0xc0) != 0x80) return std::nullopt;
      c = (c << 6) | (next & 0x3f);
    }
    static constexpr char32_t kLeast[] = {0, 0, 0x80, 0x800, 0x10000};
    if (c < kLeast[n] || c > 0x10ffff || (c >= 0xd800 && c <= 0xdfff)) return std::nullopt;
    out.push_back(c);
    i += static_cast<std::size_t>(n);
  }
  return out;
}

// A name is shown wherever the model is (a terminal, a log, the page, ROS 2):
// one with a control character (EscapeControls' C0, DEL, C1 in UTF-8), one
// that is not UTF-8, or one with a line or paragraph separator or a
// bidirectional control (it reorders the text it is shown in) is refused,
// named escaped (in printable ASCII for the last two).
std::string ControlProblem(std::string_view kind, std::string_view name) {
  const std::string shown = EscapeControls(name);
  if (shown != name) return std::string(kind) + " name " + Quote(shown) + " holds a control character";
  const std::string ascii = Quote(EscapeControls(name, /*ascii_only=*/true));
  const auto points = CodePoints(name);
  if (!points) return std::string(kind) + " name " + ascii + " is not UTF-8 text";
  for (const char32_t c : *points) {
    if (c == 0x2028 || c == 0x2029 || c == 0x061c || c == 0x200e || c == 0x200f ||
        (c >= 0x202a && c <= 0x202e) || (c >= 0x2066 && c <= 0x2069))
      return std::string(kind) + " name " + ascii + " holds a line separator or a bidirectional control";
  }
  return {};
}

template <typename T>
std::unordered_map<std::string, int> IndexByName(const std::string& robot, const std::vector<T>& items,
                                                 const char* kind) {
  std::unordered_map<std::string, int> by_name;
  for (size_t i = 0; i < items.size(); ++i) {
    const std::string& name = items[i].name;
    if (name.empty()) Fail(robot, std::string(kind) + " #" + std::to_string(i) + " has an empty name");
    if (const std::string why = ControlProblem(kind, name); !why.empty()) Fail(robot, why);
    if (!by_name.emplace(name, static_cast<int>(i)).second) {
      Fail(robot, "duplicate " + std::string(kind) + " name " + Quote(name));
    }
  }
  return by_name;
}

void ValidateLink(const std::string& robot, const Link& link) {
  const std::string what = "link " + Quote(link.name) + ": ";
  if (!std::isfinite(link.mass)) Fail(robot, what + "mass is not finite");
  if (link.mass < 0) Fail(robot, what + "negative mass " + std::to_string(link.mass) + " kg");
  if (!AllFinite(link.com)) Fail(robot, what + "centre of mass " + Vec(link.com) + " is not finite");
  if (!AllFinite(link.inertia)) Fail(robot, what + "inertia is not finite");
  if (link.inertia != link.inertia.transpose()) Fail(robot, what + "inertia tensor is not symmetric");
  if (link.mass > 0) {
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(link.inertia, Eigen::EigenvaluesOnly);
    const Eigen::Vector3d ev = eig.eigenvalues();
    if (ev.minCoeff() <= 0) {
      Fail(robot, what + "inertia is not positive-definite for a link of mass " + std::to_string(link.mass) +
                      " kg (principal moments " + Vec(ev) + ")");
    }
  }
}

void ValidateDof(const std::string& robot, const Joint& joint, size_t k, const Dof& dof) {
  const std::string what = "joint " + Quote(joint.name) + " dof " + std::to_string(k) + ": ";
  if (dof.type != DofType::kRevolute && dof.type != DofType::kPrismatic) {
    Fail(robot, what + "unknown dof type " + std::to_string(static_cast<int>(dof.type)));
  }
  if (!AllFinite(dof.axis)) Fail(robot, what + "axis " + Vec(dof.axis) + " is not finite");
  const double norm = dof.axis.norm();
  if (norm == 0) Fail(robot, what + "zero axis");
  if (std::abs(norm - 1) > kUnitTolerance) {
    Fail(robot, what + "axis " + Vec(dof.axis) + " is not a unit vector (norm " + std::to_string(norm) + ")");
  }
  const DofLimits& l = dof.limits;
  if (std::isnan(l.lower) || std::isnan(l.upper) || std::isnan(l.velocity) || std::isnan(l.effort)) {
    Fail(robot, what + "a limit is NaN");
  }
  if (l.lower == DofLimits::kInf || l.upper == -DofLimits::kInf) {
    Fail(robot, what + "position limits [" + std::to_string(l.lower) + ", " + std::to_string(l.upper) +
                    "] leave no admissible position");
  }
  if (l.lower > l.upper) {
    Fail(robot, what + "lower limit " + std::to_string(l.lower) + " is above upper limit " +
                    std::to_string(l.upper));
  }
  if (!(l.velocity > 0))
    Fail(robot, what + "velocity limit " + std::to_string(l.velocity) + " is not positive");
  if (!(l.effort > 0)) Fail(robot, what + "effort limit " + std::to_string(l.effort) + " is not positive");
}

bool IsUnit(const Eigen::Quaterniond& q) {
  return q.coeffs().allFinite() && std::abs(q.norm() - 1) <= kUnitTolerance;
}

}  // namespace

RobotModel::RobotModel(std::string name, std::vector<Link> links, std::vector<Joint> joints,
                       std::vector<ControlFrame> frames, std::vector<RootLink> roots)
    : name_(std::move(name)),
      links_(std::move(links)),
      joints_(std::move(joints)),
      frames_(std::move(frames)),
      roots_(std::move(roots)) {
  Validate();
}

void RobotModel::Validate() {
  if (name_.empty()) throw ModelError("RobotModel: the robot has an empty name");
  if (const std::string why = ControlProblem("robot", name_); !why.empty())
    throw ModelError("RobotModel: " + why);
  if (links_.empty()) Fail(name_, "has no links");
  link_by_name_ = IndexByName(name_, links_, "link");
  joint_by_name_ = IndexByName(name_, joints_, "joint");
  frame_by_name_ = IndexByName(name_, frames_, "control frame");
  const int num_links = static_cast<int>(links_.size());
  const int num_joints = static_cast<int>(joints_.size());
  auto valid_link = [&](int i) { return i >= 0 && i < num_links; };

  for (const Link& link : links_) ValidateLink(name_, link);

  // Joints: references, geometry, dofs; and each link has at most one parent.
  parent_joint_.assign(links_.size(), -1);
  dof_offsets_.assign(joints_.size(), 0);
  num_dofs_ = 0;
  for (int j = 0; j < num_joints; ++j) {
    const Joint& joint = joints_[static_cast<size_t>(j)];
    const std::string what = "joint " + Quote(joint.name) + ": ";
    if (!valid_link(joint.parent_link))
      Fail(name_, what + "unknown parent link index " + std::to_string(joint.parent_link));
    if (!valid_link(joint.child_link))
      Fail(name_, what + "unknown child link index " + std::to_string(joint.child_link));
    const std::string& child = links_[static_cast<size_t>(joint.child_link)].name;
    if (joint.parent_link == joint.child_link)
      Fail(name_, what + "joins link " + Quote(child) + " to itself");
    int& parent_of_child = parent_joint_[static_cast<size_t>(joint.child_link)];
    if (parent_of_child >= 0) {
      Fail(name_, "not a tree: link " + Quote(child) + " has two parent joints, " +
                      Quote(joints_[static_cast<size_t>(parent_of_child)].name) + " and " +
                      Quote(joint.name));
    }
    parent_of_child = j;
    if (!AllFinite(joint.inboard))
      Fail(name_, what + "inboard position " + Vec(joint.inboard) + " is not finite");
    if (!AllFinite(joint.outboard))
      Fail(name_, what + "outboard position " + Vec(joint.outboard) + " is not finite");
    if (!IsUnit(joint.rest)) Fail(name_, what + "rest rotation is not a unit quaternion");
    if (joint.dofs.size() > kMaxDofsPerJoint) {
      Fail(name_, what + "has " + std::to_string(joint.dofs.size()) + " dofs; a joint has at most " +
                      std::to_string(kMaxDofsPerJoint));
    }
    for (size_t k = 0; k < joint.dofs.size(); ++k) ValidateDof(name_, joint, k, joint.dofs[k]);
    dof_offsets_[static_cast<size_t>(j)] = num_dofs_;
    num_dofs_ += static_cast<int>(joint.dofs.size());
  }

  for (const Joint& joint : joints_) {
    if (!joint.mimic) continue;
    const std::string what = "joint " + Quote(joint.name) + ": mimic ";
    const int leader = joint.mimic->leader_joint;
    if (leader < 0 || leader >= num_joints)
      Fail(name_, what + "names unknown joint index " + std::to_string(leader));
    const Joint& lead = joints_[static_cast<size_t>(leader)];
    if (&lead == &joint) Fail(name_, what + "names the joint itself");
    if (joint.dofs.size() != 1 || lead.dofs.size() != 1) {
      Fail(name_, what + "of " + Quote(lead.name) + " needs two 1-dof joints (have " +
                      std::to_string(joint.dofs.size()) + " and " + std::to_string(lead.dofs.size()) + ")");
    }
    if (lead.mimic) Fail(name_, what + "leader " + Quote(lead.name) + " is itself a mimic joint");
    if (!std::isfinite(joint.mimic->multiplier) || !std::isfinite(joint.mimic->offset)) {
      Fail(name_, what + "multiplier or offset is not finite");
    }
  }

  for (const ControlFrame& frame : frames_) {
    const std::string what = "control frame " + Quote(frame.name) + ": ";
    if (!valid_link(frame.parent_link))
      Fail(name_, what + "unknown parent link index " + std::to_string(frame.parent_link));
    if (!AllFinite(frame.pose_in_link.translation)) Fail(name_, what + "position is not finite");
    if (!IsUnit(frame.pose_in_link.rotation)) Fail(name_, what + "orientation is not a unit quaternion");
  }

  // Roots: the given ones must be parentless and unique; every other
  // parentless link becomes a fixed root at the world origin.
  std::vector<bool> is_root(links_.size(), false);
  for (const RootLink& root : roots_) {
    if (!valid_link(root.link)) Fail(name_, "root: unknown link index " + std::to_string(root.link));
    const std::string& link = links_[static_cast<size_t>(root.link)].name;
    if (parent_joint_[static_cast<size_t>(root.link)] >= 0) {
      Fail(name_,
           "root link " + Quote(link) + " has a parent joint " +
               Quote(joints_[static_cast<size_t>(parent_joint_[static_cast<size_t>(root.link)])].name));
    }
    if (is_root[static_cast<size_t>(root.link)]) Fail(name_, "root link " + Quote(link) + " is listed twice");
    if (!AllFinite(root.pose_in_world.translation) || !IsUnit(root.pose_in_world.rotation)) {
      Fail(name_, "root link " + Quote(link) + ": pose is not finite or not a unit quaternion");
    }
    is_root[static_cast<size_t>(root.link)] = true;
  }
  for (int l = 0; l < num_links; ++l) {
    if (parent_joint_[static_cast<size_t>(l)] < 0 && !is_root[static_cast<size_t>(l)]) {
      roots_.push_back(RootLink{.link = l, .pose_in_world = {}, .base = BaseType::kFixed});
    }
  }
  if (roots_.empty())
    Fail(name_, "has no root link (every link has a parent joint, so the joints form a cycle)");

  // Depth-first sweep from the roots: parents before children. A link never
  // reached has a parent but no root above it, so it sits on a cycle.
  std::vector<std::vector<int>> child_joints(links_.size());
  for (int j = 0; j < num_joints; ++j)
    child_joints[static_cast<size_t>(joints_[static_cast<size_t>(j)].parent_link)].push_back(j);
  joint_order_.clear();
  root_of_.assign(links_.size(), -1);
  std::vector<int> stack;
  for (const RootLink& root : roots_) {
    stack.push_back(root.link);
    while (!stack.empty()) {
      const int l = stack.back();
      stack.pop_back();
      root_of_[static_cast<size_t>(l)] = root.link;
      const auto& children = child_joints[static_cast<size_t>(l)];
      for (auto it = children.rbegin(); it != children.rend(); ++it)
        stack.push_back(joints_[static_cast<size_t>(*it)].child_link);
      // Record in forward order; children are visited in joint order.
      if (l != root.link) joint_order_.push_back(parent_joint_[static_cast<size_t>(l)]);
    }
  }
  for (int l = 0; l < num_links; ++l) {
    if (root_of_[static_cast<size_t>(l)] >= 0) continue;
    // Walk up until a link repeats, naming the cycle.
    std::string cycle = Quote(links_[static_cast<size_t>(l)].name);
    std::vector<bool> seen(links_.size(), false);
    int cur = l;
    while (!seen[static_cast<size_t>(cur)]) {
      seen[static_cast<size_t>(cur)] = true;
      cur = joints_[static_cast<size_t>(parent_joint_[static_cast<size_t>(cur)])].parent_link;
      cycle += " <- " + Quote(links_[static_cast<size_t>(cur)].name);
    }
    Fail(name_, "not a tree: the joints form a cycle through links " + cycle);
  }

  // Each control frame's chain: the joints from its link up to its root.
  frame_chains_.assign(frames_.size(), {});
  for (std::size_t f = 0; f < frames_.size(); ++f) {
    for (int j = parent_joint_[static_cast<size_t>(frames_[f].parent_link)]; j >= 0;
         j = parent_joint_[static_cast<size_t>(joints_[static_cast<size_t>(j)].parent_link)]) {
      frame_chains_[f].push_back(j);
    }
  }
}

namespace {
template <typename T>
const T& At(const std::vector<T>& v, int i, const char* kind, const std::string& robot) {
  if (i < 0 || static_cast<size_t>(i) >= v.size()) {
    throw LookupError("robot " + Quote(robot) + " has no " + kind + " with index " + std::to_string(i) +
                      " (it has " + std::to_string(v.size()) + ")");
  }
  return v[static_cast<size_t>(i)];
}

std::optional<int> Find(const std::unordered_map<std::string, int>& map, std::string_view name) {
  auto it = map.find(std::string(name));
  if (it == map.end()) return std::nullopt;
  return it->second;
}
}  // namespace

const Link& RobotModel::link(int index) const { return At(links_, index, "link", name_); }
const Joint& RobotModel::joint(int index) const { return At(joints_, index, "joint", name_); }
const ControlFrame& RobotModel::frame(int index) const { return At(frames_, index, "control frame", name_); }

std::optional<int> RobotModel::FindLink(std::string_view name) const { return Find(link_by_name_, name); }
std::optional<int> RobotModel::FindJoint(std::string_view name) const { return Find(joint_by_name_, name); }
std::optional<int> RobotModel::FindFrame(std::string_view name) const { return Find(frame_by_name_, name); }

int RobotModel::LinkIndex(std::string_view name) const {
  if (auto i = FindLink(name)) return *i;
  throw LookupError("robot " + Quote(name_) + " has no link named " + Quote(name));
}
int RobotModel::JointIndex(std::string_view name) const {
  if (auto i = FindJoint(name)) return *i;
  throw LookupError("robot " + Quote(name_) + " has no joint named " + Quote(name));
}
int RobotModel::FrameIndex(std::string_view name) const {
  if (auto i = FindFrame(name)) return *i;
  throw LookupError("robot " + Quote(name_) + " has no control frame named " + Quote(name));
}

double RobotModel::total_mass() const {
  double m = 0;
  for (const Link& link : links_) m += link.mass;
  return m;
}

bool RobotModel::operator==(const RobotModel& o) const {
  return name_ == o.name_ && links_ == o.links_ && joints_ == o.joints_ && frames_ == o.frames_ &&
         roots_ == o.roots_;
}

// --- RobotModelBuilder ---------------------------------------------------

RobotModelBuilder& RobotModelBuilder::AddLink(Link link) {
  links_.push_back(std::move(link));
  return *this;
}

RobotModelBuilder& RobotModelBuilder::AddJoint(Joint joint, std::string parent_link, std::string child_link) {
  joints_.push_back({std::move(joint), std::move(parent_link), std::move(child_link)});
  return *this;
}

RobotModelBuilder& RobotModelBuilder::AddControlFrame(ControlFrame frame, std::string parent_link) {
  frames_.push_back({std::move(frame), std::move(parent_link)});
  return *this;
}

RobotModelBuilder& RobotModelBuilder::SetRoot(std::string link, const Pose& pose_in_world, BaseType base) {
  roots_.push_back({std::move(link), pose_in_world, base});
  return *this;
}

RobotModelBuilder& RobotModelBuilder::SetMimic(std::string joint, std::string leader, double multiplier,
                                               double offset) {
  mimics_.push_back({std::move(joint), std::move(leader), multiplier, offset});
  return *this;
}

RobotModel RobotModelBuilder::Build() const {
  std::unordered_map<std::string, int> link_index;
  for (size_t i = 0; i < links_.size(); ++i) link_index.emplace(links_[i].name, static_cast<int>(i));
  auto resolve = [&](const std::string& link, const std::string& owner, const char* role) {
    auto it = link_index.find(link);
    if (it == link_index.end()) Fail(name_, owner + ": unknown " + role + " link " + Quote(link));
    return it->second;
  };
  std::vector<Joint> joints;
  std::unordered_map<std::string, int> joint_index;
  for (const NamedJoint& nj : joints_) {
    Joint j = nj.joint;
    j.parent_link = resolve(nj.parent, "joint " + Quote(j.name), "parent");
    j.child_link = resolve(nj.child, "joint " + Quote(j.name), "child");
    joint_index.emplace(j.name, static_cast<int>(joints.size()));
    joints.push_back(std::move(j));
  }
  for (const NamedMimic& m : mimics_) {
    auto follower = joint_index.find(m.joint);
    if (follower == joint_index.end()) Fail(name_, "mimic: unknown joint " + Quote(m.joint));
    auto leader = joint_index.find(m.leader);
    if (leader == joint_index.end())
      Fail(name_, "joint " + Quote(m.joint) + ": mimic names unknown joint " + Quote(m.leader));
    joints[static_cast<size_t>(follower->second)].mimic = Mimic{leader->second, m.multiplier, m.offset};
  }
  std::vector<ControlFrame> frames;
  for (const NamedFrame& nf : frames_) {
    ControlFrame f = nf.frame;
    f.parent_link = resolve(nf.parent, "control frame " + Quote(f.name), "parent");
    frames.push_back(std::move(f));
  }
  std::vector<RootLink> roots;
  for (const NamedRoot& nr : roots_) {
    roots.push_back(RootLink{resolve(nr.link, "root", "root"), nr.pose, nr.base});
  }
  return RobotModel(name_, links_, std::move(joints), std::move(frames), std::move(roots));
}

}  // namespace robotalk
