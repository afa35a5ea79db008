#include "robotalk/connect_scheduler.h"

#include <algorithm>
#include <exception>
#include <system_error>
#include <tuple>

namespace robotalk {
namespace {

// `first` doubled `times` times, at most `cap` (no overflow however many).
Duration Doubled(Duration first, int times, Duration cap) {
  Duration d = first;
  for (int i = 0; i < times && d < cap; ++i) d *= 2;
  return std::min(d, cap);
}

}  // namespace

ConnectScheduler::ConnectScheduler(ConnectFn connect, FailedFn failed, ConnectSchedulerOptions options)
    : connect_(std::move(connect)),
      failed_(std::move(failed)),
      options_(options),
      clock_(options_.clock ? *options_.clock : static_cast<const Clock&>(steady_clock_)) {}

ConnectScheduler::~ConnectScheduler() {
  {
    std::lock_guard lock(mu_);
    stopping_ = true;
  }
  // No Poll() runs now, so the list does not change; each thread touches
  // only its own `finished`, under mu_.
  for (Worker& w : workers_)
    if (w.thread.joinable()) w.thread.join();
}

bool ConnectScheduler::Silent(const Name& n, TimePoint now) const {
  return now - n.heard > options_.silent_after;
}
Duration ConnectScheduler::Timeout(int failures) const {
  return Doubled(options_.first_timeout, failures, options_.max_timeout);
}
Duration ConnectScheduler::Backoff(int failures) const {
  return Doubled(options_.first_backoff, failures, options_.max_backoff);
}

ConnectScheduler::Heard ConnectScheduler::Announce(const std::string& name, std::string* evicted) {
  if (evicted) evicted->clear();
  std::lock_guard lock(mu_);
  const TimePoint now = clock_.Now();
  if (auto it = names_.find(name); it != names_.end()) {
    it->second.heard = now;
    return Heard::kKnown;
  }
  if (names_.size() >= options_.max_names && !Evict(now, evicted)) return Heard::kRefused;
  names_.emplace(name, Name{.heard = now, .due = now, .order = next_order_++});
  return Heard::kAdded;
}

// The table is full and a new name is announced: one neither served nor
// connecting, whose connects failed or that fell silent, gives its place (a
// silent one first, then the one that failed most, then the one announced
// longest ago). A name heard and not tried yet keeps it.
bool ConnectScheduler::Evict(TimePoint now, std::string* evicted) {
  auto worst = names_.end();
  const auto rank = [&](const Name& n) { return std::make_tuple(Silent(n, now), n.failures, now - n.heard); };
  for (auto it = names_.begin(); it != names_.end(); ++it) {
    const Name& n = it->second;
    if (n.served || n.connecting || (n.failures == 0 && !Silent(n, now))) continue;
    if (worst == names_.end() || rank(n) > rank(worst->second)) worst = it;
  }
  if (worst == names_.end()) return false;
  if (evicted) *evicted = worst->first;
  names_.erase(worst);
  return true;
}

std::vector<std::string> ConnectScheduler::Poll() {
  std::vector<std::string> forgotten;
  std::vector<std::thread> ended;  // joined outside the lock
  {
    std::lock_guard lock(mu_);
    const TimePoint now = clock_.Now();
    for (auto it = workers_.begin(); it != workers_.end();) {
      if (!it->finished) {
        ++it;
        continue;
      }
      ended.push_back(std::move(it->thread));
      it = workers_.erase(it);
    }
    std::erase_if(names_, [&](const auto& entry) {
      const Name& n = entry.second;
      const bool forget =
          !n.served && !n.connecting && now - n.heard > options_.silent_after + options_.forget_after;
      if (forget) forgotten.push_back(entry.first);
      return forget;
    });
    StartDue(now);
  }
  for (std::thread& t : ended) t.join();
  return forgotten;
}

// The names due, not tried yet first (in the order they came), then the
// retries, each on a thread of its own while fewer than max_connecting are.
void ConnectScheduler::StartDue(TimePoint now) {
  if (stopping_) return;
  std::vector<std::map<std::string, Name>::iterator> due;
  for (auto it = names_.begin(); it != names_.end(); ++it) {
    const Name& n = it->second;
    if (!n.served && !n.connecting && !Silent(n, now) && n.due <= now) due.push_back(it);
  }
  std::sort(due.begin(), due.end(), [](const auto& a, const auto& b) {
    return std::make_tuple(a->second.failures > 0, a->second.due, a->second.order) <
           std::make_tuple(b->second.failures > 0, b->second.due, b->second.order);
  });
  for (auto& it : due) {
    if (in_flight_ >= options_.max_connecting) break;
    const auto self = workers_.emplace(workers_.end());
    try {
      self->thread = std::thread(&ConnectScheduler::Run, this, self, it->first, Timeout(it->second.failures));
    } catch (const std::system_error&) {  // no thread now: tried again at the next Poll()
      workers_.erase(self);
      break;
    }
    it->second.connecting = true;
    ++in_flight_;
  }
}

void ConnectScheduler::Run(std::list<Worker>::iterator self, const std::string& name, Duration timeout) {
  std::string error;
  bool ok = false;
  try {
    connect_(name, timeout);
    ok = true;
  } catch (const std::exception& e) {
    error = e.what();
  } catch (...) {
    error = "unknown exception";
  }
  Duration retry_in{0};
  {
    std::lock_guard lock(mu_);
    --in_flight_;
    // Always found: a name connecting is never forgotten or pushed out.
    if (auto it = names_.find(name); it != names_.end()) {
      Name& n = it->second;
      const TimePoint now = clock_.Now();
      n.connecting = false;
      n.order = next_order_++;
      if (ok) {
        n.served = !n.lost;
        n.failures = 0;
        n.due = now;
      } else {
        retry_in = Backoff(n.failures);
        ++n.failures;
        n.due = now + retry_in;
      }
      n.lost = false;
    }
    StartDue(clock_.Now());  // its slot is free: the next name due need not wait for Poll()
  }
  if (!ok && failed_) {
    try {
      failed_(name, error, retry_in);
    } catch (...) {  // the caller's report failed: the scheduler goes on
    }
  }
  std::lock_guard lock(mu_);
  self->finished = true;
}

void ConnectScheduler::Lost(const std::string& name) {
  std::lock_guard lock(mu_);
  auto it = names_.find(name);
  if (it == names_.end()) return;
  Name& n = it->second;
  if (n.connecting) {
    n.lost = true;
    return;
  }
  n.served = false;
  n.failures = 0;
  n.due = clock_.Now();
  n.order = next_order_++;
}

std::optional<ConnectScheduler::State> ConnectScheduler::Find(const std::string& name) const {
  std::lock_guard lock(mu_);
  auto it = names_.find(name);
  if (it == names_.end()) return std::nullopt;
  const Name& n = it->second;
  return State{.served = n.served,
               .connecting = n.connecting,
               .silent = Silent(n, clock_.Now()),
               .failures = n.failures};
}

ConnectScheduler::Counts ConnectScheduler::counts() const {
  std::lock_guard lock(mu_);
  return {.names = names_.size(), .connecting = in_flight_};
}

}  // namespace robotalk
