// MemoryTransport: an in-process bus for tests and simulations, no sockets.
//
//   auto bus = std::make_shared<robotalk::MemoryBus>();
//   robotalk::MemoryTransport server(bus), client(bus);
//
// A Publish() on any endpoint copies the bytes once and queues them to every
// endpoint of the bus (the publisher included, like LCM's multicast loopback)
// that has a subscription matching the channel at that moment. Each endpoint
// dispatches its queue in HandleFor() on the caller's thread; fileno() is an
// eventfd readable while the queue is not empty.
//
// Thread safety: as stated in transport.h; Publish() and the bus may be used
// from any thread.
#pragma once

#include "robotalk/transport.h"

#include <cstddef>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

namespace robotalk {

class MemoryEndpoint;  // private: one MemoryTransport's queue and subscriptions

/// The shared medium. Endpoints join it on construction and leave on
/// destruction. Thread-safe.
class MemoryBus {
 public:
  MemoryBus() = default;
  MemoryBus(const MemoryBus&) = delete;
  MemoryBus& operator=(const MemoryBus&) = delete;

  /// Messages published on this bus so far (every endpoint).
  std::size_t published() const;

 private:
  friend class MemoryTransport;
  void Join(const std::shared_ptr<MemoryEndpoint>& endpoint);
  void Leave(const MemoryEndpoint* endpoint);
  void Deliver(const std::string& channel, std::span<const std::uint8_t> bytes);

  mutable std::mutex mu_;
  std::vector<std::weak_ptr<MemoryEndpoint>> endpoints_;  // GUARDED_BY(mu_)
  std::size_t published_ = 0;                             // GUARDED_BY(mu_)
};

struct MemoryTransportOptions {
  /// Messages this endpoint queues before it drops new ones (as LCM does).
  std::size_t queue_capacity = 10000;
};

class MemoryTransport final : public Transport {
 public:
  /// Joins `bus`. Throws TransportError when no eventfd can be created.
  explicit MemoryTransport(std::shared_ptr<MemoryBus> bus, MemoryTransportOptions options = {});
  ~MemoryTransport() override;

  void Publish(const std::string& channel, std::span<const std::uint8_t> bytes) override;
  std::unique_ptr<Subscription> Subscribe(const std::string& channel_regex, Handler handler) override;
  int HandleFor(Duration timeout) override;
  int fileno() const override;
  std::string url() const override { return "memory://"; }
  /// When the message being dispatched was published.
  WallTime ReceiveTime() const override { return received_; }

  /// Messages waiting in this endpoint's queue.
  std::size_t queued() const;
  /// Messages this endpoint dropped because its queue was full.
  std::size_t dropped() const;

 private:
  std::shared_ptr<MemoryBus> bus_;
  std::shared_ptr<MemoryEndpoint> endpoint_;
  WallTime received_{};  // the dispatched message's (HandleFor() thread)
};

}  // namespace robotalk
