// URDF import. urdfdom does the URDF parsing; tinyxml supplies the file order
// and what urdfdom forgets; this file applies the frame conventions of
// model_types.h and the defect policy of docs/urdf_import.md.
//
// urdfdom accepts many broken files: a link with two parents gives it a
// tree whose recursive walk never ends. So nothing here walks urdfdom's
// tree; the model is built from the flat joint list and checked first.
#include "robotalk/urdf_import.h"

#include "robotalk/error.h"
#include "urdf_extensions.h"

#include <urdf_parser/urdf_parser.h>

#include <Eigen/Eigenvalues>
#include <climits>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>

namespace robotalk {
namespace {

using urdf_detail::Num;
using urdf_detail::Quote;
using urdf_detail::Refuse;

constexpr double kAxisTolerance = 1e-6;  // same as RobotModel's unit check

std::string Join(const std::vector<std::string>& items, const std::string& separator) {
  std::string s;
  for (const std::string& item : items) s += (s.empty() ? "" : separator) + item;
  return s;
}

// --- conversions -------------------------------------------------------------

Eigen::Vector3d ToEigen(const urdf::Vector3& v) { return {v.x, v.y, v.z}; }

Eigen::Quaterniond ToEigen(const urdf::Rotation& r) {
  return Eigen::Quaterniond(r.w, r.x, r.y, r.z).normalized();
}

std::string Vec(const Eigen::Vector3d& v) {
  return "(" + Num(v.x()) + " " + Num(v.y()) + " " + Num(v.z()) + ")";
}

// A joint on its way into the model, links still named.
struct Draft {
  Joint joint;
  std::string parent;
  std::string child;
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();  // URDF joint origin xyz
  std::optional<std::string> leader;                 // mimic leader, while representable
  double multiplier = 1.0;
  double offset = 0.0;
};

class Importer {
 public:
  Importer(const UrdfImportOptions& options, std::string source)
      : options_(options), source_(std::move(source)) {}

  UrdfImportResult Run(const std::string& xml);

 private:
  void Warn(std::string message) { warnings_.push_back(std::move(message)); }
  [[noreturn]] void Fail(const std::string& what) const { Refuse(source_, what); }

  urdf::ModelInterfaceSharedPtr ParseWithUrdfdom(const std::string& xml);
  void ImportLinks(const urdf::ModelInterface& model);
  void CheckTree(const urdf::ModelInterface& model);
  void ImportJoints(const urdf::ModelInterface& model);
  std::vector<Dof> MakeDofs(const urdf::Joint& j, const urdf_detail::XmlJoint& xml);
  DofLimits OneDofLimits(const urdf::Joint& j, const urdf_detail::XmlJoint& xml);
  void ResolveMimics();
  void FlattenMimicChains();
  void ApplyExtensions();
  void MergeMasslessChains();
  RobotModel Build(const std::string& robot_name);

  int LinkIndex(const std::string& name) const { return link_index_.at(name); }
  // Valid from ImportJoints until MergeMasslessChains renames joints.
  int FindDraft(const std::string& name) const {
    auto it = draft_index_.find(name);
    return it == draft_index_.end() ? -1 : it->second;
  }

  const UrdfImportOptions& options_;
  std::string source_;
  std::vector<std::string> warnings_;
  urdf_detail::XmlScan scan_;
  urdf_detail::Extensions ext_;
  std::vector<Link> links_;
  std::map<std::string, int> link_index_;
  std::vector<Draft> drafts_;
  std::map<std::string, int> draft_index_;
  std::string root_;
};

UrdfImportResult Importer::Run(const std::string& xml) {
  // Both limits before any XML parser runs: TinyXML recurses per element.
  if (xml.size() > options_.max_file_bytes) {
    Fail(std::to_string(xml.size()) + " bytes is more than the limit of " +
         std::to_string(options_.max_file_bytes) + " bytes (UrdfImportOptions::max_file_bytes)");
  }
  urdf_detail::CheckXmlDepth(xml, options_.max_xml_depth, source_);
  TiXmlDocument doc;
  doc.Parse(xml.c_str(), nullptr, TIXML_ENCODING_UTF8);
  if (doc.Error()) {
    Fail("malformed XML at line " + std::to_string(doc.ErrorRow()) + ", column " +
         std::to_string(doc.ErrorCol()) + ": " + doc.ErrorDesc());
  }
  const TiXmlElement* robot = doc.RootElement();
  if (robot == nullptr || std::string(robot->Value()) != "robot") {
    Fail("the root element is " + (robot ? "<" + std::string(robot->Value()) + ">" : std::string("missing")) +
         ", not <robot>");
  }
  scan_ = urdf_detail::ScanRobot(*robot, source_);
  urdf::ModelInterfaceSharedPtr model = ParseWithUrdfdom(xml);
  // In a file with a cycle urdfdom's links own each other through
  // child_links, and the model would leak; cut those links when done.
  struct CutTree {
    urdf::ModelInterface& model;
    ~CutTree() {
      for (auto& [name, link] : model.links_) {
        link->child_links.clear();
        link->child_joints.clear();
      }
    }
  } cut_tree{*model};
  ext_ = urdf_detail::ParseExtensions(*robot, source_);

  ImportLinks(*model);
  CheckTree(*model);
  ImportJoints(*model);
  ResolveMimics();
  ApplyExtensions();
  if (options_.merge_massless_chains) MergeMasslessChains();
  RobotModel built = Build(options_.robot_name.empty() ? model->getName() : options_.robot_name);
  if (options_.strict && !warnings_.empty()) {
    Fail("strict import refuses " + std::to_string(warnings_.size()) +
         " warning(s): " + Join(warnings_, "; "));
  }
  return UrdfImportResult{std::move(built), std::move(warnings_)};
}

urdf::ModelInterfaceSharedPtr Importer::ParseWithUrdfdom(const std::string& xml) {
  urdf_detail::UrdfdomMessages messages;
  urdf::ModelInterfaceSharedPtr model = urdf_detail::ParseQuietly(xml, messages);
  // urdfdom logs an error yet returns a model for some defects (an <inertial>
  // without <inertia> is dropped); a dropped mass is not a repair we accept.
  if (!model || !messages.errors.empty()) {
    Fail("urdfdom rejected the file: " +
         (messages.errors.empty() ? std::string("no reason given") : Join(messages.errors, "; ")));
  }
  for (const std::string& w : messages.warnings) Warn("urdfdom: " + w);
  return model;
}

void Importer::ImportLinks(const urdf::ModelInterface& model) {
  for (const std::string& name : scan_.links) {
    urdf::LinkConstSharedPtr l = model.getLink(name);
    if (!l) Fail("urdfdom lost link " + Quote(name));
    Link link{.name = name};
    if (const urdf::InertialSharedPtr& in = l->inertial) {
      const std::string what = "link " + Quote(name) + ": ";
      if (!std::isfinite(in->mass)) Fail(what + "mass is not finite");
      if (in->mass < 0) Fail(what + "negative mass " + Num(in->mass) + " kg");
      link.mass = in->mass;
      link.com = ToEigen(in->origin.position);
      Eigen::Matrix3d inertia;
      inertia << in->ixx, in->ixy, in->ixz, in->ixy, in->iyy, in->iyz, in->ixz, in->iyz, in->izz;
      if (!link.com.allFinite() || !inertia.allFinite())
        Fail(what + "inertial origin or inertia is not finite");
      const Eigen::Quaterniond q = ToEigen(in->origin.rotation);
      if (q.coeffs() != Eigen::Quaterniond::Identity().coeffs()) {
        // URDF gives the inertia in the inertial frame; RoboTalk wants it in
        // link axes. Averaging with the transpose makes it exactly symmetric.
        const Eigen::Matrix3d r = q.toRotationMatrix();
        const Eigen::Matrix3d rotated = r * inertia * r.transpose();
        inertia = 0.5 * (rotated + rotated.transpose());
      }
      link.inertia = inertia;
      if (link.mass > 0) {
        Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(link.inertia, Eigen::EigenvaluesOnly);
        if (eig.eigenvalues().minCoeff() <= 0) {
          Fail(what + "mass " + Num(link.mass) +
               " kg but the inertia is not positive-definite (principal moments " + Vec(eig.eigenvalues()) +
               ")");
        }
      }
    }
    link_index_.emplace(name, static_cast<int>(links_.size()));
    links_.push_back(std::move(link));
  }
}

// Parents from the flat joint list: one parent per link, no cycle, one root.
void Importer::CheckTree(const urdf::ModelInterface& model) {
  const size_t n = links_.size();
  std::vector<int> parent(n, -1);
  std::vector<std::string> parent_joint(n);
  for (const std::string& name : scan_.joints) {
    urdf::JointConstSharedPtr j = model.getJoint(name);
    if (!j) Fail("urdfdom lost joint " + Quote(name));
    auto p = link_index_.find(j->parent_link_name);
    auto c = link_index_.find(j->child_link_name);
    if (p == link_index_.end())
      Fail("joint " + Quote(name) + ": unknown parent link " + Quote(j->parent_link_name));
    if (c == link_index_.end())
      Fail("joint " + Quote(name) + ": unknown child link " + Quote(j->child_link_name));
    if (p->second == c->second)
      Fail("joint " + Quote(name) + " joins link " + Quote(p->first) + " to itself");
    const size_t child = static_cast<size_t>(c->second);
    if (parent[child] >= 0) {
      Fail("not a tree: link " + Quote(c->first) + " has two parent joints, " + Quote(parent_joint[child]) +
           " and " + Quote(name));
    }
    parent[child] = p->second;
    parent_joint[child] = name;
  }
  // Walk up from every link; a link met twice on one walk is on a cycle.
  // Each link is walked over once: a walk stops at a link an earlier walk
  // proved to reach the root, and on_path marks links with the walk's number.
  std::vector<char> reaches_root(n, 0);
  std::vector<size_t> on_path(n, SIZE_MAX);
  std::vector<int> path;
  for (size_t start = 0; start < n; ++start) {
    path.clear();
    int cur = static_cast<int>(start);
    while (!reaches_root[static_cast<size_t>(cur)]) {
      if (on_path[static_cast<size_t>(cur)] == start) {
        std::string cycle = Quote(links_[static_cast<size_t>(cur)].name);
        for (int l = parent[static_cast<size_t>(cur)]; l != cur; l = parent[static_cast<size_t>(l)]) {
          cycle += " <- " + Quote(links_[static_cast<size_t>(l)].name);
        }
        Fail("not a tree: the joints form a cycle through links " + cycle + " <- " +
             Quote(links_[static_cast<size_t>(cur)].name));
      }
      on_path[static_cast<size_t>(cur)] = start;
      path.push_back(cur);
      if (parent[static_cast<size_t>(cur)] < 0) break;
      cur = parent[static_cast<size_t>(cur)];
    }
    for (int l : path) reaches_root[static_cast<size_t>(l)] = 1;
  }
  std::vector<std::string> roots;
  for (size_t l = 0; l < n; ++l) {
    if (parent[l] < 0) roots.push_back(links_[l].name);
  }
  if (roots.size() != 1) {
    std::vector<std::string> quoted;
    for (const std::string& r : roots) quoted.push_back(Quote(r));
    Fail("expected one root link, found " + std::to_string(roots.size()) + ": " + Join(quoted, ", "));
  }
  root_ = roots.front();
}

DofLimits Importer::OneDofLimits(const urdf::Joint& j, const urdf_detail::XmlJoint& xml) {
  const std::string what = "joint " + Quote(j.name) + ": ";
  DofLimits limits;
  const bool continuous = j.type == urdf::Joint::CONTINUOUS;
  if (!j.limits) {
    // urdfdom insists on <limit> for revolute and prismatic joints.
    Warn(what + "no <limit>; velocity and effort unlimited");
    return limits;
  }
  const urdf::JointLimits& l = *j.limits;
  if (continuous) {
    if (xml.has_lower || xml.has_upper) {
      Warn(what + "lower/upper limits on a continuous joint ignored");
    }
  } else {
    if (!xml.has_lower || !xml.has_upper) {
      Warn(what + "<limit> lacks " + std::string(!xml.has_lower ? "lower" : "upper") +
           "; the URDF default 0 is used");
    }
    if (!std::isfinite(l.lower) || !std::isfinite(l.upper)) Fail(what + "position limit is not finite");
    limits.lower = l.lower;
    limits.upper = l.upper;
    if (limits.lower > limits.upper) {
      Warn(what + "lower limit " + Num(l.lower) + " > upper " + Num(l.upper) + "; swapped");
      std::swap(limits.lower, limits.upper);
    }
  }
  auto rate = [&](double value, const char* name, double& out) {
    if (std::isnan(value) || value < 0) Fail(what + "negative or NaN " + name + " limit " + Num(value));
    if (value == 0) {
      Warn(what + name + " limit 0 taken as not given; unlimited");
    } else {
      out = value;
    }
  };
  rate(l.velocity, "velocity", limits.velocity);
  rate(l.effort, "effort", limits.effort);
  return limits;
}

std::vector<Dof> Importer::MakeDofs(const urdf::Joint& j, const urdf_detail::XmlJoint& xml) {
  const std::string what = "joint " + Quote(j.name) + ": ";
  auto unit_axis = [&]() -> Eigen::Vector3d {
    const Eigen::Vector3d axis = ToEigen(j.axis);
    if (!axis.allFinite()) Fail(what + "axis " + Vec(axis) + " is not finite");
    const double norm = axis.norm();
    if (norm == 0) Fail(what + "zero axis");
    if (std::abs(norm - 1) > kAxisTolerance)
      Warn(what + "axis " + Vec(axis) + " is not a unit vector; normalised");
    return axis / norm;
  };
  switch (j.type) {
    case urdf::Joint::REVOLUTE:
    case urdf::Joint::CONTINUOUS:
      return {Dof{.type = DofType::kRevolute, .axis = unit_axis(), .limits = OneDofLimits(j, xml)}};
    case urdf::Joint::PRISMATIC:
      return {Dof{.type = DofType::kPrismatic, .axis = unit_axis(), .limits = OneDofLimits(j, xml)}};
    case urdf::Joint::FIXED:
      if (xml.has_limit) Warn(what + "<limit> on a fixed joint ignored");
      return {};
    case urdf::Joint::PLANAR: {
      if (xml.has_limit) Warn(what + "<limit> on a planar joint ignored");
      // In-plane basis: u is the coordinate axis least aligned with the normal
      // (x before y before z on ties) made orthogonal to it; v = n x u.
      // The normal z gives u = x, v = y.
      const Eigen::Vector3d n = unit_axis();
      int least = 0;
      for (int k = 1; k < 3; ++k) {
        if (std::abs(n[k]) < std::abs(n[least])) least = k;
      }
      const Eigen::Vector3d e = Eigen::Vector3d::Unit(least);
      const Eigen::Vector3d u = (e - e.dot(n) * n).normalized();
      const Eigen::Vector3d v = n.cross(u).normalized();
      return {Dof{.type = DofType::kPrismatic, .axis = u}, Dof{.type = DofType::kPrismatic, .axis = v},
              Dof{.type = DofType::kRevolute, .axis = n}};
    }
    case urdf::Joint::FLOATING: {
      if (xml.has_limit) Warn(what + "<limit> on a floating joint ignored");
      std::vector<Dof> dofs;
      for (DofType type : {DofType::kPrismatic, DofType::kRevolute}) {
        for (int k = 0; k < 3; ++k) dofs.push_back(Dof{.type = type, .axis = Eigen::Vector3d::Unit(k)});
      }
      return dofs;
    }
    default:
      Fail(what + "unknown joint type");
  }
}

void Importer::ImportJoints(const urdf::ModelInterface& model) {
  for (const std::string& name : scan_.joints) {
    const urdf::Joint& j = *model.getJoint(name);
    const urdf_detail::XmlJoint& xml = scan_.joint_info.at(name);
    Draft d;
    d.parent = j.parent_link_name;
    d.child = j.child_link_name;
    d.origin = ToEigen(j.parent_to_joint_origin_transform.position);
    const Eigen::Quaterniond rest = ToEigen(j.parent_to_joint_origin_transform.rotation);
    if (!d.origin.allFinite() || !rest.coeffs().allFinite())
      Fail("joint " + Quote(name) + ": origin is not finite");
    d.joint.name = name;
    d.joint.inboard = d.origin - links_[static_cast<size_t>(LinkIndex(d.parent))].com;
    d.joint.outboard = -links_[static_cast<size_t>(LinkIndex(d.child))].com;
    d.joint.rest = rest;
    d.joint.dofs = MakeDofs(j, xml);
    if (j.mimic) {
      d.leader = j.mimic->joint_name;
      d.multiplier = j.mimic->multiplier;
      d.offset = j.mimic->offset;
    }
    draft_index_.emplace(name, static_cast<int>(drafts_.size()));
    drafts_.push_back(std::move(d));
  }
}

// Keeps the mimics RobotModel can represent; a chain of mimics is flattened
// onto its first leader.
void Importer::ResolveMimics() {
  for (Draft& d : drafts_) {
    if (!d.leader) continue;
    const std::string what = "joint " + Quote(d.joint.name) + ": mimic of " + Quote(*d.leader);
    const int leader = FindDraft(*d.leader);
    std::string reason;
    if (leader < 0) {
      reason = "names an unknown joint";
    } else if (&drafts_[static_cast<size_t>(leader)] == &d) {
      reason = "names the joint itself";
    } else if (drafts_[static_cast<size_t>(leader)].joint.dofs.size() != 1) {
      reason = "needs a 1-dof leader; it has " +
               std::to_string(drafts_[static_cast<size_t>(leader)].joint.dofs.size());
    } else if (d.joint.dofs.size() != 1) {
      reason = "needs a 1-dof joint; this one has " + std::to_string(d.joint.dofs.size());
    } else if (!std::isfinite(d.multiplier) || !std::isfinite(d.offset)) {
      reason = "has a non-finite multiplier or offset";
    }
    if (!reason.empty()) {
      Warn(what + " " + reason + "; mimic dropped");
      d.leader.reset();
    }
  }
  FlattenMimicChains();
}

// A mimic of a mimic follows the first leader: each joint's chain is walked
// once (state: 0 not seen, 1 on this walk, 2 resolved, 3 on or into a cycle),
// then resolved from its leader's end, so the work is linear in joints.
void Importer::FlattenMimicChains() {
  enum : char { kNew, kOnWalk, kResolved, kCycle };
  std::vector<char> state(drafts_.size(), kNew);
  std::vector<size_t> walk;
  for (size_t start = 0; start < drafts_.size(); ++start) {
    walk.clear();
    size_t cur = start;
    while (state[cur] == kNew && drafts_[cur].leader) {
      state[cur] = kOnWalk;
      walk.push_back(cur);
      cur = static_cast<size_t>(FindDraft(*drafts_[cur].leader));
    }
    const bool cycle = state[cur] == kOnWalk || state[cur] == kCycle;
    for (auto it = walk.rbegin(); it != walk.rend(); ++it) {
      Draft& d = drafts_[*it];
      state[*it] = cycle ? kCycle : kResolved;
      if (cycle) {
        Warn("joint " + Quote(d.joint.name) + ": mimic joints form a cycle; mimic dropped");
        d.leader.reset();
        continue;
      }
      const Draft& lead = drafts_[static_cast<size_t>(FindDraft(*d.leader))];
      if (!lead.leader) continue;  // already resolved: follows a joint that mimics nothing
      Warn("joint " + Quote(d.joint.name) + ": mimics " + Quote(lead.joint.name) + ", itself a mimic of " +
           Quote(*lead.leader) + "; now follows " + Quote(*lead.leader) + " directly");
      d.offset = d.multiplier * lead.offset + d.offset;
      d.multiplier *= lead.multiplier;
      d.leader = lead.leader;
    }
  }
}

void Importer::ApplyExtensions() {
  // Defaults: see docs/urdf_import.md, "Servo types".
  for (Draft& d : drafts_) {
    ServoTypes types;
    if (!d.joint.dofs.empty() && !d.leader) {
      types = ServoTypes(ServoType::kSetPoint) | ServoType::kSpeed;
      bool effort_known = true;
      for (const Dof& dof : d.joint.dofs) effort_known = effort_known && std::isfinite(dof.limits.effort);
      if (effort_known) types = types | ServoType::kForce;
    }
    d.joint.servo_types = types;
  }
  for (const urdf_detail::Extensions::Servo& s : ext_.servos) {
    const std::string at =
        "<robotalk>: <servo joint=" + Quote(s.joint) + "> (line " + std::to_string(s.line) + "): ";
    const int index = FindDraft(s.joint);
    if (index < 0) Fail(at + "unknown joint " + Quote(s.joint));
    Draft& d = drafts_[static_cast<size_t>(index)];
    if (!s.types.empty() && d.joint.dofs.empty()) Fail(at + "a fixed joint takes no servo commands");
    if (!s.types.empty() && d.leader)
      Fail(at + "a mimic joint takes no servo commands (it follows " + Quote(*d.leader) + ")");
    d.joint.servo_types = s.types;
  }
  for (const urdf_detail::Extensions::Frame& f : ext_.frames) {
    if (!link_index_.contains(f.link)) {
      Fail("<robotalk>: <control_frame name=" + Quote(f.name) + "> (line " + std::to_string(f.line) +
           "): unknown link " + Quote(f.link));
    }
  }
  if (ext_.base && ext_.base->link && *ext_.base->link != root_) {
    const std::string at = "<robotalk>: <base link=" + Quote(*ext_.base->link) + "> (line " +
                           std::to_string(ext_.base->line) + "): ";
    if (!link_index_.contains(*ext_.base->link)) Fail(at + "unknown link");
    Fail(at + "not the root link (the root is " + Quote(root_) + ")");
  }
}

// J1 (P -> M) and J2 (M -> C) become one joint when M is a massless link that
// only carries C, has no control frame and J2 adds no translation:
//   Tr(o1) R1 M1(q1) R2 M2(q2) = Tr(o1) (R1 R2) (R2^T M1(q1) R2) M2(q2),
// so J1's dof axes are rotated by R2^T and J2's follow unchanged.
// Joints are visited top-down (breadth-first from the root) and each one
// absorbs the chain below it while it can, so every joint and link is looked
// at a bounded number of times: linear in the size of the model.
void Importer::MergeMasslessChains() {
  const size_t num_links = links_.size();
  std::vector<char> framed(num_links, 0);
  for (const auto& f : ext_.frames) framed[static_cast<size_t>(LinkIndex(f.link))] = 1;
  std::set<std::string> mimic_involved;
  for (const Draft& d : drafts_) {
    if (d.leader) {
      mimic_involved.insert(d.joint.name);
      mimic_involved.insert(*d.leader);
    }
  }
  std::vector<std::vector<int>> child_joints(num_links);
  for (size_t i = 0; i < drafts_.size(); ++i)
    child_joints[static_cast<size_t>(LinkIndex(drafts_[i].parent))].push_back(static_cast<int>(i));
  std::vector<int> order;  // joints, parents before children
  std::vector<int> links_to_visit{LinkIndex(root_)};
  for (size_t k = 0; k < links_to_visit.size(); ++k) {
    for (int j : child_joints[static_cast<size_t>(links_to_visit[k])]) {
      order.push_back(j);
      links_to_visit.push_back(LinkIndex(drafts_[static_cast<size_t>(j)].child));
    }
  }

  std::vector<char> joint_gone(drafts_.size(), 0);
  std::vector<char> link_gone(num_links, 0);
  for (int h : order) {
    if (joint_gone[static_cast<size_t>(h)]) continue;
    Draft& head = drafts_[static_cast<size_t>(h)];
    if (head.joint.dofs.empty() || mimic_involved.contains(head.joint.name)) continue;
    for (;;) {
      const size_t m = static_cast<size_t>(LinkIndex(head.child));
      if (links_[m].mass != 0 || child_joints[m].size() != 1 || framed[m]) break;
      const size_t i2 = static_cast<size_t>(child_joints[m].front());
      const Draft& j2 = drafts_[i2];
      if (!j2.origin.isZero(0.0) || j2.joint.dofs.empty() ||
          head.joint.dofs.size() + j2.joint.dofs.size() > 6 || mimic_involved.contains(j2.joint.name)) {
        break;
      }
      const Eigen::Matrix3d r2t = j2.joint.rest.toRotationMatrix().transpose();
      for (Dof& dof : head.joint.dofs) dof.axis = (r2t * dof.axis).normalized();
      for (const Dof& dof : j2.joint.dofs) head.joint.dofs.push_back(dof);
      head.joint.name += "+" + j2.joint.name;
      head.joint.rest = (head.joint.rest * j2.joint.rest).normalized();
      head.joint.outboard = j2.joint.outboard;
      head.joint.servo_types =
          ServoTypes::FromBits(head.joint.servo_types.bits() & j2.joint.servo_types.bits());
      head.child = j2.child;
      joint_gone[i2] = 1;
      link_gone[m] = 1;
    }
  }

  std::vector<Draft> drafts;
  for (size_t i = 0; i < drafts_.size(); ++i) {
    if (!joint_gone[i]) drafts.push_back(std::move(drafts_[i]));
  }
  drafts_ = std::move(drafts);
  draft_index_.clear();  // the merged joints have new names
  std::vector<Link> links;
  for (size_t l = 0; l < num_links; ++l) {
    if (!link_gone[l]) links.push_back(std::move(links_[l]));
  }
  links_ = std::move(links);
  link_index_.clear();
  for (size_t l = 0; l < links_.size(); ++l) link_index_.emplace(links_[l].name, static_cast<int>(l));
}

RobotModel Importer::Build(const std::string& robot_name) {
  RobotModelBuilder builder(robot_name);
  for (const Link& link : links_) builder.AddLink(link);
  for (const Draft& d : drafts_) builder.AddJoint(d.joint, d.parent, d.child);
  for (const Draft& d : drafts_) {
    if (d.leader) builder.SetMimic(d.joint.name, *d.leader, d.multiplier, d.offset);
  }
  for (const auto& f : ext_.frames) {
    builder.AddControlFrame(ControlFrame{.name = f.name, .pose_in_link = f.pose, .servo_types = f.servo},
                            f.link);
  }
  if (ext_.base) {
    builder.SetRoot(root_, ext_.base->pose, ext_.base->type);
  } else {
    builder.SetRoot(root_, Pose{}, BaseType::kFixed);
  }
  try {
    return builder.Build();
  } catch (const ModelError& e) {
    Fail(e.what());
  }
}

}  // namespace

UrdfImportResult LoadUrdfFile(const std::string& path, const UrdfImportOptions& options) {
  const std::string text = urdf_detail::ReadLimited(path, options.max_file_bytes, "LoadUrdfFile");
  return ParseUrdf(text, options, path);
}

UrdfImportResult ParseUrdf(const std::string& xml, const UrdfImportOptions& options,
                           const std::string& source_name) {
  return Importer(options, source_name).Run(xml);
}

}  // namespace robotalk
