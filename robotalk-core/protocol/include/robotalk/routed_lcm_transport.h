// RoutedLcmTransport: the Transport over the split traffic layout
// (traffic_layout.h) — one LcmTransport per lane, created on first use, and
// OpenLcmTransport(), the factory that picks it or a plain LcmTransport
// from a RoboTalk URL. Server, client and tools open LCM through it.
//
// Routing. Publish() sends on the lane of the channel (LaneOfChannel).
// Subscribe() listens on the one lane LaneOfSubscription() names; any other
// regex listens on the main lane only, or on every lane when the transport
// was opened with `all_lanes` (tools that must see everything: recorders,
// relays). A lane that is only published on creates no receive socket and
// no receive thread (LCM udpm creates them on the first subscribe, handle or
// fileno), so its traffic costs this process nothing.
//
// Thread safety and dispatch: as stated in transport.h. fileno() is an epoll
// descriptor over the receiving lanes; HandleFor() dispatches every lane's
// waiting messages on the calling thread.
#pragma once

#include "robotalk/lcm_transport.h"
#include "robotalk/traffic_layout.h"

#include <array>
#include <atomic>
#include <memory>
#include <mutex>
#include <string>

namespace robotalk {

struct OpenLcmOptions {
  /// Per lane: receive buffer and queue capacity (LcmTransportOptions; its
  /// url is ignored, the URL is OpenLcmTransport's argument).
  LcmTransportOptions lane;
  /// Subscribe a regex the lane rules cannot place on every lane instead of
  /// only the main lane (recording, relaying). Costs 66 receive sockets and
  /// threads once such a regex is subscribed.
  bool all_lanes = false;
};

class RoutedLcmTransport final : public Transport {
 public:
  /// `lcm_url`: the main lane's LCM URL (udpm://G:P?opts, traffic= removed;
  /// ParseTrafficUrl gives it). No socket is opened until the first
  /// Publish()/Subscribe(). Throws TransportError for a URL that cannot be
  /// split, or when the epoll descriptor cannot be created.
  RoutedLcmTransport(std::string lcm_url, OpenLcmOptions options = {});
  ~RoutedLcmTransport() override;

  /// Throws TransportError (LCM cannot start the lane, or the send fails).
  void Publish(const std::string& channel, std::span<const std::uint8_t> bytes) override;
  std::unique_ptr<Subscription> Subscribe(const std::string& channel_regex, Handler handler) override;
  int HandleFor(Duration timeout) override;
  int fileno() const override;
  /// The main URL, as given to the constructor.
  std::string url() const override;
  /// LCM's recv_utime of the message being dispatched, from its lane.
  WallTime ReceiveTime() const override;
  TrafficLayout traffic_layout() const override { return TrafficLayout::kSplit; }

  /// Whether lane `lane` has a receive socket (exposed for tests).
  bool Receives(int lane) const;

 private:
  LcmTransport& Lane(int lane);   // created on first use
  void StartReceiving(int lane);  // REQUIRES: Lane(lane) exists
  int DispatchLane(int lane);     // HandleFor(0) on one lane

  const std::string lcm_url_;
  const OpenLcmOptions options_;
  int epoll_fd_ = -1;
  std::mutex mu_;  // guards creating lanes and starting their reception
  std::array<std::unique_ptr<LcmTransport>, kLaneCount> owned_;  // GUARDED_BY(mu_)
  std::array<std::atomic<LcmTransport*>, kLaneCount> lanes_{};   // published after creation
  std::array<std::atomic<bool>, kLaneCount> receiving_{};        // a socket in epoll_fd_
  LcmTransport* dispatching_ = nullptr;  // the lane HandleFor() is dispatching (its thread only)
};

/// Opens LCM on RoboTalk URL `url` ("" = $LCM_DEFAULT_URL, else LCM's
/// default udpm://239.255.76.67:7667?ttl=0): a RoutedLcmTransport for the
/// split layout, an LcmTransport for the single one (traffic=single,
/// memq://, file://; for udpm its url() ends in traffic=single), with
/// `options.lane` either way. Throws TransportError naming the URL (bad
/// traffic= option, LCM cannot start).
std::unique_ptr<Transport> OpenLcmTransport(const std::string& url, const OpenLcmOptions& options = {});

/// `url` with LCM's default resolved ("" -> $LCM_DEFAULT_URL or
/// udpm://239.255.76.67:7667?ttl=0); any other URL unchanged.
std::string ResolveLcmUrl(const std::string& url);

/// The LCM URL of RoboTalk URL `url`'s main lane (default resolved, traffic=
/// removed): where ANNOUNCE, CONFIG and STATE travel in either layout, for
/// tools that open LCM themselves to watch them. Throws TransportError as
/// ParseTrafficUrl.
std::string MainLcmUrl(const std::string& url);

}  // namespace robotalk
