// LcmTransport: the Transport over real LCM (udpm://, memq://, ...). No LCM
// header is exposed here; the lcm::LCM instance lives behind a pimpl.
//
// Thread safety and dispatch: as stated in transport.h. Messages are received
// by LCM's own thread into a queue per subscription (capacity
// `LcmTransportOptions::queue_capacity`; LCM drops what does not fit) and
// dispatched by HandleFor() on the caller's thread.
#pragma once

#include "robotalk/transport.h"

#include <memory>
#include <string>

namespace robotalk {

namespace internal {
class LcmCore;  // lcm_transport.cpp: the lcm_t and what its callbacks share
}

struct LcmTransportOptions {
  /// The LCM URL. "" = LCM's default: $LCM_DEFAULT_URL, or
  /// udpm://239.255.76.67:7667?ttl=0.
  std::string url;
  /// Socket receive buffer (bytes) appended to a udpm:// URL as
  /// `recv_buf_size=` when the URL does not give one; 0 = leave LCM's default.
  /// The kernel caps it at net.core.rmem_max (208 KB by default): raise that
  /// (sysctl -w net.core.rmem_max=2097152) for bursts not to be dropped.
  int recv_buf_size = 2 * 1024 * 1024;
  /// Messages each subscription queues before LCM drops new ones. LCM's own
  /// default (30) drops bursts of state samples or replies; this is deep.
  int queue_capacity = 10000;
};

class LcmTransport final : public Transport {
 public:
  /// Starts LCM on `options.url`. Throws TransportError naming the URL when
  /// LCM cannot start (bad URL, no multicast route, ...).
  explicit LcmTransport(LcmTransportOptions options = {});
  ~LcmTransport() override;

  void Publish(const std::string& channel, std::span<const std::uint8_t> bytes) override;
  std::unique_ptr<Subscription> Subscribe(const std::string& channel_regex, Handler handler) override;
  int HandleFor(Duration timeout) override;
  int fileno() const override;
  /// The URL LCM was started with (recv_buf_size included), or "(LCM default)".
  std::string url() const override;
  /// LCM's recv_utime of the message being dispatched.
  WallTime ReceiveTime() const override;

  /// The URL LcmTransport would hand LCM for `options` (exposed for tests).
  static std::string EffectiveUrl(const LcmTransportOptions& options);

 private:
  // Shared with the subscriptions (weakly), which may outlive the transport.
  std::shared_ptr<internal::LcmCore> impl_;
};

}  // namespace robotalk
