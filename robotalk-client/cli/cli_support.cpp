#include "cli_support.h"

#include "describe_format.h"
#include "robotalk/broadcast_signature.h"
#include "robotalk/channels.h"
#include "robotalk/error.h"
#include "robotalk/heard_announcement.h"
#include "robotalk/request.h"
#include "robotalk/routed_lcm_transport.h"
#include "sequence_runner.h"

#include <poll.h>
#include <unistd.h>
#include <lcm/lcm-cpp.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <map>
#include <mutex>
#include <sstream>
#include <thread>

namespace robotalk::cli {

constexpr Duration kAnnounceWait = kAnnouncePeriod + std::chrono::milliseconds(200);  // > one announce period
// The watch listens from here to kAnnounceWait: still more than one period.
constexpr std::chrono::milliseconds kWatchAfter(100);

struct AnnounceWatch::Impl {
  std::string url;
  std::optional<PublicKey> trusted_key;             // keyed: only announcements this key signed count
  std::function<TimePoint(TimePoint)> client_time;  // keyed: freshness by the signed server time
  int wake[2] = {-1, -1};
  mutable std::mutex mu;
  std::map<std::string, TimePoint> heard;  // GUARDED_BY(mu): robot -> last announce (steady clock)
  std::uint64_t stale = 0;                 // GUARDED_BY(mu)
  std::thread thread;

  void On(const lcm::ReceiveBuffer* rbuf, const std::string&) {
    const std::span<const std::uint8_t> bytes(static_cast<const std::uint8_t*>(rbuf->data), rbuf->data_size);
    // Keyed: an unsigned one, or one of another key, is not its server's; a
    // hostile one is dropped, never thrown through LCM.
    const std::optional<HeardAnnouncement> got =
        HearAnnouncement(bytes, trusted_key ? &*trusted_key : nullptr);
    if (!got) return;
    const Announcement& a = got->announcement;
    const TimePoint now = SteadyClock().Now();
    TimePoint at = now;
    if (trusted_key && client_time) {
      // Signed, so the server time is the server's: it was alive then. A
      // recording replayed after the server stopped is that old.
      const TimePoint announced = client_time(a.server_time);
      const std::optional<TimePoint> fresh = FreshAnnouncementTime(now, announced);
      if (!fresh) {
        std::lock_guard lock(mu);
        if (stale++ == 0)
          std::cerr << "robotalk: refused an announcement signed by the server but "
                    << (announced > now ? "stamped " + FormatDuration(announced - now) + " ahead"
                                        : FormatDuration(now - announced) + " old")
                    << " (more than " << FormatDuration(kAnnounceMaxAge)
                    << "): replayed, delayed or of another clock; it does not show the server is there\n";
        return;
      }
      at = *fresh;
    }
    std::lock_guard lock(mu);
    for (const auto& r : a.robots)
      // As many names as ListRobots lists (anyone can announce any name).
      if (heard.size() < kMaxListedRobots || heard.count(r.name)) heard[r.name] = std::max(heard[r.name], at);
  }
  // LCM is opened on this thread, and only after kWatchAfter, so a Connect
  // that succeeds at once neither waits for it nor shares the CPU with a
  // third LCM instance (a one-shot CLI process); poll() on LCM's socket and a
  // pipe lets the destructor wake it.
  void Run() {
    pollfd early = {wake[0], POLLIN, 0};
    if (poll(&early, 1, static_cast<int>(kWatchAfter.count())) > 0) return;  // woken: connected
    std::string main_url;  // ANNOUNCE travels on the main lane in either layout
    try {
      main_url = MainLcmUrl(url);
    } catch (const TransportError&) {
      return;  // the client's own Connect reports the bad URL
    }
    lcm::LCM lcm(main_url);
    if (!lcm.good()) return;
    lcm.subscribe(kAnnounceChannel, &Impl::On, this);
    for (;;) {
      pollfd fds[2] = {{lcm.getFileno(), POLLIN, 0}, {wake[0], POLLIN, 0}};
      if (poll(fds, 2, -1) < 0) continue;
      if (fds[1].revents) return;
      if (fds[0].revents & POLLIN) lcm.handle();
    }
  }
};

AnnounceWatch::AnnounceWatch(const std::string& url, std::string trusted_key,
                             std::function<TimePoint(TimePoint)> client_time)
    : impl_(std::make_unique<Impl>()) {
  impl_->url = url;
  impl_->client_time = std::move(client_time);
  if (!trusted_key.empty()) impl_->trusted_key = PublicKey::Parse(trusted_key);
  if (pipe(impl_->wake) != 0) return;
  impl_->thread = std::thread([this] { impl_->Run(); });
}

AnnounceWatch::~AnnounceWatch() {
  if (impl_->thread.joinable()) {
    const char byte = 1;
    if (write(impl_->wake[1], &byte, 1) != 1) impl_->thread.detach();
    if (impl_->thread.joinable()) impl_->thread.join();
  }
  for (int fd : impl_->wake)
    if (fd >= 0) close(fd);
}

std::set<std::string> AnnounceWatch::Heard() const {
  std::lock_guard lock(impl_->mu);
  std::set<std::string> names;
  for (const auto& entry : impl_->heard) names.insert(entry.first);
  return names;
}

std::uint64_t AnnounceWatch::Stale() const {
  std::lock_guard lock(impl_->mu);
  return impl_->stale;
}

std::optional<TimePoint> AnnounceWatch::LastHeard(const std::string& robot) const {
  std::lock_guard lock(impl_->mu);
  auto it = impl_->heard.find(robot);
  if (it == impl_->heard.end()) return std::nullopt;
  return it->second;
}

ClientOptions MakeOptions(const GlobalOptions& g) {
  ClientOptions o;
  o.lcm_url = g.url;
  o.timeout = FromSeconds(g.timeout_s);
  o.max_late = g.max_late;
  o.connect_timeout = FromSeconds(g.timeout_s);
  o.key_file = g.key_file;
  o.server_key_file = g.server_key;
  o.known_servers_file = g.known_servers;
  return o;
}

namespace {
// Trust on first use says so, as SSH does (docs/security.md, "Which server?").
std::unique_ptr<RobotClient> SayIfPinned(std::unique_ptr<RobotClient> client, const std::string& robot) {
  const TrustedServer trust = client->trusted_server();
  if (trust.source == TrustedServer::Source::kPinnedNow) {
    std::cerr << "robotalk: first connection to robot '" << robot << "': trusting its server key "
              << trust.fingerprint << " from now on (pinned in " << trust.file << ")\n";
  }
  return client;
}
}  // namespace

std::unique_ptr<RobotClient> ConnectClient(const GlobalOptions& g, const std::string& robot, ClockUse clock) {
  AnnounceWatch watch(g.url);
  const Duration total = FromSeconds(g.timeout_s);
  ClientOptions options = MakeOptions(g);
  if (clock == ClockUse::kUntimed) options.clock_sync_rounds = 1;
  options.connect_timeout = std::min(total, kAnnounceWait);
  auto client = std::make_unique<RobotClient>(options);
  try {
    client->Connect(robot);
    return SayIfPinned(std::move(client), robot);
  } catch (const TimeoutError&) {
    const std::set<std::string> heard = watch.Heard();
    if (heard.count(robot) == 0) {
      std::string list;
      for (const auto& n : heard) list += (list.empty() ? "" : ", ") + n;
      if (!list.empty()) throw ClientError("no robot '" + robot + "' on this network (heard: " + list + ")");
      if (options.connect_timeout >= kAnnounceWait)
        throw ClientError("no robot '" + robot + "' on this network (no server announced itself within " +
                          FormatDuration(options.connect_timeout) +
                          "; is robotalk-server running with this --url?)");
      // A --timeout shorter than an announce period cannot rule a server
      // out, but the likely cause is still the same: say that, not HELLO.
      throw ClientError("no robot '" + robot + "' answered within " + FormatDuration(total) +
                        " and no server announced itself meanwhile; is robotalk-server running with this "
                        "--url? (servers announce once a second: a --timeout under " +
                        FormatDuration(kAnnounceWait) + " may miss one)");
    }
    if (options.connect_timeout >= total) throw;
  }
  // Announced but slow to answer: use the rest of --timeout.
  options.connect_timeout = total - options.connect_timeout;
  client = std::make_unique<RobotClient>(options);
  client->Connect(robot);
  return SayIfPinned(std::move(client), robot);
}

void ExitAfterOutput(int status) {
  std::cout.flush();
  std::cerr.flush();
  std::fflush(nullptr);
  std::_Exit(status);
}

std::string ReplyJson(const Reply& r) {
  return JsonText(nlohmann::ordered_json{{"id", r.id},
                                         {"signal", ToString(r.signal)},
                                         {"message", r.message},
                                         {"exec_time_us", ToWireMicros(r.exec_time)},
                                         {"lateness_s", ToSeconds(r.lateness)},
                                         {"values", r.values}});
}

std::string StateJson(const StateSample& s) {
  return JsonText(nlohmann::ordered_json{{"robot", s.robot},
                                         {"sample", s.sample},
                                         {"server_time_us", ToWireMicros(s.server_time)},
                                         {"period_s", ToSeconds(s.period)},
                                         {"panic", s.panic},
                                         {"moving", s.moving},
                                         {"base", {s.base.x, s.base.y, s.base.theta, s.base.v, s.base.omega}},
                                         {"position", s.positions},
                                         {"velocity", s.velocities},
                                         {"effort", s.efforts},
                                         {"link",
                                          {{"client_id", Hex64(static_cast<std::uint64_t>(s.link.client_id))},
                                           {"level", ToString(s.link.level)},
                                           {"round_trip_s", ToSeconds(s.link.round_trip)},
                                           {"jitter_s", ToSeconds(s.link.jitter)},
                                           {"loss", s.link.loss},
                                           {"late", s.link.late},
                                           {"expired", s.link.expired}}}});
}

std::string RobotsJson(const std::vector<AnnouncedRobot>& robots) {
  nlohmann::ordered_json list = nlohmann::ordered_json::array();
  for (const AnnouncedRobot& r : robots) {
    list.push_back({{"name", r.name},
                    {"driver", r.driver},
                    {"dofs", r.total_dofs},
                    {"base", ToString(r.base_type)},
                    {"config_hash", Hex64(r.config_hash)},
                    {"panic", r.panic},
                    {"clients", r.num_clients},
                    {"server", Hex64(static_cast<std::uint64_t>(r.server_id))},
                    {"server_key", r.server_key.empty() ? nlohmann::ordered_json(nullptr)
                                                        : nlohmann::ordered_json(r.server_key)}});
  }
  return JsonText(list);
}

}  // namespace robotalk::cli
