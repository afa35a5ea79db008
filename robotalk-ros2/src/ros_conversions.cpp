#include "ros_conversions.h"

#include "robotalk/error.h"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <map>
#include <sstream>

namespace robotalk::ros2 {

RosTime ToRosTime(SystemTime t) {
  const auto ns = t.time_since_epoch().count();
  const auto sec = ns >= 0 ? ns / 1000000000 : -((-ns + 999999999) / 1000000000);
  return RosTime{static_cast<std::int32_t>(sec), static_cast<std::uint32_t>(ns - sec * 1000000000)};
}

SystemTime FromRosTime(RosTime t) {
  return SystemTime(std::chrono::seconds(t.sec) + std::chrono::nanoseconds(t.nanosec));
}

std::string RosNameToken(const std::string& robot) {
  std::string out;
  for (char c : robot) out += std::isalnum(static_cast<unsigned char>(c)) || c == '_' ? c : '_';
  if (out.empty() || std::isdigit(static_cast<unsigned char>(out[0]))) out.insert(out.begin(), '_');
  return out;
}

std::vector<std::string> JointStateNames(const RobotModel& model) {
  std::vector<std::string> names(static_cast<std::size_t>(model.num_dofs()));
  for (int j = 0; j < static_cast<int>(model.joints().size()); ++j) {
    const Joint& joint = model.joint(j);
    for (std::size_t k = 0; k < joint.dofs.size(); ++k) {
      names[static_cast<std::size_t>(model.dof_offset(j)) + k] =
          joint.dofs.size() == 1 ? joint.name : joint.name + "/" + std::to_string(k);
    }
  }
  return names;
}

// --- TF ----------------------------------------------------------------------

Eigen::Isometry3d RobotFrames::RootPose(const RootLink& root, const BaseState& base) {
  // The model's pose with its yaw replaced by θ and its x y by the base's.
  const Eigen::Isometry3d model = root.pose_in_world.ToIsometry();
  const Eigen::Matrix3d r = model.linear();
  const double model_yaw = std::atan2(r(1, 0), r(0, 0));
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = Eigen::AngleAxisd(base.theta - model_yaw, Eigen::Vector3d::UnitZ()) * r;
  pose.translation() = Eigen::Vector3d(base.x, base.y, model.translation().z());
  return pose;
}

RobotFrames::RobotFrames(const RobotModel& model, std::string prefix, std::string world_frame)
    : model_(model), kin_(model), q_(Eigen::VectorXd::Zero(model.num_dofs())) {
  const auto frame_id = [&](const std::string& name) { return prefix + name; };
  kin_.Update(q_);
  for (int j = 0; j < static_cast<int>(model.joints().size()); ++j) {
    const Joint& joint = model.joint(j);
    FrameTransform t{frame_id(model.link(joint.parent_link).name),
                     frame_id(model.link(joint.child_link).name),
                     kin_.link_pose(joint.parent_link).inverse() * kin_.link_pose(joint.child_link)};
    if (joint.dofs.empty()) {
      static_.push_back(std::move(t));
    } else {
      moving_.push_back(std::move(t));
      moving_joints_.push_back(j);
    }
  }
  for (int f = 0; f < static_cast<int>(model.frames().size()); ++f) {
    const ControlFrame& frame = model.frame(f);
    static_.push_back({frame_id(model.link(frame.parent_link).name), frame_id(frame.name),
                       frame.pose_in_link.ToIsometry()});
  }
  for (int r = 0; r < static_cast<int>(model.roots().size()); ++r) {
    const RootLink& root = model.roots()[static_cast<std::size_t>(r)];
    root_poses_.push_back(root.pose_in_world.ToIsometry());
    FrameTransform t{world_frame, frame_id(model.link(root.link).name), root.pose_in_world.ToIsometry()};
    // Only the first root moves with the sample's base state (state_sample.h).
    if (root.base == BaseType::kFixed || r > 0) {
      static_.push_back(std::move(t));
    } else {
      moving_.push_back(std::move(t));
      moving_roots_.push_back(r);
    }
  }
}

const std::vector<FrameTransform>& RobotFrames::Update(const StateSample& sample) {
  if (static_cast<int>(sample.positions.size()) != model_.num_dofs()) {
    throw ProtocolError("a STATE sample of robot '" + sample.robot + "' has " +
                        std::to_string(sample.positions.size()) + " positions; its model has " +
                        std::to_string(model_.num_dofs()) + " dofs");
  }
  for (std::size_t i = 0; i < sample.positions.size(); ++i)
    q_[static_cast<Eigen::Index>(i)] = sample.positions[i];
  for (int r : moving_roots_) {
    root_poses_[static_cast<std::size_t>(r)] =
        RootPose(model_.roots()[static_cast<std::size_t>(r)], sample.base);
  }
  kin_.Update(q_, root_poses_);
  std::size_t i = 0;
  for (int j : moving_joints_) {
    const Joint& joint = model_.joint(j);
    moving_[i++].pose = kin_.link_pose(joint.parent_link).inverse() * kin_.link_pose(joint.child_link);
  }
  for (int r : moving_roots_) moving_[i++].pose = root_poses_[static_cast<std::size_t>(r)];
  return moving_;
}

// --- Trajectories --------------------------------------------------------------

namespace {

std::string Num(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

void CheckFinite(const std::vector<double>& values, const std::string& field) {
  for (std::size_t i = 0; i < values.size(); ++i) {
    if (!std::isfinite(values[i]))
      throw Error("JointTrajectory: " + field + "[" + std::to_string(i) + "] is " + Num(values[i]));
  }
}

}  // namespace

TrajectoryCommands TrajectoryToCommands(const RobotModel& model, const TrajectoryMessage& msg,
                                        TimePoint start, TimePoint now) {
  if (msg.joint_names.empty()) throw Error("JointTrajectory: joint_names is empty");
  if (msg.points.empty()) throw Error("JointTrajectory: no points (an empty trajectory means stop)");
  // Which dof each name is, then which joints are named (all their dofs).
  const std::vector<std::string> dof_names = JointStateNames(model);
  std::map<std::string, int> dof_of;
  for (std::size_t d = 0; d < dof_names.size(); ++d) dof_of[dof_names[d]] = static_cast<int>(d);
  std::vector<int> column_of_dof(dof_names.size(), -1);
  for (std::size_t c = 0; c < msg.joint_names.size(); ++c) {
    const std::string& name = msg.joint_names[c];
    auto it = dof_of.find(name);
    if (it == dof_of.end()) {
      throw Error("JointTrajectory: joint_names[" + std::to_string(c) + "] '" + name + "': robot '" +
                  model.name() + "' has no joint (or dof) of that name");
    }
    if (column_of_dof[static_cast<std::size_t>(it->second)] >= 0) {
      throw Error("JointTrajectory: joint_names[" + std::to_string(c) + "] '" + name + "' is named twice");
    }
    column_of_dof[static_cast<std::size_t>(it->second)] = static_cast<int>(c);
  }
  std::vector<int> joints;  // in model order
  for (int j = 0; j < static_cast<int>(model.joints().size()); ++j) {
    const Joint& joint = model.joint(j);
    int named = 0;
    for (std::size_t k = 0; k < joint.dofs.size(); ++k) {
      named += column_of_dof[static_cast<std::size_t>(model.dof_offset(j)) + k] >= 0;
    }
    if (named == 0) continue;
    if (named != static_cast<int>(joint.dofs.size())) {
      throw Error("JointTrajectory: joint '" + joint.name + "' has " + std::to_string(joint.dofs.size()) +
                  " dofs; name all of them ('" + joint.name + "/0' ...), not " + std::to_string(named));
    }
    if (joint.mimic) {
      throw Error("JointTrajectory: joint '" + joint.name + "' mimics '" +
                  model.joint(joint.mimic->leader_joint).name + "'; command its leader");
    }
    joints.push_back(j);
  }
  const std::size_t n = msg.joint_names.size();
  for (std::size_t p = 0; p < msg.points.size(); ++p) {
    const auto& point = msg.points[p];
    const std::string at = "points[" + std::to_string(p) + "]";
    if (point.positions.size() != n) {
      throw Error("JointTrajectory: " + at + ".positions has " + std::to_string(point.positions.size()) +
                  " values for " + std::to_string(n) + " joint names");
    }
    if (!point.velocities.empty() && point.velocities.size() != n) {
      throw Error("JointTrajectory: " + at + ".velocities has " + std::to_string(point.velocities.size()) +
                  " values for " + std::to_string(n) + " joint names (give none or one per name)");
    }
    CheckFinite(point.positions, at + ".positions");
    CheckFinite(point.velocities, at + ".velocities");
    if (point.time_from_start < Duration(0))
      throw Error("JointTrajectory: " + at + ".time_from_start is negative");
    if (p > 0 && point.time_from_start <= msg.points[p - 1].time_from_start) {
      throw Error("JointTrajectory: " + at + ".time_from_start (" + Num(ToSeconds(point.time_from_start)) +
                  " s) is not after the previous point's");
    }
  }
  // Points already past: keep only the last of them, sent now.
  std::size_t first = 0;
  while (first + 1 < msg.points.size() && start + msg.points[first + 1].time_from_start <= now) ++first;
  TrajectoryCommands out;
  out.points_skipped = first;
  for (std::size_t p = first; p < msg.points.size(); ++p) {
    const auto& point = msg.points[p];
    const TimePoint at = std::max(start + point.time_from_start, now);
    for (int j : joints) {
      Command c{.type = CommandType::kJointSetPoint,
                .start_time = StartTime::At(at),
                .target = model.joint(j).name};
      const Joint& joint = model.joint(j);
      for (std::size_t k = 0; k < joint.dofs.size(); ++k) {
        const auto col =
            static_cast<std::size_t>(column_of_dof[static_cast<std::size_t>(model.dof_offset(j)) + k]);
        c.values.push_back(point.positions[col]);
        if (!point.velocities.empty()) c.velocities.push_back(point.velocities[col]);
      }
      if (auto refusal = CheckCommand(model, c)) {
        throw Error("JointTrajectory: points[" + std::to_string(p) + "]: " + refusal->message);
      }
      out.commands.push_back(std::move(c));
    }
  }
  return out;
}

Command TwistToCommand(BaseType base, const Eigen::Vector3d& linear, const Eigen::Vector3d& angular,
                       std::string* ignored) {
  if (base == BaseType::kFixed) throw Error("Twist: the robot's base is fixed; it takes no cmd_vel");
  for (int i = 0; i < 3; ++i) {
    if (!std::isfinite(linear[i]) || !std::isfinite(angular[i])) {
      throw Error("Twist: a component is not finite (linear " + Num(linear[i]) + ", angular " +
                  Num(angular[i]) + ")");
    }
  }
  std::string note;
  Command c{.type = CommandType::kSetSpeed};
  if (base == BaseType::kDifferential) {
    c.values = {linear.x(), angular.z()};
    if (linear.y() != 0) note += "linear.y (a differential base cannot move sideways) ";
  } else {
    c.values = {linear.x(), linear.y(), angular.z()};
  }
  if (linear.z() != 0 || angular.x() != 0 || angular.y() != 0) note += "linear.z, angular.x, angular.y ";
  if (ignored) *ignored = note.empty() ? "" : "ignored: " + note.substr(0, note.size() - 1);
  return c;
}

// --- URDF ----------------------------------------------------------------------

namespace {

std::string Xyz(const Eigen::Vector3d& v) {
  std::ostringstream s;
  s << std::setprecision(17) << v.x() << " " << v.y() << " " << v.z();
  return s.str();
}

std::string Origin(const Eigen::Isometry3d& x) {
  const Eigen::Matrix3d r = x.linear();
  // URDF rpy: R = Rz(yaw) Ry(pitch) Rx(roll).
  const double pitch = std::asin(std::clamp(-r(2, 0), -1.0, 1.0));
  const double roll = std::atan2(r(2, 1), r(2, 2));
  const double yaw = std::atan2(r(1, 0), r(0, 0));
  return "<origin xyz=\"" + Xyz(x.translation()) + "\" rpy=\"" + Xyz(Eigen::Vector3d(roll, pitch, yaw)) +
         "\"/>";
}

std::string XmlEscape(const std::string& s) {
  std::string out;
  for (char c : s) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

}  // namespace

std::string ModelToUrdf(const RobotModel& model) {
  std::ostringstream u;
  u << std::setprecision(17);
  u << "<?xml version=\"1.0\"?>\n<!-- Written by robotalk-ros2 from robot '" << XmlEscape(model.name())
    << "''s RoboTalk configuration (no geometry). -->\n<robot name=\"" << XmlEscape(model.name()) << "\">\n";
  for (const Link& link : model.links()) {
    u << "  <link name=\"" << XmlEscape(link.name) << "\">";
    if (link.mass > 0) {
      const Eigen::Matrix3d& i = link.inertia;
      u << "<inertial><origin xyz=\"" << Xyz(link.com) << "\" rpy=\"0 0 0\"/><mass value=\"" << link.mass
        << "\"/><inertia ixx=\"" << i(0, 0) << "\" ixy=\"" << i(0, 1) << "\" ixz=\"" << i(0, 2) << "\" iyy=\""
        << i(1, 1) << "\" iyz=\"" << i(1, 2) << "\" izz=\"" << i(2, 2) << "\"/></inertial>";
    }
    u << "</link>\n";
  }
  for (const Joint& joint : model.joints()) {
    const Link& parent = model.link(joint.parent_link);
    const Link& child = model.link(joint.child_link);
    Eigen::Isometry3d before = Eigen::Isometry3d::Identity();
    before.translate(parent.com + joint.inboard);
    before.rotate(joint.rest);
    const Eigen::Vector3d after = -(child.com + joint.outboard);
    std::string type = "floating";
    Eigen::Isometry3d origin = Eigen::Isometry3d::Identity();
    if (joint.dofs.empty()) {
      type = "fixed";
      origin = before * Eigen::Translation3d(after);
    } else if (joint.dofs.size() == 1 && after.norm() < 1e-12) {
      const Dof& dof = joint.dofs[0];
      const bool unlimited = !std::isfinite(dof.limits.lower) && !std::isfinite(dof.limits.upper);
      type = dof.type == DofType::kPrismatic ? "prismatic" : unlimited ? "continuous" : "revolute";
      origin = before;
    }
    u << "  <joint name=\"" << XmlEscape(joint.name) << "\" type=\"" << type << "\"><parent link=\""
      << XmlEscape(parent.name) << "\"/><child link=\"" << XmlEscape(child.name) << "\"/>" << Origin(origin);
    if (type == "revolute" || type == "prismatic" || type == "continuous") {
      const Dof& dof = joint.dofs[0];
      u << "<axis xyz=\"" << Xyz(dof.axis) << "\"/><limit";
      if (type != "continuous") {
        u << " lower=\"" << (std::isfinite(dof.limits.lower) ? dof.limits.lower : -1e9) << "\" upper=\""
          << (std::isfinite(dof.limits.upper) ? dof.limits.upper : 1e9) << "\"";
      }
      // URDF requires effort and velocity; "no limit" has no spelling there.
      u << " effort=\"" << (std::isfinite(dof.limits.effort) ? dof.limits.effort : 1e9) << "\" velocity=\""
        << (std::isfinite(dof.limits.velocity) ? dof.limits.velocity : 1e9) << "\"/>";
      if (joint.mimic) {
        u << "<mimic joint=\"" << XmlEscape(model.joint(joint.mimic->leader_joint).name) << "\" multiplier=\""
          << joint.mimic->multiplier << "\" offset=\"" << joint.mimic->offset << "\"/>";
      }
    }
    u << "</joint>\n";
  }
  u << "</robot>\n";
  return u.str();
}

}  // namespace robotalk::ros2
