// ros2_peer: the tests' own ROS 2 side of robotalk-ros2, a Cyclone DDS
// program built from the same IDL (robotalk_ros2_msgs) that reads and writes
// the bridge's topics as a ROS 2 node would, and a RoboTalk client of its
// own that watches the STATE stream on LCM to compare.
//
//   ros2_peer check ROBOT --url URL [--key FILE]
//     robot_description, tf_static, joint_states, tf and odom arrive and
//     follow the STATE stream; a JointTrajectory stamped 0.6 s ahead moves
//     the robot through its points on time. Exit 0 when every check passes.
//   ros2_peer bad_trajectory ROBOT --url URL [--key FILE]
//     a JointTrajectory naming an unknown joint moves nothing.
//   ros2_peer cmd_vel ROBOT --url URL [--key FILE]
//     Twists at 10 Hz for 0.5 s drive the base; once they stop, the base
//     stops within 0.8 s (the bridge's cmd_vel timeout) and stays stopped.
//   ros2_peer cmd_vel_full_queue ROBOT --url URL [--key FILE]
//     As cmd_vel, with a JointTrajectory seconds ahead filling the bridge's
//     queue on a server run with a small --max-queue: the base still stops.
//   ros2_peer cmd_vel_flood ROBOT --url URL [--key FILE]
//     2,000 Twists the bridge refuses (linear.x not finite), half of them
//     alike, as fast as DDS takes them: nothing moves (the bridge's log of
//     them is checked by ros2_bridge_test.sh).
//   ros2_peer measure ROBOT --url URL [--key FILE] --seconds S
//     per sample, LCM latency (server sample time -> STATE received here) and
//     DDS latency (the same sample time, as JointState's stamp -> JointState
//     received here); prints percentiles (docs/performance.md).
#include "dds_entities.h"
#include "robotalk/kinematics.h"
#include "robotalk/robot_client.h"
#include "ros_conversions.h"
#include "ros_messages.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <map>
#include <mutex>
#include <thread>

using namespace robotalk;
using namespace robotalk::ros2;
using namespace std::chrono_literals;

namespace {

int failures = 0;
void Check(bool ok, const std::string& what) {
  std::cout << (ok ? "ok: " : "FAIL: ") << what << std::endl;
  if (!ok) ++failures;
}

TimePoint SteadyNow() { return std::chrono::time_point_cast<Duration>(std::chrono::steady_clock::now()); }
SystemTime SystemNow() { return std::chrono::time_point_cast<Duration>(std::chrono::system_clock::now()); }
// A ROS stamp (system clock) as a steady-clock instant of this process.
TimePoint SteadyOf(RosTime t) { return SteadyNow() + (FromRosTime(t) - SystemNow()); }
double Ms(Duration d) { return std::chrono::duration<double, std::milli>(d).count(); }

struct LcmSample {
  TimePoint server_time, received;
  std::vector<double> positions;
  BaseState base;
};
struct JointStateSeen {
  RosTime stamp;
  TimePoint received;
  std::vector<std::string> names;
  std::vector<double> positions;
};
struct TfSeen {
  RosTime stamp;
  std::string parent, child;
  Eigen::Isometry3d pose;
};

std::int64_t Key(RosTime t) { return std::int64_t{t.sec} * 1000000000 + t.nanosec; }

// Everything heard, under one lock.
struct Heard {
  std::mutex mu;
  std::vector<LcmSample> lcm;
  std::vector<JointStateSeen> joint_states;
  std::vector<TfSeen> tf, tf_static;
  std::string description;
  std::vector<std::pair<std::string, std::string>> odom_frames;
};

std::vector<double> Doubles(const dds_sequence_double& s) { return {s._buffer, s._buffer + s._length}; }

void ReadTf(const tf2_msgs_msg_dds__TFMessage_& m, std::vector<TfSeen>& out) {
  for (uint32_t i = 0; i < m.transforms._length; ++i) {
    const auto& t = m.transforms._buffer[i];
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    pose.translation() =
        Eigen::Vector3d(t.transform.translation.x, t.transform.translation.y, t.transform.translation.z);
    pose.linear() = Eigen::Quaterniond(t.transform.rotation.w, t.transform.rotation.x, t.transform.rotation.y,
                                       t.transform.rotation.z)
                        .toRotationMatrix();
    out.push_back({{t.header.stamp.sec, t.header.stamp.nanosec}, t.header.frame_id, t.child_frame_id, pose});
  }
}

template <typename Pred>
bool WaitFor(Heard& h, Duration most, Pred pred) {
  const auto end = SteadyNow() + most;
  while (SteadyNow() < end) {
    {
      std::lock_guard lock(h.mu);
      if (pred()) return true;
    }
    std::this_thread::sleep_for(20ms);
  }
  std::lock_guard lock(h.mu);
  return pred();
}

void Percentiles(const char* what, std::vector<double> v) {
  std::sort(v.begin(), v.end());
  if (v.empty()) {
    std::printf("%s: no samples\n", what);
    return;
  }
  const auto p = [&](double q) {
    return v[std::min(v.size() - 1, static_cast<std::size_t>(q * static_cast<double>(v.size())))];
  };
  std::printf("%s: n %zu p50 %.3f p90 %.3f p99 %.3f max %.3f ms\n", what, v.size(), p(0.5), p(0.9), p(0.99),
              v.back());
}

// The cmd_vel checks: the base drove at 0.2 m/s, stopped within `bound` of
// the teleop's last Twist (sent at `last_sent`, server time) and stayed
// stopped. REQUIRES: h.mu held.
void CheckTheBaseStops(const Heard& h, TimePoint last_sent, Duration bound, const std::string& what) {
  bool drove = false;
  const LcmSample* stopped = nullptr;
  for (const LcmSample& l : h.lcm) {
    drove = drove || std::abs(l.base.v - 0.2) < 1e-9;
    if (!stopped && drove && l.server_time > last_sent && l.base.v == 0 && l.base.omega == 0) stopped = &l;
  }
  Check(drove, "cmd_vel drives the base (v 0.2 m/s in the STATE stream)");
  Check(
      stopped && stopped->server_time < last_sent + bound,
      what + " (" +
          (stopped ? std::to_string(Ms(stopped->server_time - last_sent)) + " ms after the last" : "never") +
          ")");
  Check(!h.lcm.empty() && h.lcm.back().base.v == 0, "and stays stopped");
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3) {
    std::cerr
        << "usage: ros2_peer check|measure ROBOT --url URL [--key FILE] [--seconds S] [--period-ms P]\n";
    return 2;
  }
  const std::string mode = argv[1], robot = argv[2];
  ClientOptions copt;
  double seconds = 5;
  int period_ms = 10;
  for (int i = 3; i + 1 < argc; i += 2) {
    const std::string a = argv[i], v = argv[i + 1];
    if (a == "--url")
      copt.lcm_url = v;
    else if (a == "--key")
      copt.key_file = v;
    else if (a == "--seconds")
      seconds = std::atof(v.c_str());
    else if (a == "--period-ms")
      period_ms = std::atoi(v.c_str());
  }
  const char* domain_env = std::getenv("ROS_DOMAIN_ID");
  DdsParticipant participant(domain_env ? static_cast<std::uint32_t>(std::atoi(domain_env)) : 0, "");
  Heard heard;
  const std::string ns = "/" + RosNameToken(robot);
  DdsReader js_reader(
      participant, sensor_msgs_msg_dds__JointState__desc, ns + "/joint_states", kDefaultQos,
      [&](const void* p) {
        const auto& m = *static_cast<const sensor_msgs_msg_dds__JointState_*>(p);
        JointStateSeen s{{m.header.stamp.sec, m.header.stamp.nanosec}, SteadyNow(), {}, Doubles(m.position)};
        for (uint32_t i = 0; i < m.name._length; ++i) s.names.emplace_back(m.name._buffer[i]);
        std::lock_guard lock(heard.mu);
        heard.joint_states.push_back(std::move(s));
      });
  DdsReader tf_reader(participant, tf2_msgs_msg_dds__TFMessage__desc, "/tf", kTfQos, [&](const void* p) {
    std::lock_guard lock(heard.mu);
    ReadTf(*static_cast<const tf2_msgs_msg_dds__TFMessage_*>(p), heard.tf);
  });
  // As tf2_ros::StaticListenerQoS: depth 100, transient local.
  DdsReader tf_static_reader(participant, tf2_msgs_msg_dds__TFMessage__desc, "/tf_static", {true, true, 100},
                             [&](const void* p) {
                               std::lock_guard lock(heard.mu);
                               heard.tf_static.clear();
                               ReadTf(*static_cast<const tf2_msgs_msg_dds__TFMessage_*>(p), heard.tf_static);
                             });
  DdsReader description_reader(participant, std_msgs_msg_dds__String__desc, ns + "/robot_description",
                               kLatchedQos, [&](const void* p) {
                                 std::lock_guard lock(heard.mu);
                                 heard.description = static_cast<const std_msgs_msg_dds__String_*>(p)->data;
                               });
  DdsReader odom_reader(participant, nav_msgs_msg_dds__Odometry__desc, ns + "/odom", kDefaultQos,
                        [&](const void* p) {
                          const auto& m = *static_cast<const nav_msgs_msg_dds__Odometry_*>(p);
                          std::lock_guard lock(heard.mu);
                          heard.odom_frames.emplace_back(m.header.frame_id, m.child_frame_id);
                        });
  DdsWriter trajectory_writer(participant, trajectory_msgs_msg_dds__JointTrajectory__desc,
                              ns + "/joint_trajectory", kDefaultQos);

  RobotClient client(copt);
  client.Connect(robot);
  const RobotModel model = client.model();
  client.StartStateStream(std::chrono::milliseconds(period_ms), [&](const StateSample& s) {
    LcmSample l{s.server_time, SteadyNow(), s.positions, s.base};
    std::lock_guard lock(heard.mu);
    heard.lcm.push_back(std::move(l));
  });

  if (mode == "measure") {
    Check(WaitFor(heard, 10s, [&] { return heard.joint_states.size() > 10; }), "joint_states arrive");
    {
      std::lock_guard lock(heard.mu);
      heard.lcm.clear();
      heard.joint_states.clear();
    }
    std::this_thread::sleep_for(std::chrono::duration<double>(seconds));
    std::lock_guard lock(heard.mu);
    std::vector<double> lcm, dds;
    for (const auto& s : heard.lcm) lcm.push_back(Ms(s.received - client.ClientTime(s.server_time)));
    for (const auto& s : heard.joint_states) dds.push_back(Ms(s.received - SteadyOf(s.stamp)));
    // Added latency per sample on this process's clock alone: the JointState
    // received minus the same sample's STATE received. A JointState is
    // matched to the STATE sample whose time is nearest its stamp (the two
    // clock-sync estimates differ by far less than a period).
    std::vector<double> added;
    std::size_t unmatched = 0;
    std::size_t from = 0;
    for (const auto& j : heard.joint_states) {
      const TimePoint at = SteadyOf(j.stamp);
      while (from + 1 < heard.lcm.size() && client.ClientTime(heard.lcm[from + 1].server_time) <= at) ++from;
      const LcmSample* best = nullptr;
      for (std::size_t i = from; i < std::min(from + 2, heard.lcm.size()); ++i) {
        const Duration d(std::abs((client.ClientTime(heard.lcm[i].server_time) - at).count()));
        if (d < Duration(std::chrono::milliseconds(period_ms)) / 3 &&
            (!best || d < Duration(std::abs((client.ClientTime(best->server_time) - at).count())))) {
          best = &heard.lcm[i];
        }
      }
      if (best) {
        added.push_back(Ms(j.received - best->received));
      } else {
        ++unmatched;
      }
    }
    Percentiles("LCM STATE (server sample -> peer)", lcm);
    Percentiles("DDS JointState (server sample -> bridge -> peer)", dds);
    Percentiles("added: JointState received - the same sample's STATE received", added);
    std::printf("JointStates not matched to a STATE sample: %zu of %zu\n", unmatched,
                heard.joint_states.size());
    return failures ? 1 : 0;
  }

  if (mode == "cmd_vel") {
    // Drives the base for 0.5 s at 10 Hz, then falls silent as a dead teleop
    // would: the bridge must stop the base by itself.
    DdsWriter twist_writer(participant, geometry_msgs_msg_dds__Twist__desc, ns + "/cmd_vel", kDefaultQos);
    Check(WaitFor(heard, 5s, [&] { return twist_writer.matched_readers() > 0; }),
          "the bridge subscribes to cmd_vel");
    geometry_msgs_msg_dds__Twist_ twist{{0.2, 0, 0}, {0, 0, 0.1}};
    for (int i = 0; i < 5; ++i) {
      twist_writer.Write(&twist);
      std::this_thread::sleep_for(100ms);
    }
    const TimePoint last_sent = client.ServerNow();
    std::this_thread::sleep_for(1500ms);
    std::lock_guard lock(heard.mu);
    CheckTheBaseStops(heard, last_sent, 800ms, "the base stops by itself once cmd_vel falls silent");
    return failures ? 1 : 0;
  }
  if (mode == "cmd_vel_flood") {
    DdsWriter twist_writer(participant, geometry_msgs_msg_dds__Twist__desc, ns + "/cmd_vel", kDefaultQos);
    Check(WaitFor(heard, 5s, [&] { return twist_writer.matched_readers() > 0; }),
          "the bridge subscribes to cmd_vel");
    constexpr int kTwists = 2000;
    for (int i = 0; i < kTwists; ++i) {  // every other one alike; the others each say another angular.z
      geometry_msgs_msg_dds__Twist_ twist{{std::nan(""), 0, 0}, {0, 0, i % 2 ? 0.0 : 0.001 * i}};
      twist_writer.Write(&twist);
      if (i % 100 == 99) std::this_thread::sleep_for(10ms);
    }
    std::this_thread::sleep_for(1500ms);
    std::cout << "sent " << kTwists << " refused cmd_vel\n";
    return failures ? 1 : 0;
  }
  if (mode == "cmd_vel_full_queue") {
    // The server runs with a small --max-queue. The base is driven by
    // cmd_vel; then a JointTrajectory whose points lie seconds ahead fills
    // the bridge's queue on the server, and cmd_vel falls silent: the
    // timeout's SETSPEED 0 is refused ("command not queued"), and the base
    // must still stop.
    DdsWriter twist_writer(participant, geometry_msgs_msg_dds__Twist__desc, ns + "/cmd_vel", kDefaultQos);
    Check(WaitFor(
              heard, 5s,
              [&] { return twist_writer.matched_readers() > 0 && trajectory_writer.matched_readers() > 0; }),
          "the bridge subscribes to cmd_vel and joint_trajectory");
    geometry_msgs_msg_dds__Twist_ twist{{0.2, 0, 0}, {0, 0, 0.1}};
    for (int i = 0; i < 3; ++i) {
      twist_writer.Write(&twist);
      std::this_thread::sleep_for(100ms);
    }
    // Stamped 5 s ahead (none passes during the check), at +1 .. +12 s from
    // the stamp: more than the server's --max-queue.
    constexpr int kPoints = 12;
    const RosTime ahead = ToRosTime(SystemNow() + 5s);
    std::vector<char*> jn = {const_cast<char*>("pan")};
    std::vector<double> values(kPoints);
    std::vector<trajectory_msgs_msg_dds__JointTrajectoryPoint_> pts(kPoints);
    for (int k = 0; k < kPoints; ++k) {
      values[k] = 0.01 * (k + 1);
      pts[k] = {};
      pts[k].positions = {1, 1, &values[k], false};
      pts[k].time_from_start = {k + 1, 0};
    }
    trajectory_msgs_msg_dds__JointTrajectory_ msg{};
    msg.header.stamp = {ahead.sec, ahead.nanosec};
    msg.header.frame_id = const_cast<char*>("");
    msg.joint_names = {1, 1, jn.data(), false};
    msg.points = {kPoints, kPoints, pts.data(), false};
    trajectory_writer.Write(&msg);
    std::this_thread::sleep_for(200ms);
    twist_writer.Write(&twist);  // the teleop's last message
    const TimePoint last_sent = client.ServerNow();
    std::this_thread::sleep_for(2500ms);
    std::lock_guard lock(heard.mu);
    CheckTheBaseStops(heard, last_sent, 1500ms,
                      "with the bridge's queue full, the base still stops once cmd_vel falls silent");
    return failures ? 1 : 0;
  }
  if (mode == "bad_trajectory") {
    std::vector<char*> jn = {const_cast<char*>("nek")};
    double value = 0.3;
    trajectory_msgs_msg_dds__JointTrajectoryPoint_ point{};
    point.positions = {1, 1, &value, false};
    trajectory_msgs_msg_dds__JointTrajectory_ msg{};
    msg.header.frame_id = const_cast<char*>("");
    msg.joint_names = {1, 1, jn.data(), false};
    msg.points = {1, 1, &point, false};
    Check(WaitFor(heard, 5s, [&] { return trajectory_writer.matched_readers() > 0; }),
          "the bridge subscribes to joint_trajectory");
    trajectory_writer.Write(&msg);
    std::this_thread::sleep_for(500ms);
    std::lock_guard lock(heard.mu);
    Check(!heard.lcm.empty() && heard.lcm.back().positions == heard.lcm.front().positions,
          "a trajectory naming an unknown joint moves nothing");
    return failures ? 1 : 0;
  }

  // --- check -------------------------------------------------------------------
  Check(WaitFor(heard, 10s, [&] { return !heard.description.empty(); }),
        "robot_description arrives (transient local, to a late joiner)");
  {
    std::lock_guard lock(heard.mu);
    Check(heard.description.find("<robot name=\"" + robot + "\"") != std::string::npos &&
              heard.description.find("<joint name=\"pan\" type=\"revolute\"") != std::string::npos,
          "robot_description is the robot's URDF with its joint 'pan'");
  }
  const std::string prefix = RosNameToken(robot) + "/";
  RobotFrames expected(model, prefix, "world");
  Check(WaitFor(heard, 5s,
                [&] {
                  return heard.tf_static.size() == expected.static_transforms().size() &&
                         !heard.tf_static.empty();
                }),
        "tf_static holds the robot's " + std::to_string(expected.static_transforms().size()) +
            " fixed transforms in one message");
  const std::vector<std::string> names = JointStateNames(model);
  Check(WaitFor(heard, 5s, [&] { return heard.joint_states.size() > 5 && heard.tf.size() > 5; }),
        "joint_states and tf arrive");
  {
    std::lock_guard lock(heard.mu);
    Check(heard.joint_states.back().names == names, "JointState names every dof in the model's order");
    for (const TfSeen& t : heard.tf_static) {
      const auto it = std::find_if(expected.static_transforms().begin(), expected.static_transforms().end(),
                                   [&](const FrameTransform& e) { return e.child == t.child; });
      if (it == expected.static_transforms().end() || it->parent != t.parent ||
          !it->pose.isApprox(t.pose, 1e-9)) {
        Check(false, "tf_static " + t.parent + " -> " + t.child + " is the model's");
      }
    }
    heard.lcm.clear();
    heard.joint_states.clear();
    heard.tf.clear();
  }

  // A trajectory stamped 0.6 s ahead: points at +0.2, +0.6, +1.0 s.
  const int pan = model.dof_offset(model.JointIndex("pan")),
            tilt = model.dof_offset(model.JointIndex("tilt"));
  const std::vector<std::array<double, 2>> points = {{0.2, -0.1}, {-0.2, 0.2}, {0.4, 0.0}};
  const std::vector<Duration> times = {200ms, 600ms, 1000ms};
  Check(WaitFor(heard, 5s, [&] { return trajectory_writer.matched_readers() > 0; }),
        "the bridge subscribes to joint_trajectory");
  const TimePoint server_start = client.ServerNow() + 600ms;
  const RosTime stamp = ToRosTime(SystemNow() + 600ms);
  {
    std::vector<char*> jn = {const_cast<char*>("pan"), const_cast<char*>("tilt")};
    std::vector<trajectory_msgs_msg_dds__JointTrajectoryPoint_> pts(points.size());
    std::vector<std::vector<double>> values(points.size());
    for (std::size_t k = 0; k < points.size(); ++k) {
      values[k] = {points[k][0], points[k][1]};
      pts[k] = {};
      pts[k].positions = {2, 2, values[k].data(), false};
      const auto ns_total = times[k].count();
      pts[k].time_from_start = {static_cast<int32_t>(ns_total / 1000000000),
                                static_cast<uint32_t>(ns_total % 1000000000)};
    }
    trajectory_msgs_msg_dds__JointTrajectory_ msg{};
    msg.header.stamp = {stamp.sec, stamp.nanosec};
    msg.header.frame_id = const_cast<char*>("");
    msg.joint_names = {2, 2, jn.data(), false};
    msg.points = {static_cast<uint32_t>(pts.size()), static_cast<uint32_t>(pts.size()), pts.data(), false};
    trajectory_writer.Write(&msg);
  }
  std::this_thread::sleep_for(600ms + 1000ms + 700ms);

  std::lock_guard lock(heard.mu);
  // On time (issue 22: the bridge sends each joint's points as one cubic
  // trajectory): the robot holds where it is until header.stamp, as JTC
  // does, then passes through each point at its time -- the STATE sample
  // nearest each point's time is within the distance the joint can cover in
  // the time between them.
  bool held = true;
  for (const LcmSample& s : heard.lcm) {
    if (s.server_time < server_start - std::chrono::milliseconds(period_ms) &&
        (std::abs(s.positions[pan]) > 1e-9 || std::abs(s.positions[tilt]) > 1e-9)) {
      held = false;
    }
  }
  Check(held, "the robot holds until header.stamp");
  for (std::size_t k = 0; k < points.size(); ++k) {
    const TimePoint due = server_start + times[k];
    const LcmSample* nearest = nullptr;
    for (const LcmSample& s : heard.lcm) {
      if (!nearest || std::abs(Ms(s.server_time - due)) < std::abs(Ms(nearest->server_time - due)))
        nearest = &s;
    }
    const std::string name =
        "point " + std::to_string(k) + " (+" + std::to_string(Ms(times[k]) / 1000) + " s)";
    const double off = nearest ? std::max(std::abs(nearest->positions[pan] - points[k][0]),
                                          std::abs(nearest->positions[tilt] - points[k][1]))
                               : 1e9;
    // A STATE sample carries the state of the server's last control period
    // (the kinematic driver's 10 ms), up to one period before its own time.
    const double allowed =
        nearest ? 3.0 * (std::abs(Ms(nearest->server_time - due)) + 10.0) / 1000 + 1e-6 : 0;
    Check(nearest && off <= allowed,
          name + ": passed at its time (" + std::to_string(off) + " rad from it, " +
              (nearest ? std::to_string(Ms(nearest->server_time - due)) : "?") + " ms from due)");
  }
  // joint_states follow the STATE stream: every JointState is a STATE sample
  // (same positions), stamped with its time.
  std::size_t matched = 0, stamp_ok = 0;
  std::map<std::int64_t, std::vector<double>> positions_at;
  for (const JointStateSeen& j : heard.joint_states) {
    positions_at[Key(j.stamp)] = j.positions;
    const auto it = std::find_if(heard.lcm.begin(), heard.lcm.end(),
                                 [&](const LcmSample& s) { return s.positions == j.positions; });
    if (it == heard.lcm.end()) continue;
    ++matched;
    // Several samples can share positions (at rest): take the nearest in time.
    Duration best = Duration::max();
    for (const LcmSample& s : heard.lcm) {
      if (s.positions != j.positions) continue;
      best =
          std::min(best, Duration(std::abs((SteadyOf(j.stamp) - client.ClientTime(s.server_time)).count())));
    }
    stamp_ok += best < 5ms;
  }
  const std::size_t n = heard.joint_states.size();
  Check(n >= heard.lcm.size() * 8 / 10, "joint_states at the stream's rate (" + std::to_string(n) + " for " +
                                            std::to_string(heard.lcm.size()) + " STATE samples)");
  Check(n > 0 && matched == n, "every JointState carries a STATE sample's positions (" +
                                   std::to_string(matched) + " of " + std::to_string(n) + ")");
  Check(n > 0 && stamp_ok == n, "every JointState is stamped with its sample's time, within 5 ms (" +
                                    std::to_string(stamp_ok) + " of " + std::to_string(n) + ")");
  // tf follows: each moving transform is the model's forward kinematics at
  // the JointState of the same stamp.
  Kinematics kin(model);
  std::size_t tf_checked = 0, tf_bad = 0;
  for (const TfSeen& t : heard.tf) {
    auto q = positions_at.find(Key(t.stamp));
    const auto child = t.child.substr(prefix.size());
    const auto link = model.FindLink(child);
    if (q == positions_at.end() || !link || model.parent_joint(*link) < 0) continue;
    kin.Update(
        Eigen::Map<const Eigen::VectorXd>(q->second.data(), static_cast<Eigen::Index>(q->second.size())));
    const int parent = model.joint(model.parent_joint(*link)).parent_link;
    const Eigen::Isometry3d want = kin.link_pose(parent).inverse() * kin.link_pose(*link);
    ++tf_checked;
    if (!want.isApprox(t.pose, 1e-9) || t.parent != prefix + model.link(parent).name) ++tf_bad;
  }
  Check(tf_checked > 50 && tf_bad == 0, "tf's moving joints are the model's kinematics at the same sample (" +
                                            std::to_string(tf_checked) + " checked, " +
                                            std::to_string(tf_bad) + " wrong)");
  const std::string root = prefix + model.link(model.roots()[0].link).name;
  Check(!heard.odom_frames.empty() && heard.odom_frames.back() == std::make_pair(std::string("world"), root),
        "odom of the base: world -> " + root);
  return failures ? 1 : 0;
}
