// Ros2Bridge: robotalk-ros2's whole job (docs/interop.md, "ROS 2"). One
// RobotClient per robot (all with the bridge's one key in keyed mode) asks
// for the STATE stream and, on each sample, publishes on DDS:
//   rt/<robot>/joint_states       sensor_msgs/JointState   (QoS 10, reliable)
//   rt/tf                          tf2_msgs/TFMessage       (moving joints, moving roots; QoS 100)
//   rt/<robot>/odom                nav_msgs/Odometry        (bases that move)
// and once per robot:
//   rt/tf_static                   tf2_msgs/TFMessage       (fixed joints, control frames, fixed roots;
//                                                            transient local, depth 1: one message
//                                                            holding every robot's)
//   rt/<robot>/robot_description   std_msgs/String          (URDF; transient local, depth 1)
// It subscribes (unless read-only) to
//   rt/<robot>/joint_trajectory    trajectory_msgs/JointTrajectory -> timed JOINT_SETPOINTs, delay mode
//   rt/<robot>/cmd_vel             geometry_msgs/Twist              -> SETSPEED now (bases that move)
// A JointTrajectory's header.stamp (ROS time, the system clock) is when its
// time_from_start 0 is, converted to the server's clock through the client's
// clock sync; a zero stamp means on receipt. Its points are sent as step
// set-points (the client has no interpolation API yet: once RobotClient sends
// Request::interpolation, cubic is a one-line change in SendTrajectory). An
// empty trajectory sends STOP.
//
// Safety: a base moving under cmd_vel gets SETSPEED 0 when cmd_vel falls
// silent for `cmd_vel_timeout`; on shutdown the bridge sends STOP to every
// robot it set moving; if the bridge dies, the server's session watchdog
// stops what it owned (docs/safety.md).
//
// Thread safety: Run() on one thread; Stop() from any thread (a signal
// handler may not call it: set a flag and call it from a thread). Internally:
// each client's ReadDaemon publishes its robot's samples; Cyclone's listener
// threads turn command messages into packages; a connector thread connects
// robots; Run() does housekeeping (cmd_vel watchdog, replies).
// Errors: the constructor throws DdsError when DDS cannot start. Failures of
// one robot (no answer, a refused command) are logged on stderr with the
// robot's name, never thrown.
#pragma once

#include "ros2_options.h"

#include <memory>
#include <string>

namespace robotalk::ros2 {

class Ros2Bridge {
 public:
  explicit Ros2Bridge(const Ros2Options& options);
  /// Sends STOP to every robot the bridge set moving, then closes.
  ~Ros2Bridge();
  Ros2Bridge(const Ros2Bridge&) = delete;
  Ros2Bridge& operator=(const Ros2Bridge&) = delete;

  /// Serves until Stop() or the options' duration.
  void Run();
  void Stop();
  /// Latency (STATE sample in -> last DDS write out) and CPU figures, for --stats.
  std::string StatsText() const;

 private:
  class Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace robotalk::ros2
