#include "ros_wire.h"

namespace robotalk::ros2 {

namespace {

builtin_interfaces_msg_dds__Time_ Stamp(RosTime t) { return {t.sec, t.nanosec}; }

char* Chars(const std::string& s) { return const_cast<char*>(s.c_str()); }  // Cyclone only reads it

dds_sequence_double Doubles(const std::vector<double>& v) {
  return {static_cast<uint32_t>(v.size()), static_cast<uint32_t>(v.size()), const_cast<double*>(v.data()),
          false};
}

std::vector<double> Copy(const dds_sequence_double& s) {
  return s._length ? std::vector<double>(s._buffer, s._buffer + s._length) : std::vector<double>{};
}

void SetTransform(geometry_msgs_msg_dds__Transform_& out, const Eigen::Isometry3d& pose) {
  const Eigen::Quaterniond q(pose.linear());
  out.translation = {pose.translation().x(), pose.translation().y(), pose.translation().z()};
  out.rotation = {q.x(), q.y(), q.z(), q.w()};
}

}  // namespace

JointStateBuffer::JointStateBuffer(std::vector<std::string> names) : names_(std::move(names)) {
  for (const std::string& n : names_) name_ptrs_.push_back(Chars(n));
  msg_.name = {static_cast<uint32_t>(names_.size()), static_cast<uint32_t>(names_.size()), name_ptrs_.data(),
               false};
  msg_.header.frame_id = const_cast<char*>("");
}

const sensor_msgs_msg_dds__JointState_& JointStateBuffer::Fill(RosTime stamp, const StateSample& sample) {
  msg_.header.stamp = Stamp(stamp);
  msg_.position = Doubles(sample.positions);
  msg_.velocity = Doubles(sample.velocities);
  msg_.effort = Doubles(sample.efforts);
  return msg_;
}

const tf2_msgs_msg_dds__TFMessage_& TfBuffer::Fill(RosTime stamp,
                                                   const std::vector<FrameTransform>& transforms) {
  items_.resize(transforms.size());
  for (std::size_t i = 0; i < transforms.size(); ++i) {
    auto& item = items_[i];
    item.header.stamp = Stamp(stamp);
    item.header.frame_id = Chars(transforms[i].parent);
    item.child_frame_id = Chars(transforms[i].child);
    SetTransform(item.transform, transforms[i].pose);
  }
  msg_.transforms = {static_cast<uint32_t>(items_.size()), static_cast<uint32_t>(items_.size()),
                     items_.data(), false};
  return msg_;
}

nav_msgs_msg_dds__Odometry_ MakeOdometry(RosTime stamp, const std::string& world_frame,
                                         const std::string& child_frame, const Eigen::Isometry3d& pose,
                                         const BaseState& base) {
  nav_msgs_msg_dds__Odometry_ m{};
  m.header.stamp = Stamp(stamp);
  m.header.frame_id = Chars(world_frame);
  m.child_frame_id = Chars(child_frame);
  const Eigen::Quaterniond q(pose.linear());
  m.pose.pose.position = {pose.translation().x(), pose.translation().y(), pose.translation().z()};
  m.pose.pose.orientation = {q.x(), q.y(), q.z(), q.w()};
  m.twist.twist.linear = {base.v, 0, 0};
  m.twist.twist.angular = {0, 0, base.omega};
  return m;
}

std_msgs_msg_dds__String_ MakeString(const std::string& text) { return {Chars(text)}; }

TrajectoryMessage ReadTrajectory(const trajectory_msgs_msg_dds__JointTrajectory_& msg) {
  TrajectoryMessage out;
  out.stamp = {msg.header.stamp.sec, msg.header.stamp.nanosec};
  for (uint32_t i = 0; i < msg.joint_names._length; ++i) {
    out.joint_names.emplace_back(msg.joint_names._buffer[i] ? msg.joint_names._buffer[i] : "");
  }
  for (uint32_t i = 0; i < msg.points._length; ++i) {
    const auto& p = msg.points._buffer[i];
    out.points.push_back(
        {Copy(p.positions), Copy(p.velocities),
         std::chrono::seconds(p.time_from_start.sec) + std::chrono::nanoseconds(p.time_from_start.nanosec)});
  }
  return out;
}

}  // namespace robotalk::ros2
