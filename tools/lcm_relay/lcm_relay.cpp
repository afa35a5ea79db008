#include "lcm_relay.h"

#include <poll.h>

#include <condition_variable>
#include <cstdio>
#include <mutex>
#include <queue>
#include <regex>
#include <stdexcept>
#include <thread>
#include <unordered_map>
#include <vector>

#include <robotalk/routed_lcm_transport.h>
#include <robotalk/traffic_layout.h>
#include <lcm/lcm-cpp.hpp>

#include "echo_filter.h"

namespace robotalk::relay {
namespace {

constexpr int kSideA = 0;
constexpr int kSideB = 1;

struct Message {
  std::string channel;
  int lane = 0;  // on the target side
  std::vector<unsigned char> data;
  std::uint64_t fingerprint = 0;
  TimePoint arrival{};
  int copies_queued = 0;  // guarded by the relay's mu: at 0 it leaves the QueueBound
};

struct Release {
  TimePoint at;
  std::uint64_t order;  // FIFO among equal release times
  int target;
  std::shared_ptr<Message> message;
};

struct Later {
  bool operator()(const Release& x, const Release& y) const {
    return x.at != y.at ? x.at > y.at : x.order > y.order;
  }
};

// One direction: from `source` to the other side.
struct Direction {
  Direction(const DirectionOptions& o, std::uint64_t seed, QueueLimits limits)
      : channel(o.impairment, seed),
        filter(o.channels, std::regex::ECMAScript | std::regex::optimize),
        bound(limits) {}
  ImpairedChannel channel;
  std::regex filter;
  std::unordered_map<std::string, bool> match_cache;  // channel names are few
  DirectionStats stats;
  QueueBound bound;  // its release queue: messages held, not yet released

  bool Matches(const std::string& name) {
    if (auto it = match_cache.find(name); it != match_cache.end()) return it->second;
    const bool match = std::regex_match(name, filter);
    if (match_cache.size() < 4096) match_cache.emplace(name, match);
    return match;
  }
};

}  // namespace

struct LcmRelay::Impl {
  // The lane a message was heard on: LCM's callback context.
  struct LaneTag {
    Impl* impl;
    int side;
    int lane;
  };

  explicit Impl(const RelayOptions& o)
      : options(o),
        directions{Direction(o.a2b, o.seed, o.queue), Direction(o.b2a, DerivedSeed(o.seed), o.queue)},
        echo{EchoFilter(o.echo_window), EchoFilter(o.echo_window)} {
    const std::string urls[2] = {o.url_a, o.url_b};
    for (int side : {kSideA, kSideB}) {
      // Every lane of a split URL (traffic_layout.h), or the one URL.
      for (const std::string& url : RelayLaneUrls(urls[side])) {
        auto& lane = lcm[side].emplace_back(std::make_unique<lcm::LCM>(url));
        if (!lane->good()) throw std::runtime_error("LcmRelay: cannot open LCM URL '" + url + "'");
      }
    }
    for (int side : {kSideA, kSideB}) {
      for (int lane = 0; lane < static_cast<int>(lcm[side].size()); ++lane) {
        tags.push_back(std::make_unique<LaneTag>(LaneTag{this, side, lane}));
        lcm[side][static_cast<std::size_t>(lane)]->subscribeFunction(".*", &Impl::OnLane, tags.back().get());
      }
    }
  }

  static void OnLane(const lcm::ReceiveBuffer* rbuf, const std::string& channel, LaneTag* tag) {
    tag->impl->OnMessage(tag->side, tag->lane, rbuf, channel);
  }

  // The lane of the target side: the same lane when both sides have the same
  // layout; else the lane the split side's rules give (or the one URL).
  int TargetLane(int source, int lane, const std::string& channel) const {
    const std::size_t target_lanes = lcm[1 - source].size();
    if (target_lanes == lcm[source].size()) return lane;
    return target_lanes == 1 ? 0 : LaneOfChannel(channel);
  }

  // Called from LCM's handle(): must not throw (see DESIGN/STYLE: store and rethrow).
  void OnMessage(int source, int lane, const lcm::ReceiveBuffer* rbuf, const std::string& channel) noexcept {
    // LCM's udpm provider publishes one LCM_SELF_TEST message per instance at
    // start-up; it belongs to that instance, so it is never relayed (and does
    // not draw random numbers, which keeps the schedule reproducible).
    if (channel == "LCM_SELF_TEST") return;
    try {
      const TimePoint now = clock.Now();
      const auto* bytes = static_cast<const unsigned char*>(rbuf->data);
      const std::uint64_t fp = Fingerprint(channel, bytes, rbuf->data_size);
      std::unique_lock lock(mu);
      Direction& d = directions[source];
      if (echo[source].ConsumeIfEcho(fp, now)) {
        ++d.stats.echoes;
        return;
      }
      ++d.stats.received;
      if (!d.Matches(channel)) {
        ++d.stats.filtered;
        return;
      }
      // The queue full: dropped before the link (a router's full buffer).
      if (!d.bound.TryAdmit(rbuf->data_size)) return;
      const Releases r = d.channel.Admit(now);
      if (r.count == 0) {
        d.bound.Release(rbuf->data_size);
        return;
      }
      auto message = std::make_shared<Message>(
          Message{channel, TargetLane(source, lane, channel),
                  std::vector<unsigned char>(bytes, bytes + rbuf->data_size), fp, now, r.count});
      for (int i = 0; i < r.count; ++i) queue.push(Release{r.at[i], next_order++, 1 - source, message});
      lock.unlock();
      wake.notify_one();
    } catch (const std::exception& e) {
      Fail(std::string("LcmRelay receive: ") + e.what());
    }
  }

  void Fail(const std::string& what) {
    std::lock_guard lock(mu);
    if (error.empty()) error = what;
    stop.store(true);
    wake.notify_all();
  }

  void ReceiveLoop() {
    std::vector<pollfd> fds;
    std::vector<lcm::LCM*> owners;
    for (int side : {kSideA, kSideB}) {
      for (auto& lane : lcm[side]) {
        fds.push_back({lane->getFileno(), POLLIN, 0});
        owners.push_back(lane.get());
      }
    }
    while (!stop.load()) {
      if (::poll(fds.data(), fds.size(), 50) <= 0) continue;
      for (std::size_t i = 0; i < fds.size(); ++i) {
        if (fds[i].revents & POLLIN) owners[i]->handleTimeout(0);
      }
    }
  }

  void ReleaseLoop() {
    std::vector<Release> due;
    std::unique_lock lock(mu);
    while (!stop.load()) {
      if (queue.empty()) {
        wake.wait_for(lock, std::chrono::milliseconds(100));
        continue;
      }
      const TimePoint deadline = queue.top().at;
      if (clock.Now() < deadline) {
        // Absolute deadline: a late wake-up does not shift later releases.
        wake.wait_until(lock, deadline);
        continue;
      }
      const TimePoint now = clock.Now();
      while (!queue.empty() && queue.top().at <= now) {
        due.push_back(queue.top());
        queue.pop();
        Message& m = *due.back().message;
        if (--m.copies_queued == 0) directions[1 - due.back().target].bound.Release(m.data.size());
        // Expect the echo before publishing: it can come back at once.
        echo[due.back().target].Expect(due.back().message->fingerprint, now);
      }
      lock.unlock();
      std::vector<int> results;
      results.reserve(due.size());
      for (const Release& r : due) {
        const Message& m = *r.message;
        results.push_back(lcm[r.target][static_cast<std::size_t>(m.lane)]->publish(
            m.channel, m.data.data(), static_cast<unsigned>(m.data.size())));
      }
      lock.lock();
      for (std::size_t i = 0; i < due.size(); ++i) {
        DirectionStats& s = directions[1 - due[i].target].stats;
        if (results[i] != 0) {
          ++s.publish_errors;
          continue;
        }
        ++s.published;
        const Duration delay = now - due[i].message->arrival;
        s.total_delay += delay;
        s.max_delay = std::max(s.max_delay, delay);
      }
      due.clear();
    }
  }

  RelayOptions options;
  SteadyClock clock;
  std::vector<std::unique_ptr<lcm::LCM>> lcm[2];  // per side, its lanes
  std::vector<std::unique_ptr<LaneTag>> tags;
  std::atomic<bool> stop{false};
  mutable std::mutex mu;
  std::condition_variable wake;
  // Guarded by mu:
  Direction directions[2];  // [kSideA] = a2b, [kSideB] = b2a
  EchoFilter echo[2];       // per side: our publications there
  std::priority_queue<Release, std::vector<Release>, Later> queue;
  std::uint64_t next_order = 0;
  std::string error;
};

LcmRelay::LcmRelay(const RelayOptions& options) : impl_(std::make_unique<Impl>(options)) {}
LcmRelay::~LcmRelay() = default;

void LcmRelay::RequestStop() { impl_->stop.store(true); }

void LcmRelay::Run() {
  Impl& m = *impl_;
  std::thread receiver([&m] { m.ReceiveLoop(); });
  std::thread releaser([&m] { m.ReleaseLoop(); });
  const TimePoint end = m.clock.Now() + FromSeconds(m.options.duration_s);
  while (!m.stop.load()) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    if (m.options.duration_s > 0 && m.clock.Now() >= end) m.stop.store(true);
  }
  m.wake.notify_all();
  receiver.join();
  releaser.join();
  std::lock_guard lock(m.mu);
  while (!m.queue.empty()) {
    ++m.directions[1 - m.queue.top().target].stats.unreleased;
    m.queue.pop();
  }
  if (!m.error.empty()) throw std::runtime_error(m.error);
}

RelayStats LcmRelay::Stats() const {
  std::lock_guard lock(impl_->mu);
  RelayStats s{impl_->directions[kSideA].stats, impl_->directions[kSideB].stats};
  s.a2b.queue_dropped = impl_->directions[kSideA].bound.dropped();
  s.b2a.queue_dropped = impl_->directions[kSideB].bound.dropped();
  s.a2b.channel = impl_->directions[kSideA].channel.stats();
  s.b2a.channel = impl_->directions[kSideB].channel.stats();
  return s;
}

std::string FormatStats(const RelayStats& stats) {
  std::string out;
  auto line = [&out](const char* name, const DirectionStats& d) {
    const double mean_ms =
        d.published ? ToSeconds(d.total_delay) * 1e3 / static_cast<double>(d.published) : 0.0;
    char buf[512];
    std::snprintf(
        buf, sizeof buf,
        "%s: received=%llu filtered=%llu lost=%llu duplicated=%llu reordered=%llu published=%llu "
        "publish_errors=%llu unreleased=%llu echoes=%llu held=%llu queue_dropped=%llu mean_delay_ms=%.3f "
        "max_delay_ms=%.3f\n",
        name, static_cast<unsigned long long>(d.received), static_cast<unsigned long long>(d.filtered),
        static_cast<unsigned long long>(d.channel.lost),
        static_cast<unsigned long long>(d.channel.duplicated),
        static_cast<unsigned long long>(d.channel.reordered), static_cast<unsigned long long>(d.published),
        static_cast<unsigned long long>(d.publish_errors), static_cast<unsigned long long>(d.unreleased),
        static_cast<unsigned long long>(d.echoes), static_cast<unsigned long long>(d.channel.held),
        static_cast<unsigned long long>(d.queue_dropped), mean_ms, ToSeconds(d.max_delay) * 1e3);
    out += buf;
  };
  line("a2b", stats.a2b);
  line("b2a", stats.b2a);
  return out;
}

}  // namespace robotalk::relay
