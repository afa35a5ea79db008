#include "ros2_options.h"

#include "robotalk/channels.h"
#include "robotalk/error.h"
#include "robotalk/option_reader.h"
#include "robotalk/sequence_file.h"

namespace robotalk::ros2 {
namespace {

std::uint32_t ParseDomain(const std::string& option, const std::string& text) {
  // DDS's port mapping leaves room for domain ids 0..232 (ROS 2's
  // "The ROS_DOMAIN_ID" concept page).
  return static_cast<std::uint32_t>(ParseNumberIn(text, option, {.min = 0, .max = 232, .whole = true}));
}

}  // namespace

std::string Ros2Usage() {
  return "usage: robotalk-ros2 [options]\n"
         "Bridges RoboTalk robots to ROS 2 over DDS (Cyclone DDS; no ROS install needed):\n"
         "per robot, publishes /<robot>/joint_states, /tf, /tf_static, /<robot>/robot_description\n"
         "and /<robot>/odom (moving bases), and turns /<robot>/joint_trajectory and\n"
         "/<robot>/cmd_vel into RoboTalk commands.\n"
         "  --robot NAME        bridge this robot (repeatable; default: every robot announced)\n"
         "  --url URL           LCM URL (default: LCM_DEFAULT_URL or LCM's default)\n"
         "  --key FILE          keyed mode: the bridge's secret key (default $ROBOTALK_KEY)\n"
         "  --server-key FILE   keyed mode: the server's public key (else the known-servers pin)\n"
         "  --domain N          DDS domain = ROS_DOMAIN_ID (default $ROS_DOMAIN_ID, else 0)\n"
         "  --dds-interface IF  network interface (name or address) for DDS (default:\n"
         "                      CYCLONEDDS_URI, else Cyclone's choice)\n"
         "  --rate HZ           joint_states / tf / odom rate = STATE stream rate (default 100)\n"
         "  --frame-prefix P    prefix of tf frame ids; {robot} = the robot's name\n"
         "                      (default '{robot}/'; '' for none, as with one robot)\n"
         "  --world-frame F     frame of the root links and odometry (default world)\n"
         "  --urdf NAME=FILE    publish this URDF as NAME's robot_description (repeatable;\n"
         "                      default: one written from the configuration, without geometry)\n"
         "  --cmd-vel-timeout S SETSPEED 0 when a moving base hears no cmd_vel for S s (default 0.5)\n"
         "  --read-only         publish only; subscribe to no command topic\n"
         "  --duration S        exit after S seconds\n"
         "  --stats             print latency and CPU figures on exit\n"
         "  --version           print the version and exit\n"
         "  -h, --help          print this help and exit\n";
}

Ros2Options ParseRos2Options(const std::vector<std::string>& args, const std::string& ros_domain_id) {
  Ros2Options o;
  if (!ros_domain_id.empty()) o.domain = ParseDomain("ROS_DOMAIN_ID", ros_domain_id);
  OptionReader r(args);
  while (r.Next()) {
    const std::string& a = r.word();
    if (r.IsHelp()) {
      o.help = true;
    } else if (r.IsVersion()) {
      o.version = true;
    } else if (a == "--robot") {
      const std::string& name = r.Value();
      if (const std::string why = RobotNameProblem(name); !why.empty())
        throw Error("--robot '" + name + "': " + why);
      o.robots.push_back(name);
    } else if (a == "--url") {
      o.lcm_url = r.Value();
    } else if (a == "--key") {
      o.key_file = r.Value();
    } else if (a == "--server-key") {
      o.server_key_file = r.Value();
    } else if (a == "--domain") {
      o.domain = ParseDomain(a, r.Value());
    } else if (a == "--dds-interface") {
      o.dds_interface = r.Value();
    } else if (a == "--rate") {
      o.period =
          FromSeconds(1.0 / ParseNumberIn(r.Value(), a, {.min = 1, .max = 1000}));  // the STATE stream's
    } else if (a == "--frame-prefix") {
      o.frame_prefix = r.Value();
    } else if (a == "--world-frame") {
      o.world_frame = r.Value();
      if (o.world_frame.empty()) throw Error("--world-frame: the name is empty");
    } else if (a == "--urdf") {
      const std::string& v = r.Value();
      const auto eq = v.find('=');
      if (eq == std::string::npos || eq == 0 || eq + 1 == v.size()) {
        throw Error("--urdf: '" + v + "' is not NAME=FILE");
      }
      o.urdf[v.substr(0, eq)] = v.substr(eq + 1);
    } else if (a == "--cmd-vel-timeout") {
      o.cmd_vel_timeout = FromSeconds(ParseNumberIn(r.Value(), a, {.min = 0, .max = 60, .above_min = true}));
    } else if (a == "--read-only") {
      o.read_only = true;
    } else if (a == "--duration") {
      const std::string& text = r.Value();
      const double s = ParseSeconds(text, a);  // at most kMaxTextSeconds: FromSeconds cannot overflow
      if (s <= 0) throw Error("--duration: " + text + " s is not positive");
      o.duration = FromSeconds(s);
    } else if (a == "--stats") {
      o.stats = true;
    } else {
      r.Unknown();
    }
  }
  return o;
}

std::string FramePrefixFor(const std::string& frame_prefix, const std::string& robot) {
  std::string out = frame_prefix;
  for (std::size_t at = out.find("{robot}"); at != std::string::npos;
       at = out.find("{robot}", at + robot.size())) {
    out.replace(at, 7, robot);
  }
  return out;
}

}  // namespace robotalk::ros2
