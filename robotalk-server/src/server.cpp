#include "robotalk/server.h"

#include "fault_injector.h"
#include "robot_service.h"
#include "robotalk/channels.h"
#include "robotalk/error.h"
#include "robotalk/protocol_codec.h"
#include "robotalk_msgs/announce_t.hpp"

#include <poll.h>
#include <sys/eventfd.h>
#include <unistd.h>
#include <lcm/lcm-cpp.hpp>

#include <cinttypes>
#include <cstdio>
#include <random>
#include <regex>
#include <thread>

namespace robotalk {
namespace {

constexpr size_t kMaxRepliesBytes = 30000;  // split reply packages well under LCM's 64 KB

bool ValidRobotName(const std::string& name) {
  return !name.empty() && std::regex_match(name, std::regex("[A-Za-z0-9_-]+"));
}

}  // namespace

RobotSpec RobotSpec::Parse(const std::string& text) {
  const auto eq = text.find('=');
  const auto colon = eq == std::string::npos ? std::string::npos : text.find(':', eq);
  if (colon == std::string::npos)
    throw Error("--robot '" + text + "': expected NAME=DRIVER:URDF[,key=value...]");
  RobotSpec spec;
  spec.name = text.substr(0, eq);
  spec.driver = text.substr(eq + 1, colon - eq - 1);
  if (!ValidRobotName(spec.name)) {
    throw Error("--robot '" + text + "': robot name '" + spec.name + "' must be letters, digits, '_' or '-'");
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

class Server::Impl {
 public:
  Impl(ServerOptions options, const std::vector<RobotSpec>& specs, const DriverRegistry& registry,
       const Clock& clock)
      : options_(std::move(options)),
        clock_(clock),
        lcm_(options_.lcm_url),
        faults_(options_.reply_drop_probability, options_.reply_duplicate_probability, options_.fault_seed) {
    if (!lcm_.good()) throw Error("Server: cannot open LCM URL '" + options_.lcm_url + "'");
    if (specs.empty()) throw Error("Server: no robot to serve");
    RobotServiceOptions service_options{
        options_.session_timeout, options_.max_queue, options_.max_future,
        PlaybackEstimatorOptions{options_.playback_min_frames, options_.playback_fraction},
        options_.log_executions};
    for (const RobotSpec& spec : specs) {
      if (robots_.count(spec.name)) throw Error("Server: robot name '" + spec.name + "' is given twice");
      DriverConfig config{spec.name, spec.urdf_path, spec.options};
      std::unique_ptr<Driver> driver = registry.Create(spec.driver, config);
      auto service =
          std::make_unique<RobotService>(spec.name, spec.driver, std::move(driver), clock_, service_options);
      service->set_replies_ready_callback([this] { Signal(); });
      robots_.emplace(spec.name, std::move(service));
    }
    event_fd_ = eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC);
    if (event_fd_ < 0) throw Error("Server: eventfd failed");
    std::random_device rd;
    server_id_ = (static_cast<std::int64_t>(rd()) << 32) ^ rd();
    lcm::Subscription* sub = lcm_.subscribe("ROBOTALK/[^/]+/REQUEST", &Impl::OnRequest, this);
    // LCM drops the newest messages of a full subscription queue: make it deep.
    sub->setQueueCapacity(10000);
  }

  ~Impl() {
    Stop();
    if (event_fd_ >= 0) close(event_fd_);
  }

  void Start() {
    for (auto& [name, robot] : robots_) robot->Start();
    running_ = true;
    daemon_ = std::thread([this] { DaemonLoop(); });
    for (auto& [name, robot] : robots_) {
      std::fprintf(
          stderr, "robotalk-server: serving robot '%s' (%zu links, %d dofs, config %016" PRIx64 ") on '%s'\n",
          name.c_str(), robot->model().links().size(), robot->model().num_dofs(), robot->config_hash(),
          options_.lcm_url.empty() ? "LCM default" : options_.lcm_url.c_str());
    }
  }

  void Stop() {
    if (!running_.exchange(false)) return;
    // Never leave a robot moving: stop each, let its daemon run the STOP, then join.
    for (auto& [name, robot] : robots_) robot->StopRobot("server shutting down");
    for (auto& [name, robot] : robots_) robot->Stop();  // runs the queued STOP before returning
    Signal();
    if (daemon_.joinable()) daemon_.join();
  }

  std::vector<std::string> names() const {
    std::vector<std::string> out;
    for (const auto& [name, robot] : robots_) out.push_back(name);
    return out;
  }

 private:
  void Signal() {
    const std::uint64_t one = 1;
    [[maybe_unused]] ssize_t n = write(event_fd_, &one, sizeof one);
  }

  // The ServerDaemon: LCM receive, replies, announce and session expiry.
  void DaemonLoop() {
    TimePoint next_announce = clock_.Now();
    TimePoint next_expiry = clock_.Now();
    pollfd fds[2] = {{lcm_.getFileno(), POLLIN, 0}, {event_fd_, POLLIN, 0}};
    while (running_) {
      const int ready = poll(fds, 2, 50);
      if (ready > 0 && (fds[0].revents & POLLIN)) lcm_.handleTimeout(0);
      if (ready > 0 && (fds[1].revents & POLLIN)) {
        std::uint64_t count;
        [[maybe_unused]] ssize_t n = read(event_fd_, &count, sizeof count);
      }
      SendReplies();
      const TimePoint now = clock_.Now();
      if (now >= next_expiry) {
        for (auto& [name, robot] : robots_) {
          for (const ExpiredSession& e : robot->ExpireSessions(now)) {
            // Quiet for the ordinary case: a short-lived client (the CLI) that is done.
            if (e.dropped_commands == 0 && !e.moved_robot) continue;
            std::fprintf(
                stderr, "robotalk-server: robot '%s': client %s went silent; %zu queued commands dropped\n",
                name.c_str(), Hex64(static_cast<std::uint64_t>(e.client_id)).c_str(), e.dropped_commands);
          }
        }
        next_expiry = now + std::chrono::milliseconds(100);
      }
      if (now >= next_announce) {
        Announce(now);
        next_announce = now + options_.announce_period;
      }
    }
  }

  // LCM callback: never throws (an exception here would unwind through LCM's C code).
  void OnRequest(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
    const TimePoint received = clock_.Now();
    const std::string robot_name = channel.substr(9, channel.size() - 9 - 8);  // ROBOTALK/<robot>/REQUEST
    auto it = robots_.find(robot_name);
    if (it == robots_.end()) return;  // another server's robot
    RobotService& robot = *it->second;
    try {
      const auto* data = static_cast<const std::uint8_t*>(rbuf->data);
      robotalk_msgs::package_t package = DecodePackage({data, rbuf->data_size});
      const std::string bad = CheckPackageHeader(package);
      ImmediateAnswer answer =
          bad.empty() ? robot.HandlePackage(package, received) : robot.RefusePackage(package, received, bad);
      if (!bad.empty()) {
        std::fprintf(stderr, "robotalk-server: robot '%s': refused package from client %s: %s\n",
                     robot_name.c_str(), Hex64(static_cast<std::uint64_t>(package.header.client_id)).c_str(),
                     bad.c_str());
      }
      if (answer.publish_config) {
        lcm_.publish(ConfigChannel(robot_name), robot.encoded_config().data(),
                     static_cast<unsigned>(robot.encoded_config().size()));
      }
      if (answer.send) Publish(robot_name, answer.package);
      // The paper's congestion injector (§VI-B): a random pause after each
      // received package, during which nothing else is received.
      if (options_.congestion_max_pause.count() > 0) {
        std::this_thread::sleep_for(
            FromSeconds(congestion_(congestion_rng_) * ToSeconds(options_.congestion_max_pause)));
      }
    } catch (const std::exception& e) {
      // Undecodable bytes carry no trustworthy client id to answer: count and log.
      ++malformed_;
      std::fprintf(stderr, "robotalk-server: robot '%s': dropped a malformed package on %s: %s\n",
                   robot_name.c_str(), channel.c_str(), e.what());
    }
  }

  void SendReplies() {
    for (auto& [name, robot] : robots_) {
      states_.clear();
      robot->TakeStates(states_);
      for (const auto& state : states_) lcm_.publish(StateChannel(name), &state);
      outgoing_.clear();
      robot->TakeReplies(outgoing_);
      for (OutgoingReplies& out : outgoing_) {
        robotalk_msgs::reply_package_t package{};
        package.protocol_version = kProtocolVersion;
        package.client_id = out.client_id;
        package.ack_sequence = 0;
        size_t bytes = 0;
        for (const Reply& r : out.replies) {
          package.replies.push_back(ToWire(r));
          bytes += 64 + r.message.size() + 8 * r.values.size();
          if (bytes > kMaxRepliesBytes) {
            Publish(name, package);
            package.replies.clear();
            bytes = 0;
          }
        }
        if (!package.replies.empty()) Publish(name, package);
      }
    }
  }

  void Publish(const std::string& robot, robotalk_msgs::reply_package_t& package) {
    package.num_replies = static_cast<std::int32_t>(package.replies.size());
    package.server_send_us = ToWireMicros(clock_.Now());
    const std::string channel = ReplyChannel(robot, package.client_id);
    for (int copies = faults_.Copies(); copies > 0; --copies) lcm_.publish(channel, &package);
  }

  void Announce(TimePoint now) {
    robotalk_msgs::announce_t a{};
    a.protocol_version = kProtocolVersion;
    a.server_id = server_id_;
    a.server_time_us = ToWireMicros(now);
    a.url_hint = options_.lcm_url;
    for (auto& [name, robot] : robots_) a.robots.push_back(robot->Info());
    a.num_robots = static_cast<std::int32_t>(a.robots.size());
    lcm_.publish(kAnnounceChannel, &a);
  }

  ServerOptions options_;
  const Clock& clock_;
  lcm::LCM lcm_;
  FaultInjector faults_;
  std::map<std::string, std::unique_ptr<RobotService>> robots_;
  std::vector<OutgoingReplies> outgoing_;
  std::vector<robotalk_msgs::robot_state_t> states_;
  std::mt19937_64 congestion_rng_{options_.fault_seed};
  std::uniform_real_distribution<double> congestion_{0.0, 1.0};
  int event_fd_ = -1;
  std::int64_t server_id_ = 0;
  std::atomic<bool> running_{false};
  std::uint64_t malformed_ = 0;
  std::thread daemon_;
};

Server::Server(ServerOptions options, const std::vector<RobotSpec>& robots, const DriverRegistry& registry,
               const Clock& clock)
    : impl_(std::make_unique<Impl>(std::move(options), robots, registry, clock)) {}
Server::~Server() = default;
void Server::Start() { impl_->Start(); }
void Server::Stop() { impl_->Stop(); }
std::vector<std::string> Server::robot_names() const { return impl_->names(); }

}  // namespace robotalk
