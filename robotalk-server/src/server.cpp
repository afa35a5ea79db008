#include "robotalk/server.h"

#include "panic_latch.h"
#include "robot_daemon.h"
#include "robotalk/channels.h"
#include "robotalk/config_message.h"
#include "robotalk/error.h"
#include "robotalk/keys.h"
#include "robotalk/routed_lcm_transport.h"
#include "server_daemon.h"
#include "server_log.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstdlib>

namespace robotalk {
namespace {

// RobotDaemons whose thread the shutdown gave up waiting for (a driver call
// that hangs): that thread may still use them, so they are never destroyed.
std::vector<std::unique_ptr<RobotDaemon>>& AbandonedRobots() {
  static auto* abandoned = new std::vector<std::unique_ptr<RobotDaemon>>;
  return *abandoned;
}

}  // namespace

LogWriter& ServerLog() {
  static LogWriter* const log = new LogWriter("robotalk-server: ", LogWriter::Stderr());
  return *log;
}

RobotSpec RobotSpec::Parse(const std::string& text) {
  const auto eq = text.find('=');
  const auto colon = eq == std::string::npos ? std::string::npos : text.find(':', eq);
  if (colon == std::string::npos)
    throw Error("--robot '" + text + "': expected NAME=DRIVER:URDF[,key=value...]");
  RobotSpec spec;
  spec.name = text.substr(0, eq);
  spec.driver = text.substr(eq + 1, colon - eq - 1);
  if (const std::string why = RobotNameProblem(spec.name); !why.empty()) {
    throw Error("--robot '" + text + "': robot name '" + spec.name + "': " + why);
  }
  if (spec.driver.empty()) throw Error("--robot '" + text + "': no driver given");
  // URDF path, then key=value options, comma separated.
  std::vector<std::string> parts;
  for (size_t pos = colon + 1;;) {
    const size_t comma = text.find(',', pos);
    parts.push_back(text.substr(pos, comma == std::string::npos ? std::string::npos : comma - pos));
    if (comma == std::string::npos) break;
    pos = comma + 1;
  }
  spec.urdf_path = parts.front();
  if (spec.urdf_path.empty()) throw Error("--robot '" + text + "': no URDF file given");
  for (size_t i = 1; i < parts.size(); ++i) {
    const auto oeq = parts[i].find('=');
    if (oeq == std::string::npos || oeq == 0) {
      throw Error("--robot '" + text + "': option '" + parts[i] + "' is not key=value");
    }
    spec.options[parts[i].substr(0, oeq)] = parts[i].substr(oeq + 1);
  }
  return spec;
}

namespace {

// Keyed mode from the key and access-list files (errors name the file).
SessionTableOptions TableOptions(const ServerOptions& options) {
  SessionTableOptions table;
  table.max_sessions = options.max_sessions;
  if (options.key_file.empty() != options.clients_file.empty()) {
    throw Error("keyed mode needs both --key (the server's secret key) and --clients (the access list)");
  }
  if (options.key_file.empty()) {
    SayServer(
        "open mode: any process on the LAN may command these robots "
        "(--key and --clients turn on authentication; docs/security.md)");
    return table;
  }
  table.identity = std::make_shared<const KeyPair>(ReadSecretKeyFile(options.key_file));
  table.access = std::make_shared<const AccessList>(AccessList::ReadFile(options.clients_file));
  SayServer("keyed mode: " + std::to_string(table.access->size()) + " client keys from " +
            options.clients_file + "; server key " + table.identity->public_key.Fingerprint());
  return table;
}

}  // namespace

class Server::Impl {
 public:
  Impl(Transport* transport, ServerOptions options, const std::vector<RobotSpec>& specs,
       const DriverRegistry& registry, const Clock& clock)
      : options_(std::move(options)), clock_(clock) {
    if (specs.empty()) throw Error("Server: no robot to serve");
    if (const char* env = std::getenv("ROBOTALK_PRECISE_TIMING"); env != nullptr && std::string(env) == "0") {
      options_.precise_timing = false;  // the one place the environment is read
    }
    if (!transport) {
      owned_transport_ = OpenLcmTransport(options_.lcm_url);
      transport = owned_transport_.get();
    }
    if (options_.panic_latch_path.empty() && !options_.state_dir.empty()) {
      PanicLatch::MakeStateDir(options_.state_dir);
      options_.panic_latch_path = PanicLatch::LatchFileFor(options_.state_dir, transport->url());
    }
    server_daemon_ = std::make_unique<ServerDaemon>(
        *transport, clock_,
        ServerDaemonOptions{.announce_period = options_.announce_period,
                            .congestion_max_pause = options_.congestion_max_pause,
                            .reply_drop_probability = options_.reply_drop_probability,
                            .reply_duplicate_probability = options_.reply_duplicate_probability,
                            .fault_seed = options_.fault_seed,
                            .log_lines_per_second = options_.log_lines_per_second,
                            .panic_latch_path = options_.panic_latch_path,
                            .allow_duplicate_robots = options_.allow_duplicate_robots,
                            .sessions = TableOptions(options_),
                            .traffic_layout = transport->traffic_layout(),
                            .fifo_priority = options_.precise_timing ? 5 : 0});
    SessionOptions sessions{options_.session_timeout, options_.max_queue, options_.max_future};
    sessions.limits.max_goto_distance = options_.max_goto_distance;
    sessions.playback = PlaybackEstimatorOptions{options_.playback_min_frames, options_.playback_fraction};
    sessions.playback.quick_start = options_.playback_estimator != "paper";
    sessions.playback.adaptive = options_.playback_estimator == "adaptive";
    sessions.playback.max_stretch = options_.playback_stretch;
    sessions.playback.thin_stretch = options_.playback_thin_stretch;
    sessions.playback.adaptive_margin = options_.playback_margin;
    sessions.playback.queue_start = options_.playback_queue_start;
    sessions.playback.follow_queue = options_.playback_follow_queue;
    sessions.playback.burst_wait_discount = options_.playback_burst_discount;
    sessions.playback.copies_start = options_.playback_copies_start;
    sessions.playback_resent_delays = options_.playback_resent_delays;
    sessions.log_playback = options_.log_playback;
    sessions.playback.start_lead = options_.playback_start_lead;
    // The server-wide bound of queued items, an equal part per robot.
    sessions.max_robot_queue = std::max<std::size_t>(options_.max_queued_total / specs.size(), 1);
    sessions.max_sessions_per_robot = options_.max_sessions_per_robot;
    sessions.link_stop = options_.link_stop;
    RobotDaemonOptions daemon_options{.log_executions = options_.log_executions,
                                      .driver_call_bound = options_.driver_call_bound,
                                      .precise_timing = options_.precise_timing,
                                      .max_acceleration = options_.max_acceleration};
    static_assert(BaseAccelerationLimit{}.linear == kDefaultBaseLinearAcceleration &&
                  BaseAccelerationLimit{}.angular == kDefaultBaseAngularAcceleration);
    for (const auto& [name, limit] : options_.robot_max_late) {
      if (std::none_of(specs.begin(), specs.end(), [&](const RobotSpec& s) { return s.name == name; }))
        throw Error("Server: --max-late " + name + "=...: no robot '" + name + "' is served");
    }
    for (const auto& [name, limit] : options_.robot_base_acceleration) {
      if (std::none_of(specs.begin(), specs.end(), [&](const RobotSpec& s) { return s.name == name; }))
        throw Error("Server: --max-base-acceleration " + name + "=...: no robot '" + name + "' is served");
    }
    for (const RobotSpec& spec : specs) {
      for (const auto& robot : robots_) {
        if (robot->robot_name() == spec.name)
          throw Error("Server: robot name '" + spec.name + "' is given twice");
      }
      DriverConfig config{spec.name, spec.urdf_path, spec.options};
      const auto base = options_.robot_base_acceleration.find(spec.name);
      const BaseAccelerationLimit& accel =
          base != options_.robot_base_acceleration.end() ? base->second : options_.base_acceleration;
      if (!(accel.linear > 0) || !(accel.angular > 0) || !std::isfinite(accel.linear) ||
          !std::isfinite(accel.angular))
        throw Error("Server: robot '" + spec.name +
                    "': the base acceleration limit must be > 0 (m/s², rad/s²)");
      daemon_options.base_linear_acceleration = accel.linear;
      daemon_options.base_angular_acceleration = accel.angular;
      robots_.push_back(std::make_unique<RobotDaemon>(
          spec.name, spec.driver, registry.Create(spec.driver, config), clock_, daemon_options));
      const auto own_limit = options_.robot_max_late.find(spec.name);
      sessions.max_late = own_limit != options_.robot_max_late.end() ? own_limit->second : options_.max_late;
      robots_.back()->LogLateStarts(options_.log_playback);  // its late starts explained (issue 23)
      server_daemon_->AddRobot(*robots_.back(), sessions);
    }
    url_ = transport->url();
  }

  ~Impl() { Stop(); }

  void Start() {
    if (!options_.panic_latch_path.empty()) {
      SayServer("panic latch " + options_.panic_latch_path + " (a panic survives a restart)");
    }
    // The ServerDaemon writes a robot's "starts in PANIC" as it starts, so
    // that line comes before "serving robot" (tests and operators wait for it).
    for (auto& robot : robots_) robot->Start();
    server_daemon_->Start();
    running_ = true;
    for (auto& robot : robots_) {
      SayServer("serving robot '" + robot->robot_name() + "' (" +
                std::to_string(robot->model().links().size()) + " links, " +
                std::to_string(robot->model().num_dofs()) + " dofs, config " +
                Hex64(ConfigHash(robot->model())) + ") on '" + url_ + "'");
    }
  }

  void Stop() {
    if (!running_.exchange(false)) return;
    // Never leave a robot moving: take no command any more, end every
    // robot's thread at once, then STOP each robot as the last command its
    // driver gets; what still waited never runs (issue 19: a command due
    // while another robot stopped ran after its STOP).
    server_daemon_->Stop();
    for (auto& robot : robots_) robot->EndSoon();
    // Each robot's thread drops what waits and STOPs its robot itself, all
    // at once: a driver call that hangs keeps no other robot from its STOP.
    // While the server waits, the call bound is watched as while it served
    // (the ServerDaemon that watched it has stopped): a call past it is a
    // driver fault, its command answered ERROR and the robot latched in
    // panic on disk. A call still running at twice the bound is given up on:
    // the server says so and shuts down without that robot's STOP (its
    // thread still STOPs it should the call ever return).
    const Duration bound = options_.driver_call_bound;
    std::vector<std::unique_ptr<RobotDaemon>*> left;
    for (auto& robot : robots_) left.push_back(&robot);
    while (!left.empty()) {
      std::erase_if(left, [](std::unique_ptr<RobotDaemon>* robot) {
        if (!(*robot)->WaitEnded(Duration(0))) return false;
        (*robot)->Shutdown();  // joins: it has ended
        return true;
      });
      const TimePoint now = clock_.Now();
      bool flush = false;  // a fault or a NOT STOPPED line to write now
      for (auto* robot : left) flush = (*robot)->CheckOverrun(now) || flush;
      std::erase_if(left, [&](std::unique_ptr<RobotDaemon>* robot) {
        RobotDaemon& daemon = **robot;
        const Duration running = daemon.CallRunning(now);
        if (bound.count() <= 0 || running <= 2 * bound) return false;
        if (!daemon.Abandon(now)) {
          return false;  // its call returned meanwhile (its STOP runs) or it ended: the next turn
        }
        flush = true;
        not_stopped_.push_back(daemon.robot_name());
        AbandonedRobots().push_back(std::move(*robot));  // its thread may still use it: never destroyed
        return true;
      });
      if (flush) server_daemon_->Flush();  // the latch, the ERROR, the log lines now
      if (!left.empty()) (*left.front())->WaitEnded(std::chrono::milliseconds(20));
    }
    std::erase(robots_, nullptr);
    server_daemon_->Flush();  // the STOPs' log lines, the last replies and samples
  }

  std::vector<std::string> names() const { return server_daemon_->robot_names(); }
  const ServerDaemon& daemon() const { return *server_daemon_; }
  std::vector<std::string> not_stopped() const { return not_stopped_; }

 private:
  ServerOptions options_;
  const Clock& clock_;
  std::unique_ptr<Transport> owned_transport_;
  std::vector<std::unique_ptr<RobotDaemon>> robots_;
  std::unique_ptr<ServerDaemon> server_daemon_;  // destroyed before the robots it refers to
  std::string url_;
  std::atomic<bool> running_{false};
  std::vector<std::string> not_stopped_;
};

Server::Server(ServerOptions options, const std::vector<RobotSpec>& robots, const DriverRegistry& registry,
               const Clock& clock)
    : impl_(std::make_unique<Impl>(nullptr, std::move(options), robots, registry, clock)) {}
Server::Server(Transport& transport, ServerOptions options, const std::vector<RobotSpec>& robots,
               const DriverRegistry& registry, const Clock& clock)
    : impl_(std::make_unique<Impl>(&transport, std::move(options), robots, registry, clock)) {}
Server::~Server() = default;
void Server::Start() { impl_->Start(); }
void Server::Stop() { impl_->Stop(); }
std::vector<std::string> Server::robot_names() const { return impl_->names(); }
std::size_t Server::serving() const { return impl_->daemon().serving(); }
std::vector<std::string> Server::refusals() const { return impl_->daemon().refusals(); }
std::vector<std::string> Server::not_stopped() const { return impl_->not_stopped(); }

}  // namespace robotalk
