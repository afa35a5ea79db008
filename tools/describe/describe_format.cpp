#include "describe_format.h"

#include <cmath>
#include <iomanip>
#include <sstream>

namespace robotalk {
namespace {

std::string Num(double v, int precision = 4) {
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  std::ostringstream s;
  s << std::setprecision(precision) << v;
  return s.str();
}

std::string Vec(const Eigen::Vector3d& v, int precision = 4) {
  return "(" + Num(v.x(), precision) + ", " + Num(v.y(), precision) + ", " + Num(v.z(), precision) + ")";
}

std::string DofText(const Dof& dof) {
  std::string s = dof.type == DofType::kRevolute ? "R" : "P";
  s += Vec(dof.axis, 3);
  return s;
}

std::string LimitText(const Dof& dof) {
  const DofLimits& l = dof.limits;
  std::string pos = std::isinf(l.lower) && std::isinf(l.upper)
                        ? "unbounded"
                        : "[" + Num(l.lower) + ", " + Num(l.upper) + "]";
  return pos + " v<=" + Num(l.velocity) + " f<=" + Num(l.effort);
}

using Json = nlohmann::ordered_json;

Json JsonVec(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }
Json JsonQuat(const Eigen::Quaterniond& q) { return {q.w(), q.x(), q.y(), q.z()}; }

Json JsonServo(ServoTypes t) {
  Json words = Json::array();
  for (auto [type, word] : {std::pair{ServoType::kSetPoint, "setpoint"},
                            std::pair{ServoType::kSpeed, "speed"}, std::pair{ServoType::kForce, "force"}}) {
    if (t.Has(type)) words.push_back(word);
  }
  return words;
}

}  // namespace

void PrintModelTable(const RobotModel& m, std::ostream& out) {
  out << "Robot '" << m.name() << "': " << m.links().size() << " links, " << m.joints().size() << " joints, "
      << m.num_dofs() << " dofs, " << m.frames().size() << " control frames, total mass "
      << Num(m.total_mass(), 6) << " kg\n";
  for (const RootLink& r : m.roots()) {
    out << "Root '" << m.link(r.link).name << "' (" << ToString(r.base) << " base) at "
        << Vec(r.pose_in_world.translation) << "\n";
  }

  out << "\nLinks\n";
  out << std::left << std::setw(4) << "#" << std::setw(28) << "name" << std::setw(11) << "mass [kg]"
      << "COM [m]\n";
  for (size_t i = 0; i < m.links().size(); ++i) {
    const Link& l = m.links()[i];
    out << std::left << std::setw(4) << i << std::setw(28) << l.name << std::setw(11) << Num(l.mass)
        << Vec(l.com) << "\n";
  }

  out << "\nJoints (dofs: R revolute / P prismatic with axis; limits in rad|m, rad/s|m/s, N·m|N)\n";
  out << std::left << std::setw(4) << "#" << std::setw(28) << "name" << std::setw(44) << "parent -> child"
      << std::setw(22) << "servo"
      << "dofs and limits\n";
  for (size_t i = 0; i < m.joints().size(); ++i) {
    const Joint& j = m.joints()[i];
    std::string servo = j.servo_types.ToString();
    if (j.mimic) servo = "mimic " + m.joint(j.mimic->leader_joint).name;
    out << std::left << std::setw(4) << i << std::setw(28) << j.name << std::setw(44)
        << (m.link(j.parent_link).name + " -> " + m.link(j.child_link).name) << std::setw(22) << servo;
    if (j.dofs.empty()) out << "fixed";
    for (size_t k = 0; k < j.dofs.size(); ++k) {
      if (k > 0) out << "\n" << std::string(98, ' ');
      out << DofText(j.dofs[k]) << " " << LimitText(j.dofs[k]);
    }
    out << "\n";
  }

  out << "\nControl frames\n";
  if (m.frames().empty()) out << "(none)\n";
  for (size_t i = 0; i < m.frames().size(); ++i) {
    const ControlFrame& f = m.frames()[i];
    out << std::left << std::setw(4) << i << std::setw(28) << f.name << std::setw(28)
        << m.link(f.parent_link).name << std::setw(22) << f.servo_types.ToString()
        << Vec(f.pose_in_link.translation) << "\n";
  }
}

Json ModelJson(const RobotModel& m, const std::vector<std::string>& warnings) {
  Json links = Json::array();
  for (const Link& l : m.links()) {
    const Eigen::Matrix3d& I = l.inertia;
    links.push_back({{"name", l.name},
                     {"mass", l.mass},
                     {"com", JsonVec(l.com)},
                     {"inertia", {I(0, 0), I(0, 1), I(0, 2), I(1, 1), I(1, 2), I(2, 2)}}});
  }
  Json joints = Json::array();
  for (const Joint& j : m.joints()) {
    Json dofs = Json::array();
    for (const Dof& d : j.dofs) {
      dofs.push_back({{"type", ToString(d.type)},
                      {"axis", JsonVec(d.axis)},
                      {"lower", d.limits.lower},
                      {"upper", d.limits.upper},
                      {"velocity", d.limits.velocity},
                      {"effort", d.limits.effort}});
    }
    Json joint = {{"name", j.name},
                  {"parent", m.link(j.parent_link).name},
                  {"child", m.link(j.child_link).name},
                  {"inboard", JsonVec(j.inboard)},
                  {"outboard", JsonVec(j.outboard)},
                  {"rest", JsonQuat(j.rest)},
                  {"servo", JsonServo(j.servo_types)},
                  {"dofs", dofs}};
    if (j.mimic) {
      joint["mimic"] = {{"joint", m.joint(j.mimic->leader_joint).name},
                        {"multiplier", j.mimic->multiplier},
                        {"offset", j.mimic->offset}};
    }
    joints.push_back(joint);
  }
  Json frames = Json::array();
  for (const ControlFrame& f : m.frames()) {
    frames.push_back({{"name", f.name},
                      {"link", m.link(f.parent_link).name},
                      {"position", JsonVec(f.pose_in_link.translation)},
                      {"orientation", JsonQuat(f.pose_in_link.rotation)},
                      {"servo", JsonServo(f.servo_types)}});
  }
  Json roots = Json::array();
  for (const RootLink& r : m.roots()) {
    roots.push_back({{"link", m.link(r.link).name},
                     {"base", ToString(r.base)},
                     {"position", JsonVec(r.pose_in_world.translation)},
                     {"orientation", JsonQuat(r.pose_in_world.rotation)}});
  }
  return {
      {"name", m.name()}, {"total_mass", m.total_mass()}, {"num_dofs", m.num_dofs()}, {"links", links},
      {"joints", joints}, {"control_frames", frames},     {"roots", roots},           {"warnings", warnings}};
}

void PrintModelJson(const RobotModel& model, const std::vector<std::string>& warnings, std::ostream& out) {
  out << JsonText(ModelJson(model, warnings)) << "\n";
}

}  // namespace robotalk
