// Command-line options of robotalk-ros2 (docs/interop.md, "ROS 2").
//
// Thread safety: pure functions. Errors: ParseRos2Options throws
// robotalk::Error naming the bad argument ("--domain: '300' is not a DDS
// domain id (0..232)").
#pragma once

#include "robotalk/clock.h"

#include <cstdint>
#include <map>
#include <string>
#include <vector>

namespace robotalk::ros2 {

struct Ros2Options {
  /// Robots to bridge; empty = every robot announced on the LCM bus.
  std::vector<std::string> robots;
  /// LCM URL; "" = LCM's default (LCM_DEFAULT_URL or udpm://239.255.76.67:7667?ttl=0).
  std::string lcm_url;
  /// Keyed mode: the bridge's own secret key (else $ROBOTALK_KEY, else open
  /// mode), and optionally the server's public key.
  std::string key_file;
  std::string server_key_file;
  /// DDS domain = ROS_DOMAIN_ID (the environment's when set, else 0).
  std::uint32_t domain = 0;
  /// Network interface (name or address) DDS uses; "" = CYCLONEDDS_URI or
  /// Cyclone's choice.
  std::string dds_interface;
  /// Period of the STATE stream asked for, i.e. of joint_states, tf and odom.
  Duration period = std::chrono::milliseconds(10);
  /// Prepended to every link and control-frame id on tf ("{robot}" is
  /// replaced by the robot's name), as robot_state_publisher's frame_prefix.
  std::string frame_prefix = "{robot}/";
  /// The frame every root link (and odometry) is given in.
  std::string world_frame = "world";
  /// Robot name -> URDF file published as robot_description instead of the
  /// one written from the RoboTalk configuration.
  std::map<std::string, std::string> urdf;
  /// A base moving under cmd_vel is sent SETSPEED 0 when no cmd_vel came for
  /// this long (a teleop that died must not leave it driving).
  Duration cmd_vel_timeout = std::chrono::milliseconds(500);
  /// Publish only: no joint_trajectory or cmd_vel subscriptions.
  bool read_only = false;
  /// Exit after this long (0 = run until SIGINT/SIGTERM).
  Duration duration{0};
  /// Print latency and CPU figures on exit (docs/performance.md).
  bool stats = false;
  bool help = false;
  bool version = false;
};

/// Parses argv[1..]. `ros_domain_id` is $ROS_DOMAIN_ID ("" when unset).
Ros2Options ParseRos2Options(const std::vector<std::string>& args, const std::string& ros_domain_id = "");

/// The --help text.
std::string Ros2Usage();

/// `frame_prefix` with "{robot}" replaced by `robot`.
std::string FramePrefixFor(const std::string& frame_prefix, const std::string& robot);

}  // namespace robotalk::ros2
