#include "ros2_bridge.h"

#include "dds_entities.h"
#include "robotalk/announce_listener.h"
#include "robotalk/connect_scheduler.h"
#include "robotalk/log_limiter.h"
#include "robotalk/log_writer.h"
#include "robotalk/robot_client.h"
#include "robotalk/routed_lcm_transport.h"
#include "ros_wire.h"

#include <sys/resource.h>

#include <algorithm>
#include <atomic>
#include <condition_variable>
#include <fstream>
#include <iostream>
#include <map>
#include <mutex>
#include <set>
#include <sstream>
#include <thread>

namespace robotalk::ros2 {
namespace {

using SteadyTime = std::chrono::steady_clock::time_point;

// The bridge's log. A ROS 2 peer can send a cmd_vel or trajectory the bridge
// refuses as fast as DDS carries them, and anyone on the LAN can announce
// robot names no server answers for: each refusal or failed connect was a
// line of its own (2,000 refused cmd_vel, 2,000 lines). Such lines (LogLimited)
// pass one LogLimiter, as the server's: a line repeated is printed once and
// summarised every 10 s; at most 20 lines a second, the rest counted. The
// bridge's own actions (a robot bridged, the cmd_vel timeout's stop, STOP on
// shutdown) come at its own pace and are always printed (Log), so a flood
// cannot hide them. Lines come from DDS listener threads, the connector and
// Run(): one mutex, held while printing too, so lines never interleave;
// printed through a LogWriter (robotalk/log_writer.h), never waiting long.
class LimitedLog {
 public:
  void Limited(const std::string& line) {
    std::lock_guard lock(mu_);
    limiter_.Add(line, SteadyClock().Now(), out_);
    Print();
  }
  void Always(const std::string& line) {
    std::lock_guard lock(mu_);
    out_.push_back(line);
    Print();
  }
  /// Summaries that fell due (Run() calls it every iteration).
  void Tick() {
    std::lock_guard lock(mu_);
    limiter_.Tick(SteadyClock().Now(), out_);
    Print();
  }
  /// Every pending summary (at shutdown).
  void Flush() {
    std::lock_guard lock(mu_);
    limiter_.Flush(SteadyClock().Now(), out_);
    Print();
  }

 private:
  void Print() {  // REQUIRES: mu_
    // Waits for stderr at most LogWriter::kMaxWait: a stderr that takes
    // nothing (a full pipe, a terminal stopped with Ctrl-S) must not hold the
    // cmd_vel timeout's stop, which logs first (the base drove on).
    if (!out_.empty()) writer_.Write(out_);
  }
  LogWriter writer_{"robotalk-ros2: ", LogWriter::Stderr()};  // the process's one writer of stderr
  std::mutex mu_;
  LogLimiter limiter_;            // GUARDED_BY(mu_)
  std::vector<std::string> out_;  // GUARDED_BY(mu_)
};

LimitedLog& TheLog() {
  static LimitedLog log;
  return log;
}

void Log(const std::string& line) { TheLog().Always(line); }
void LogLimited(const std::string& line) { TheLog().Limited(line); }

// The system-clock (ROS time) instant of a steady-clock instant, read now.
SystemTime ToSystem(TimePoint steady) {
  const auto sys_now = std::chrono::time_point_cast<Duration>(std::chrono::system_clock::now());
  const auto steady_now = std::chrono::time_point_cast<Duration>(std::chrono::steady_clock::now());
  return sys_now + (steady - steady_now);
}

std::string ReadFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error("--urdf: cannot read '" + path + "'");
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

struct Pending {
  PendingReply reply;
  std::string what;  // "JOINT_SETPOINT 'pan' at +0.300 s"
  // The bridge's own stop of the base (the cmd_vel timeout): if it is not
  // executed (refused, e.g. "command not queued" behind the bridge's own
  // trajectory, or its outcome unknown), a STOP follows, which always runs.
  bool stop_if_not_executed = false;
};

}  // namespace

// One bridged robot. Built whole by the connector thread, then shared.
struct RobotLink {
  std::string name, token, prefix, root_frame;
  std::unique_ptr<RobotModel> model;
  BaseType base = BaseType::kFixed;
  std::unique_ptr<RobotFrames> frames;  // publish_mu
  std::unique_ptr<JointStateBuffer> joint_state_buffer;
  TfBuffer tf_buffer;
  std::string urdf;
  std::unique_ptr<DdsWriter> joint_states, odom, description;
  std::unique_ptr<DdsReader> trajectory, cmd_vel;

  // Held by the stream callback while it publishes: Close() takes it to know
  // no sample is being published with what it is about to destroy (the
  // client may still call back after StopStateStream, or when that fails).
  std::mutex publish_mu;
  bool closed = false;  // GUARDED_BY(publish_mu)

  std::mutex mu;
  std::vector<Pending> pending;  // GUARDED_BY(mu)
  bool set_moving = false;       // GUARDED_BY(mu): a motion was sent; STOP on shutdown
  std::atomic<std::int64_t> last_cmd_vel_ns{0};
  std::atomic<bool> base_moving{false};
  std::atomic<bool> twist_note_told{false};

  // publish_mu.
  std::vector<std::int64_t> latencies_ns;
  std::uint64_t samples = 0, publish_failures = 0;

  // Last: destroyed first, which joins its ReadDaemon before the writers go.
  std::unique_ptr<RobotClient> client;
};

class Ros2Bridge::Impl {
 public:
  explicit Impl(const Ros2Options& options)
      : options_(options),
        participant_(options.domain,
                     options.dds_interface.empty() ? "" : InterfaceConfig(options.dds_interface)),
        tf_(participant_, tf2_msgs_msg_dds__TFMessage__desc, "/tf", kTfQos),
        tf_static_(participant_, tf2_msgs_msg_dds__TFMessage__desc, "/tf_static", kLatchedQos) {
    getrusage(RUSAGE_SELF, &usage_start_);
    start_ = std::chrono::steady_clock::now();
    connector_ = std::jthread([this](std::stop_token st) { ConnectLoop(st); });
  }

  ~Impl() {
    connector_.request_stop();
    cv_.notify_all();
    if (connector_.joinable()) connector_.join();
    std::map<std::string, std::shared_ptr<RobotLink>> robots;
    {
      std::lock_guard lock(mu_);
      robots = robots_;
    }
    for (auto& [name, r] : robots) Close(*r);
    TheLog().Flush();  // what repeated since its last summary
  }

  void Run() {
    const SteadyTime end = options_.duration > Duration(0) ? start_ + options_.duration : SteadyTime::max();
    std::unique_lock lock(mu_);
    while (!stopping_ && std::chrono::steady_clock::now() < end) {
      cv_.wait_for(lock, std::chrono::milliseconds(20));
      auto robots = robots_;
      lock.unlock();
      for (auto& [name, r] : robots) Housekeep(*r);
      TheLog().Tick();
      lock.lock();
    }
    end_ = std::chrono::steady_clock::now();
    getrusage(RUSAGE_SELF, &usage_end_);
  }

  void Stop() {
    std::lock_guard lock(mu_);
    stopping_ = true;
    cv_.notify_all();
  }

  std::string StatsText() const;

 private:
  ClientOptions MakeClientOptions() const {
    ClientOptions c;
    c.lcm_url = options_.lcm_url;
    c.key_file = options_.key_file;
    c.server_key_file = options_.server_key_file;
    return c;
  }

  // Connects every robot wanted (--robot, or every one announced) that is not
  // bridged yet. Anyone can announce a name no server answers for, and a
  // connect waits for an answer up to its timeout: the names kept, the
  // connects at once, their timeouts and retries are a ConnectScheduler's
  // (robotalk/connect_scheduler.h, as robotalk-web's), so a name that never
  // answers delays no other and a forger cannot keep a real robot out (they
  // connected one at a time, 5 s each: 255 forged names held a real robot
  // back 21 minutes; 256 re-announced kept the table full for good). A robot
  // bridged stays bridged until the bridge exits.
  void ConnectLoop(std::stop_token st) {
    ConnectSchedulerOptions options;
    options.max_names = std::max(options.max_names, options_.robots.size());  // --robot: every one
    ConnectScheduler scheduler(
        [this](const std::string& name, Duration timeout) {
          std::shared_ptr<RobotLink> link = Connect(name, timeout);
          std::lock_guard lock(mu_);  // at once: Run() watches its cmd_vel from now on
          robots_[name] = std::move(link);
        },
        [](const std::string& name, const std::string& error, Duration retry_in) {
          LogLimited("robot '" + name + "': " + error + " (trying again in " +
                     std::to_string(static_cast<int>(ToSeconds(retry_in))) + " s)");
        },
        options);
    // Every robot announced: heard as it is announced (with --server-key,
    // only what that key signed), on the listener's thread.
    std::unique_ptr<AnnounceListener> announcements;  // destroyed before the scheduler
    while (!st.stop_requested()) {
      if (options_.robots.empty()) {
        if (!announcements) {
          try {
            announcements = std::make_unique<AnnounceListener>(
                OpenLcmTransport(options_.lcm_url, kAnnounceQueue), ExplicitServerKey(MakeClientOptions()),
                [&scheduler](const HeardAnnouncement& heard) {
                  for (const RobotAnnouncement& r : heard.announcement.robots)
                    if (scheduler.Announce(r.name) == ConnectScheduler::Heard::kAdded)
                      LogLimited("robot '" + r.name + "' announced");
                });
          } catch (const std::exception& e) {
            LogLimited(std::string("listening for robots: ") + e.what());
          }
        }
      } else {
        for (const std::string& name : options_.robots) scheduler.Announce(name);  // wanted: never silent
      }
      scheduler.Poll();
      std::unique_lock lock(mu_);
      cv_.wait_for(lock, std::chrono::milliseconds(200), [&] { return st.stop_requested(); });
    }
    // The scheduler waits for each connect still running (up to its timeout);
    // one that succeeds is in robots_, so shutdown stops it.
  }

  std::shared_ptr<RobotLink> Connect(const std::string& name, Duration connect_timeout) {
    auto r = std::make_shared<RobotLink>();
    r->name = name;
    r->token = RosNameToken(name);
    if (r->token != name) LogLimited("robot '" + name + "': its ROS 2 topics are under /" + r->token);
    r->prefix = FramePrefixFor(options_.frame_prefix, r->token);
    ClientOptions options = MakeClientOptions();
    options.connect_timeout = connect_timeout;
    r->client = std::make_unique<RobotClient>(options);
    r->client->Connect(name);
    r->model = std::make_unique<RobotModel>(r->client->model());
    r->base = r->model->roots().empty() ? BaseType::kFixed : r->model->roots()[0].base;
    r->root_frame =
        r->model->roots().empty() ? "" : r->prefix + r->model->link(r->model->roots()[0].link).name;
    r->frames = std::make_unique<RobotFrames>(*r->model, r->prefix, options_.world_frame);
    r->joint_state_buffer = std::make_unique<JointStateBuffer>(JointStateNames(*r->model));
    r->latencies_ns.reserve(1 << 20);
    const std::string ns = "/" + r->token;
    r->joint_states = std::make_unique<DdsWriter>(participant_, sensor_msgs_msg_dds__JointState__desc,
                                                  ns + "/joint_states", kDefaultQos);
    if (r->base != BaseType::kFixed) {
      r->odom = std::make_unique<DdsWriter>(participant_, nav_msgs_msg_dds__Odometry__desc, ns + "/odom",
                                            kDefaultQos);
    }
    auto urdf = options_.urdf.find(name);
    r->urdf = urdf != options_.urdf.end() ? ReadFile(urdf->second) : ModelToUrdf(*r->model);
    r->description = std::make_unique<DdsWriter>(participant_, std_msgs_msg_dds__String__desc,
                                                 ns + "/robot_description", kLatchedQos);
    const auto description = MakeString(r->urdf);
    r->description->Write(&description);
    RobotLink* raw = r.get();
    r->client->StartStateStream(options_.period, [this, raw](const StateSample& s) { OnSample(*raw, s); });
    std::string topics = ns + "/joint_states, /tf, /tf_static, " + ns + "/robot_description";
    if (r->odom) topics += ", " + ns + "/odom";
    if (!options_.read_only) {
      r->trajectory = std::make_unique<DdsReader>(
          participant_, trajectory_msgs_msg_dds__JointTrajectory__desc, ns + "/joint_trajectory", kDefaultQos,
          [this, raw](const void* m) {
            OnTrajectory(*raw,
                         ReadTrajectory(*static_cast<const trajectory_msgs_msg_dds__JointTrajectory_*>(m)));
          });
      topics += "; subscribes " + ns + "/joint_trajectory";
      if (r->base != BaseType::kFixed) {
        r->cmd_vel = std::make_unique<DdsReader>(
            participant_, geometry_msgs_msg_dds__Twist__desc, ns + "/cmd_vel", kBestEffortReaderQos,
            [this, raw](const void* m) {
              OnTwist(*raw, *static_cast<const geometry_msgs_msg_dds__Twist_*>(m));
            });
        topics += ", " + ns + "/cmd_vel";
      }
    }
    PublishStatic(*r);  // last: a robot that failed to connect adds none (it is tried again)
    Log("robot '" + name + "' bridged (DDS domain " + std::to_string(options_.domain) + "): publishes " +
        topics);
    return r;
  }

  // Every robot's static transforms in one message: tf_static keeps only the
  // last message for late joiners (depth 1), as tf2_ros's static broadcaster.
  void PublishStatic(const RobotLink& r) {
    std::lock_guard lock(static_mu_);
    for (const FrameTransform& t : r.frames->static_transforms()) static_all_.push_back(t);
    const RosTime now = ToRosTime(std::chrono::time_point_cast<Duration>(std::chrono::system_clock::now()));
    tf_static_.Write(&static_buffer_.Fill(now, static_all_));
  }

  void OnSample(RobotLink& r, const StateSample& s) {
    const auto in = std::chrono::steady_clock::now();
    std::lock_guard lock(r.publish_mu);
    if (r.closed) return;
    try {
      const RosTime stamp = ToRosTime(ToSystem(r.client->ClientTime(s.server_time)));
      r.joint_states->Write(&r.joint_state_buffer->Fill(stamp, s));
      tf_.Write(&r.tf_buffer.Fill(stamp, r.frames->Update(s)));
      if (r.odom) {
        const auto pose = RobotFrames::RootPose(r.model->roots()[0], s.base);
        const auto odom = MakeOdometry(stamp, options_.world_frame, r.root_frame, pose, s.base);
        r.odom->Write(&odom);
      }
    } catch (const std::exception& e) {
      if (r.publish_failures++ < 3) Log("robot '" + r.name + "': " + e.what());
      return;
    }
    ++r.samples;
    if (r.latencies_ns.size() < r.latencies_ns.capacity()) {
      r.latencies_ns.push_back((std::chrono::steady_clock::now() - in).count());
    }
  }

  void OnTrajectory(RobotLink& r, const TrajectoryMessage& msg) {
    if (msg.points.empty()) {
      LogLimited("robot '" + r.name + "': an empty JointTrajectory: STOP");
      Track(r, r.client->Send(Command{.type = CommandType::kStop}), "STOP (empty JointTrajectory)", false);
      return;
    }
    const TimePoint now = r.client->ServerNow();
    const TimePoint start = msg.stamp.is_zero()
                                ? now
                                : now + (FromRosTime(msg.stamp) - std::chrono::time_point_cast<Duration>(
                                                                      std::chrono::system_clock::now()));
    TrajectoryCommands plan;
    try {
      plan = TrajectoryToCommands(*r.model, msg, start, now);
    } catch (const std::exception& e) {
      LogLimited("robot '" + r.name + "': trajectory refused: " + e.what());
      return;
    }
    std::ostringstream what;
    what << "trajectory of " << msg.points.size() << " points";
    if (plan.points_skipped) what << " (" << plan.points_skipped << " already past, skipped)";
    what << " starts in " << ToSeconds(start - now) << " s, " << plan.commands.size() << " JOINT_SETPOINTs";
    LogLimited("robot '" + r.name + "': " + what.str());
    SendTrajectory(r, std::move(plan.commands), start);
  }

  // Each joint's points as one cubic trajectory in delay mode (issue 22):
  // the server interpolates between them and splices a newer trajectory in.
  // As JTC, the joint holds until header.stamp: a first point after it gets
  // a waypoint at the stamp where the joint is now (a first point at the
  // stamp is reached at the stamp, moving there from where it is now).
  void SendTrajectory(RobotLink& r, std::vector<Command> commands, TimePoint start) {
    std::vector<JointTrajectory> joints;
    for (Command& c : commands) {
      auto it = std::find_if(joints.begin(), joints.end(),
                             [&](const JointTrajectory& j) { return j.joint == c.target; });
      if (it == joints.end()) it = joints.insert(joints.end(), JointTrajectory{c.target, {}});
      it->points.push_back(TrajectoryPoint{.time_from_start = *c.start_time.time() - start,
                                           .positions = std::move(c.values),
                                           .velocities = std::move(c.velocities),
                                           .accelerations = std::move(c.accelerations)});
    }
    const TrajectoryOptions options{
        .mode = CommandMode::kDelay, .interpolation = Interpolation::kCubic, .start = start};
    for (JointTrajectory& j : joints) {
      try {
        if (!j.points.empty() && j.points.front().time_from_start > Duration::zero()) {
          const Reply now = r.client->JointState(j.joint);
          if (now.signal == Signal::kSuccess && !now.values.empty()) {
            const std::size_t dofs = j.points.front().positions.size();
            j.points.insert(j.points.begin(),
                            TrajectoryPoint{.time_from_start = Duration::zero(),
                                            .positions = std::vector<double>(
                                                now.values.begin(),
                                                now.values.begin() + static_cast<std::ptrdiff_t>(std::min(
                                                                         dofs, now.values.size())))});
          }
        }
        auto replies = r.client->SendTrajectory(j, options);
        for (std::size_t k = 0; k < replies.size(); ++k) {
          std::ostringstream w;
          w << "JOINT_SETPOINT '" << j.joint << "' at +" << ToSeconds(j.points[k].time_from_start) << " s";
          Track(r, std::move(replies[k]), w.str(), true);
        }
      } catch (const std::exception& e) {
        LogLimited("robot '" + r.name + "': sending the trajectory of joint '" + j.joint + "': " + e.what());
        return;
      }
    }
  }

  void OnTwist(RobotLink& r, const geometry_msgs_msg_dds__Twist_& t) {
    std::string note;
    Command c;
    try {
      c = TwistToCommand(r.base, {t.linear.x, t.linear.y, t.linear.z},
                         {t.angular.x, t.angular.y, t.angular.z}, &note);
    } catch (const std::exception& e) {
      LogLimited("robot '" + r.name + "': cmd_vel refused: " + e.what());
      return;
    }
    if (!note.empty() && !r.twist_note_told.exchange(true)) Log("robot '" + r.name + "': cmd_vel: " + note);
    const bool moving = std::any_of(c.values.begin(), c.values.end(), [](double v) { return v != 0; });
    r.last_cmd_vel_ns.store(std::chrono::steady_clock::now().time_since_epoch().count());
    r.base_moving.store(moving);
    Track(r, r.client->Send(std::move(c)), "SETSPEED (cmd_vel)", moving);
  }

  void Track(RobotLink& r, PendingReply reply, std::string what, bool moves,
             bool stop_if_not_executed = false) {
    std::lock_guard lock(r.mu);
    r.set_moving = r.set_moving || moves;
    r.pending.push_back({std::move(reply), std::move(what), stop_if_not_executed});
  }

  void Housekeep(RobotLink& r) {
    const auto now = std::chrono::steady_clock::now();
    if (r.base_moving.load() &&
        now - SteadyTime(std::chrono::nanoseconds(r.last_cmd_vel_ns.load())) > options_.cmd_vel_timeout) {
      r.base_moving.store(false);
      Log("robot '" + r.name + "': no cmd_vel for " + std::to_string(ToSeconds(options_.cmd_vel_timeout)) +
          " s: SETSPEED 0");
      Command stop{.type = CommandType::kSetSpeed};
      stop.values.assign(r.base == BaseType::kHolonomic ? 3 : 2, 0.0);
      Track(r, r.client->Send(std::move(stop)), "SETSPEED 0 (cmd_vel timeout)", false, true);
    }
    std::vector<Pending> pending;
    {
      std::lock_guard lock(r.mu);
      pending.swap(r.pending);
    }
    std::vector<Pending> keep;
    std::string not_executed;  // why the bridge's own stop of the base did not run
    for (Pending& p : pending) {
      std::string failure;
      try {
        auto reply = p.reply.Poll();
        if (!reply) {
          keep.push_back(std::move(p));
        } else if (reply->signal != Signal::kSuccess && reply->signal != Signal::kModified) {
          failure = std::string(ToString(reply->signal)) + " " + reply->message;
        }
      } catch (const std::exception& e) {
        failure = e.what();
      }
      if (failure.empty()) continue;
      LogLimited("robot '" + r.name + "': " + p.what + ": " + failure);
      if (p.stop_if_not_executed) not_executed = p.what + " was not executed (" + failure + ")";
    }
    if (!not_executed.empty()) {  // the base may still be moving: STOP always runs
      Log("robot '" + r.name + "': " + not_executed + ": STOP (every actuator of the robot)");
      Track(r, r.client->Send(Command{.type = CommandType::kStop}), "STOP (cmd_vel timeout)", false);
    }
    std::lock_guard lock(r.mu);
    for (Pending& p : keep) r.pending.push_back(std::move(p));
  }

  void Close(RobotLink& r) {
    r.trajectory.reset();  // no more commands from DDS
    r.cmd_vel.reset();
    bool moved = false;
    {
      std::lock_guard lock(r.mu);
      moved = r.set_moving;
    }
    {
      std::lock_guard lock(r.publish_mu);
      r.closed = true;
    }
    try {
      r.client->StopStateStream();
      if (moved) {
        const Reply reply = r.client->Stop();
        Log("robot '" + r.name + "': STOP on shutdown: " + std::string(ToString(reply.signal)));
      }
    } catch (const std::exception& e) {
      Log("robot '" + r.name + "': on shutdown: " + e.what());
    }
  }

  Ros2Options options_;
  DdsParticipant participant_;
  DdsWriter tf_, tf_static_;
  std::mutex static_mu_;
  std::vector<FrameTransform> static_all_;  // GUARDED_BY(static_mu_)
  TfBuffer static_buffer_;                  // GUARDED_BY(static_mu_)

  mutable std::mutex mu_;
  std::condition_variable cv_;
  bool stopping_ = false;                                     // GUARDED_BY(mu_)
  std::map<std::string, std::shared_ptr<RobotLink>> robots_;  // GUARDED_BY(mu_)
  std::jthread connector_;

  SteadyTime start_, end_;
  rusage usage_start_{}, usage_end_{};
};

std::string Ros2Bridge::Impl::StatsText() const {
  std::ostringstream out;
  const auto cpu = [](const rusage& u) {
    return u.ru_utime.tv_sec + u.ru_stime.tv_sec + (u.ru_utime.tv_usec + u.ru_stime.tv_usec) * 1e-6;
  };
  const double wall = std::chrono::duration<double>(end_ - start_).count();
  out << "robotalk-ros2 stats: wall " << wall << " s, CPU " << cpu(usage_end_) - cpu(usage_start_) << " s ("
      << 100.0 * (cpu(usage_end_) - cpu(usage_start_)) / std::max(wall, 1e-9) << " % of one core)\n";
  std::lock_guard lock(mu_);
  for (const auto& [name, r] : robots_) {
    std::vector<std::int64_t> l;
    std::uint64_t samples = 0;
    {
      std::lock_guard publish(r->publish_mu);
      l = r->latencies_ns;
      samples = r->samples;
    }
    std::sort(l.begin(), l.end());
    const auto pct = [&](double p) {
      return l.empty()
                 ? 0.0
                 : l[std::min(l.size() - 1, static_cast<std::size_t>(p * static_cast<double>(l.size())))] *
                       1e-3;
    };
    out << "robot " << name << ": " << samples << " samples published; STATE in -> DDS out (us): p50 "
        << pct(0.5) << " p90 " << pct(0.9) << " p99 " << pct(0.99) << " max " << pct(1.0) << "\n";
  }
  return out.str();
}

Ros2Bridge::Ros2Bridge(const Ros2Options& options) : impl_(std::make_unique<Impl>(options)) {}
Ros2Bridge::~Ros2Bridge() = default;
void Ros2Bridge::Run() { impl_->Run(); }
void Ros2Bridge::Stop() { impl_->Stop(); }
std::string Ros2Bridge::StatsText() const { return impl_->StatsText(); }

}  // namespace robotalk::ros2
