#include "describe_format.h"

#include <cmath>
#include <cstdio>
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

// Escapes a string for JSON (names come from user files).
std::string JsonString(const std::string& s) {
  std::string out = "\"";
  for (unsigned char c : s) {
    switch (c) {
      case '"':
        out += "\\\"";
        break;
      case '\\':
        out += "\\\\";
        break;
      case '\n':
        out += "\\n";
        break;
      case '\t':
        out += "\\t";
        break;
      case '\r':
        out += "\\r";
        break;
      default:
        if (c < 0x20) {
          char buf[8];
          std::snprintf(buf, sizeof buf, "\\u%04x", c);
          out += buf;
        } else {
          out += static_cast<char>(c);
        }
    }
  }
  return out + "\"";
}

std::string JsonNum(double v) {
  if (!std::isfinite(v)) return "null";
  std::ostringstream s;
  s << std::setprecision(17) << v;
  return s.str();
}

std::string JsonVec(const Eigen::Vector3d& v) {
  return "[" + JsonNum(v.x()) + ", " + JsonNum(v.y()) + ", " + JsonNum(v.z()) + "]";
}

std::string JsonQuat(const Eigen::Quaterniond& q) {
  return "[" + JsonNum(q.w()) + ", " + JsonNum(q.x()) + ", " + JsonNum(q.y()) + ", " + JsonNum(q.z()) + "]";
}

std::string JsonServo(ServoTypes t) {
  std::string s = "[";
  bool first = true;
  for (auto [type, word] : {std::pair{ServoType::kSetPoint, "setpoint"},
                            std::pair{ServoType::kSpeed, "speed"}, std::pair{ServoType::kForce, "force"}}) {
    if (!t.Has(type)) continue;
    s += (first ? "\"" : ", \"") + std::string(word) + "\"";
    first = false;
  }
  return s + "]";
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

void PrintModelJson(const RobotModel& m, const std::vector<std::string>& warnings, std::ostream& out) {
  out << "{\n  \"name\": " << JsonString(m.name()) << ",\n  \"total_mass\": " << JsonNum(m.total_mass())
      << ",\n  \"num_dofs\": " << m.num_dofs() << ",\n  \"links\": [";
  for (size_t i = 0; i < m.links().size(); ++i) {
    const Link& l = m.links()[i];
    const Eigen::Matrix3d& I = l.inertia;
    out << (i ? ",\n    " : "\n    ") << "{\"name\": " << JsonString(l.name)
        << ", \"mass\": " << JsonNum(l.mass) << ", \"com\": " << JsonVec(l.com) << ", \"inertia\": ["
        << JsonNum(I(0, 0)) << ", " << JsonNum(I(0, 1)) << ", " << JsonNum(I(0, 2)) << ", "
        << JsonNum(I(1, 1)) << ", " << JsonNum(I(1, 2)) << ", " << JsonNum(I(2, 2)) << "]}";
  }
  out << "\n  ],\n  \"joints\": [";
  for (size_t i = 0; i < m.joints().size(); ++i) {
    const Joint& j = m.joints()[i];
    out << (i ? ",\n    " : "\n    ") << "{\"name\": " << JsonString(j.name)
        << ", \"parent\": " << JsonString(m.link(j.parent_link).name)
        << ", \"child\": " << JsonString(m.link(j.child_link).name) << ", \"inboard\": " << JsonVec(j.inboard)
        << ", \"outboard\": " << JsonVec(j.outboard) << ", \"rest\": " << JsonQuat(j.rest)
        << ", \"servo\": " << JsonServo(j.servo_types) << ", \"dofs\": [";
    for (size_t k = 0; k < j.dofs.size(); ++k) {
      const Dof& d = j.dofs[k];
      out << (k ? ", " : "") << "{\"type\": \"" << ToString(d.type) << "\", \"axis\": " << JsonVec(d.axis)
          << ", \"lower\": " << JsonNum(d.limits.lower) << ", \"upper\": " << JsonNum(d.limits.upper)
          << ", \"velocity\": " << JsonNum(d.limits.velocity) << ", \"effort\": " << JsonNum(d.limits.effort)
          << "}";
    }
    out << "]";
    if (j.mimic) {
      out << ", \"mimic\": {\"joint\": " << JsonString(m.joint(j.mimic->leader_joint).name)
          << ", \"multiplier\": " << JsonNum(j.mimic->multiplier)
          << ", \"offset\": " << JsonNum(j.mimic->offset) << "}";
    }
    out << "}";
  }
  out << "\n  ],\n  \"control_frames\": [";
  for (size_t i = 0; i < m.frames().size(); ++i) {
    const ControlFrame& f = m.frames()[i];
    out << (i ? ",\n    " : "\n    ") << "{\"name\": " << JsonString(f.name)
        << ", \"link\": " << JsonString(m.link(f.parent_link).name)
        << ", \"position\": " << JsonVec(f.pose_in_link.translation)
        << ", \"orientation\": " << JsonQuat(f.pose_in_link.rotation)
        << ", \"servo\": " << JsonServo(f.servo_types) << "}";
  }
  out << "\n  ],\n  \"roots\": [";
  for (size_t i = 0; i < m.roots().size(); ++i) {
    const RootLink& r = m.roots()[i];
    out << (i ? ", " : "") << "{\"link\": " << JsonString(m.link(r.link).name) << ", \"base\": \""
        << ToString(r.base) << "\", \"position\": " << JsonVec(r.pose_in_world.translation)
        << ", \"orientation\": " << JsonQuat(r.pose_in_world.rotation) << "}";
  }
  out << "],\n  \"warnings\": [";
  for (size_t i = 0; i < warnings.size(); ++i) out << (i ? ", " : "") << JsonString(warnings[i]);
  out << "]\n}\n";
}

}  // namespace robotalk
