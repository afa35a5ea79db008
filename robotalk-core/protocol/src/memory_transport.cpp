#include "robotalk/memory_transport.h"

#include "subscription_table.h"

#include <poll.h>
#include <sys/eventfd.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <climits>
#include <cstring>
#include <deque>

namespace robotalk {

namespace {

struct Message {
  std::string channel;
  std::shared_ptr<const std::vector<std::uint8_t>> bytes;  // shared by every endpoint
  WallTime published{};
};

}  // namespace

class MemoryEndpoint {
 public:
  explicit MemoryEndpoint(std::size_t capacity) : capacity_(capacity) {
    fd_ = ::eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC);
    if (fd_ < 0)
      throw TransportError(std::string("MemoryTransport: eventfd failed: ") + std::strerror(errno));
  }
  ~MemoryEndpoint() { ::close(fd_); }

  void Offer(const Message& m) {
    std::lock_guard lock(mu_);
    if (!subs_->Wants(m.channel)) return;
    if (queue_.size() >= capacity_) {
      ++dropped_;
      return;
    }
    queue_.push_back(m);
    if (queue_.size() == 1) Signal();
  }

  void Signal() {  // REQUIRES: mu_ held (keeps the eventfd in step with the queue)
    const std::uint64_t one = 1;
    [[maybe_unused]] auto n = ::write(fd_, &one, sizeof one);
  }
  void Drain() {  // REQUIRES: mu_ held
    std::uint64_t value = 0;
    [[maybe_unused]] auto n = ::read(fd_, &value, sizeof value);
  }

  std::mutex mu_;              // taken before subs_'s own lock, never inside it
  std::deque<Message> queue_;  // GUARDED_BY(mu_)
  std::size_t dropped_ = 0;    // GUARDED_BY(mu_)
  const std::shared_ptr<SubscriptionTable> subs_ = std::make_shared<SubscriptionTable>();
  const std::size_t capacity_;
  int fd_ = -1;
};

std::size_t MemoryBus::published() const {
  std::lock_guard lock(mu_);
  return published_;
}

void MemoryBus::Join(const std::shared_ptr<MemoryEndpoint>& endpoint) {
  std::lock_guard lock(mu_);
  endpoints_.push_back(endpoint);
}

void MemoryBus::Leave(const MemoryEndpoint* endpoint) {
  std::lock_guard lock(mu_);
  std::erase_if(endpoints_, [&](const auto& w) {
    auto e = w.lock();
    return !e || e.get() == endpoint;
  });
}

void MemoryBus::Deliver(const std::string& channel, std::span<const std::uint8_t> bytes) {
  Message m{channel, std::make_shared<const std::vector<std::uint8_t>>(bytes.begin(), bytes.end()),
            std::chrono::time_point_cast<std::chrono::microseconds>(std::chrono::system_clock::now())};
  std::vector<std::shared_ptr<MemoryEndpoint>> targets;
  {
    std::lock_guard lock(mu_);
    ++published_;
    for (const auto& w : endpoints_) {
      if (auto e = w.lock()) targets.push_back(std::move(e));
    }
  }
  // Endpoint locks are taken without the bus lock: a handler may publish.
  for (const auto& e : targets) e->Offer(m);
}

MemoryTransport::MemoryTransport(std::shared_ptr<MemoryBus> bus, MemoryTransportOptions options)
    : bus_(std::move(bus)), endpoint_(std::make_shared<MemoryEndpoint>(options.queue_capacity)) {
  if (!bus_) throw TransportError("MemoryTransport: no bus given");
  bus_->Join(endpoint_);
}

MemoryTransport::~MemoryTransport() { bus_->Leave(endpoint_.get()); }

void MemoryTransport::Publish(const std::string& channel, std::span<const std::uint8_t> bytes) {
  bus_->Deliver(channel, bytes);
}

std::unique_ptr<Subscription> MemoryTransport::Subscribe(const std::string& channel_regex, Handler handler) {
  return SubscriptionTable::Subscribe(endpoint_->subs_, "MemoryTransport", channel_regex, std::move(handler));
}

int MemoryTransport::HandleFor(Duration timeout) {
  MemoryEndpoint& ep = *endpoint_;
  std::size_t budget = 0;  // only what waits now: a handler publishing to itself cannot keep us here
  {
    std::lock_guard lock(ep.mu_);
    budget = ep.queue_.size();
  }
  if (budget == 0) {
    auto ms = std::chrono::ceil<std::chrono::milliseconds>(std::max(timeout, Duration(0))).count();
    pollfd p{ep.fd_, POLLIN, 0};
    if (::poll(&p, 1, static_cast<int>(std::min<long long>(ms, INT_MAX))) <= 0) return 0;
    std::lock_guard lock(ep.mu_);
    budget = ep.queue_.size();
  }
  int handled = 0;
  for (; budget > 0; --budget) {
    Message m;
    SubscriptionTable::Matches matching;
    {
      std::lock_guard lock(ep.mu_);
      if (ep.queue_.empty()) break;
      m = std::move(ep.queue_.front());
      ep.queue_.pop_front();
      if (ep.queue_.empty()) ep.Drain();
      matching = ep.subs_->Matching(m.channel);
    }
    ++handled;
    received_ = m.published;
    SubscriptionTable::Dispatch(matching, m.channel, *m.bytes);  // an exception leaves the rest queued
  }
  return handled;
}

int MemoryTransport::fileno() const { return endpoint_->fd_; }

std::size_t MemoryTransport::queued() const {
  std::lock_guard lock(endpoint_->mu_);
  return endpoint_->queue_.size();
}

std::size_t MemoryTransport::dropped() const {
  std::lock_guard lock(endpoint_->mu_);
  return endpoint_->dropped_;
}

}  // namespace robotalk
