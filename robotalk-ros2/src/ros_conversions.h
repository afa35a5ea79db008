// What robotalk-ros2 says to ROS 2 and hears from it, without DDS: the pure
// conversions between RoboTalk's values (RobotModel, StateSample, Command) and
// the fields of the ROS 2 messages it bridges (docs/interop.md, "ROS 2"):
// sensor_msgs/JointState names and values, tf2_msgs/TFMessage transforms,
// nav_msgs/Odometry, trajectory_msgs/JointTrajectory -> timed JOINT_SETPOINTs,
// geometry_msgs/Twist -> SETSPEED; ROS time <-> the system clock.
//
// Thread safety: free functions are pure. A RobotFrames is not thread-safe
// (it owns a Kinematics buffer): one per thread.
// Errors: TrajectoryToCommands and TwistToCommand throw robotalk::Error with a
// message naming the message field and the bad value; RobotFrames::Update
// throws ProtocolError for a sample of another model (its dof count).
#pragma once

#include "robotalk/clock.h"
#include "robotalk/command.h"
#include "robotalk/kinematics.h"
#include "robotalk/robot_model.h"
#include "robotalk/state_sample.h"

#include <Eigen/Geometry>

#include <chrono>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace robotalk::ros2 {

/// builtin_interfaces/Time: seconds and nanoseconds since the Unix epoch (ROS
/// time is the system clock unless a node uses simulated time).
struct RosTime {
  std::int32_t sec = 0;
  std::uint32_t nanosec = 0;
  bool is_zero() const { return sec == 0 && nanosec == 0; }
};
using SystemTime = std::chrono::time_point<std::chrono::system_clock, Duration>;
RosTime ToRosTime(SystemTime t);
SystemTime FromRosTime(RosTime t);

/// A topic name of the robot, as a ROS 2 name: characters other than
/// [A-Za-z0-9_] become '_', a leading digit gets a '_' before it ("arm-2" ->
/// "arm_2"). ROS 2 names allow no others (design.ros2.org, "Topic and Service
/// name mapping to DDS").
std::string RosNameToken(const std::string& robot);

/// One name per dof in the model's dof order, as JointState carries them: the
/// joint's name for a 1-dof joint, "<joint>/<k>" for dof k of a joint with
/// several (a URDF has no such joints; RoboTalk's free and planar ones).
std::vector<std::string> JointStateNames(const RobotModel& model);

/// One TF transform: `parent` -> `child` frame ids, the child's pose in the
/// parent's frame.
struct FrameTransform {
  std::string parent;
  std::string child;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
};

/// The TF tree of one robot, as robot_state_publisher publishes it from a
/// URDF: one transform per joint from its parent link's frame to its child
/// link's frame (moving ones on /tf, fixed ones on /tf_static), each control
/// frame under its link (static), and each root link under `world_frame`
/// (static for a fixed base; moving, from the sample's x y θ, otherwise).
/// Frame ids are `prefix` + the link or frame name; `world_frame` has none.
class RobotFrames {
 public:
  /// `model` must outlive this object.
  RobotFrames(const RobotModel& model, std::string prefix, std::string world_frame);

  /// Fixed joints, control frames and fixed roots. Constant.
  const std::vector<FrameTransform>& static_transforms() const { return static_; }
  /// Moving joints and moving roots at `sample`: the vector is reused by the
  /// next call (no allocation after the first).
  const std::vector<FrameTransform>& Update(const StateSample& sample);
  /// The world pose of root `i` (RobotModel::roots() order) at `base`: x, y
  /// and yaw θ from the sample; height, roll and pitch from the model.
  static Eigen::Isometry3d RootPose(const RootLink& root, const BaseState& base);

 private:
  const RobotModel& model_;
  Kinematics kin_;
  std::vector<FrameTransform> static_, moving_;
  std::vector<int> moving_joints_;  // joint index per moving_ entry before the roots
  std::vector<int> moving_roots_;   // root index per remaining moving_ entry
  std::vector<Eigen::Isometry3d> root_poses_;
  Eigen::VectorXd q_;
};

/// trajectory_msgs/JointTrajectory, as read from DDS.
struct TrajectoryMessage {
  RosTime stamp;  ///< header.stamp: when point time_from_start 0 is; zero = now
  std::vector<std::string> joint_names;
  struct Point {
    std::vector<double> positions;
    std::vector<double> velocities;  ///< empty, or one per joint name
    Duration time_from_start{0};
  };
  std::vector<Point> points;
};

/// The commands of a trajectory and what was left out.
struct TrajectoryCommands {
  std::vector<Command> commands;   ///< JOINT_SETPOINTs in start-time order
  std::size_t points_skipped = 0;  ///< points already past at `now` (all but the last of them)
};

/// Turns a JointTrajectory into one JOINT_SETPOINT per RoboTalk joint per
/// point, at `start` + time_from_start on the server clock (step set-points:
/// the joint goes to each point at its time). Points whose time is before
/// `now` are dropped except the last of them, which is sent at `now` (the
/// robot goes where the trajectory says it is by now, as JTC samples a
/// trajectory that started in the past). Every command passes CheckCommand
/// against `model`, so a trajectory is refused whole, never half run.
/// Throws robotalk::Error naming the field: no joint names, an unknown or
/// repeated name, a joint of several dofs not all named, a mimic joint, a
/// point with the wrong number of positions or velocities, a non-finite
/// value, time_from_start negative or not increasing, no points (the caller
/// treats an empty trajectory as "stop"), or the refusal of CheckCommand.
TrajectoryCommands TrajectoryToCommands(const RobotModel& model, const TrajectoryMessage& msg,
                                        TimePoint start, TimePoint now);

/// geometry_msgs/Twist -> SETSPEED (v ω for a differential base, vx vy ω for
/// a holonomic one), to start now. `ignored` is set to a note when the twist
/// has components the base cannot follow (linear.y on a differential base,
/// linear.z, angular.x/y). Throws robotalk::Error for a fixed base or a
/// non-finite component.
Command TwistToCommand(BaseType base, const Eigen::Vector3d& linear, const Eigen::Vector3d& angular,
                       std::string* ignored);

/// A URDF of the model, for robot_description when no URDF file is given:
/// every link with its inertial; a 1-dof joint as revolute (continuous
/// without limits) or prismatic, its origin the joint frame at q = 0, when
/// its child link's frame is the joint frame (as every URDF import is); any
/// other joint as "floating" (robot_state_publisher skips those; the bridge
/// publishes their TF itself) and a fixed one as "fixed". No geometry: give
/// the robot's own URDF for RViz to draw it (--urdf).
std::string ModelToUrdf(const RobotModel& model);

}  // namespace robotalk::ros2
