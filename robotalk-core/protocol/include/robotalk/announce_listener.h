// AnnounceListener: hears ROBOTALK/ANNOUNCE all the time, on a thread of its
// own, for the programs that follow every robot announced (robotalk-web's
// RobotTracker, robotalk-ros2's bridge of every robot). Each datagram is
// taken as HearAnnouncement takes it (heard_announcement.h): with a trusted
// server key only what that key signed; forged, foreign and malformed ones
// are dropped and counted.
//
// Thread safety: `on_heard` runs on the listener's thread, one call at a
// time; it may take the caller's locks and must not throw. The destructor stops that thread
// and waits for it: do not destroy the listener while holding a lock
// `on_heard` takes.
#pragma once

#include "robotalk/heard_announcement.h"
#include "robotalk/keys.h"
#include "robotalk/routed_lcm_transport.h"
#include "robotalk/transport.h"

#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <thread>

namespace robotalk {

/// The LCM options for an AnnounceListener's transport: at most 100
/// announcements queued (servers announce once a second; a flood beyond that
/// is dropped by LCM, not held).
inline const OpenLcmOptions kAnnounceQueue{.lane = {.queue_capacity = 100}};

class AnnounceListener {
 public:
  using OnHeard = std::function<void(const HeardAnnouncement&)>;

  /// Subscribes to ANNOUNCE on `transport` (owned; nobody else may call its
  /// HandleFor) and starts listening.
  AnnounceListener(std::unique_ptr<Transport> transport, std::optional<PublicKey> only, OnHeard on_heard);
  ~AnnounceListener();
  AnnounceListener(const AnnounceListener&) = delete;
  AnnounceListener& operator=(const AnnounceListener&) = delete;

  /// Datagrams not taken: forged, of another key than `only`, or malformed.
  std::uint64_t dropped() const { return dropped_; }

 private:
  void Listen();

  const std::unique_ptr<Transport> transport_;
  const std::optional<PublicKey> only_;
  const OnHeard on_heard_;
  std::unique_ptr<Subscription> subscription_;  // destroyed on the listening thread
  std::atomic<std::uint64_t> dropped_{0};
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

}  // namespace robotalk
