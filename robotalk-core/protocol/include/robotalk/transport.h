// The transport seam: how RoboTalk's server, client and tools move bytes on
// named channels, in the style of Drake's DrakeLcmInterface. Implementations:
//   LcmTransport     (lcm_transport.h)    real LCM (udpm://, memq://, file://)
//   MemoryTransport  (memory_transport.h) an in-process bus for tests
//   LogTransport     (log_transport.h)    replays an LCM log file
// Typed helpers Publish<Msg>() / Subscribe<Msg>() encode and decode lcm-gen
// messages over the raw byte interface.
//
// Dispatch model (as LCM's): handlers run only inside HandleFor(), on the
// thread that calls it, one at a time, in arrival order. A handler that
// throws stops that HandleFor() call; the exception is rethrown from it
// (for LCM after LCM's C stack has unwound, never through it).
//
// Thread safety: Publish() may be called from any thread at any time.
// Subscribe(), destroying a Subscription and HandleFor() may be called from
// any thread, including from inside a handler; but destroying a Subscription
// on one thread while another thread is inside HandleFor() may race with a
// call of that handler already under way, so destroy subscriptions on the
// dispatching thread, or after it has stopped calling HandleFor().
// Only one thread at a time may call HandleFor() on one transport.
#pragma once

#include "robotalk/clock.h"
#include "robotalk/error.h"

#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <vector>

namespace robotalk {

/// A channel subscription. RAII: destroying it unsubscribes; its handler is
/// not called by any HandleFor() that starts after the destructor returned.
/// It may outlive its transport (its destructor then does nothing).
class Subscription {
 public:
  virtual ~Subscription();

 protected:
  Subscription() = default;
  Subscription(const Subscription&) = delete;
  Subscription& operator=(const Subscription&) = delete;
};

/// How a transport lays RoboTalk's channels on LCM URLs (traffic_layout.h):
/// every channel on one URL, or the split layout's lanes. On the wire as
/// announce_t.traffic_layout (TRAFFIC_SINGLE = 0, TRAFFIC_SPLIT = 1).
enum class TrafficLayout : std::int8_t { kSingle = 0, kSplit = 1 };

/// Wall-clock time (the UNIX epoch, microseconds): when a message was
/// received, as LCM stamps it (lcm_recv_buf_t::recv_utime).
using WallTime = std::chrono::time_point<std::chrono::system_clock, std::chrono::microseconds>;

class Transport {
 public:
  /// Called with the channel the message arrived on and its bytes; the bytes
  /// are valid only during the call.
  using Handler = std::function<void(const std::string& channel, std::span<const std::uint8_t> bytes)>;

  virtual ~Transport();

  /// Sends `bytes` on `channel` to every subscriber, this transport's own
  /// included (LCM's multicast loopback). Throws TransportError.
  virtual void Publish(const std::string& channel, std::span<const std::uint8_t> bytes) = 0;

  /// Calls `handler` for each message whose channel matches `channel_regex`
  /// as a whole (LCM semantics: POSIX extended regex, anchored at both ends;
  /// a plain name matches only itself). Throws TransportError (bad regex).
  virtual std::unique_ptr<Subscription> Subscribe(const std::string& channel_regex, Handler handler) = 0;

  /// Dispatches the messages waiting, on the calling thread; when none waits,
  /// waits at most `timeout` for the first. Returns how many messages were
  /// dispatched (0 on timeout). Rethrows a handler's exception; throws
  /// TransportError when the transport fails.
  virtual int HandleFor(Duration timeout) = 0;

  /// A file descriptor that polls readable while messages wait (for poll()
  /// loops that also wait on other descriptors), or -1 when there is none.
  virtual int fileno() const = 0;

  /// Where this transport talks ("udpm://239.255.76.67:7667?ttl=0",
  /// "memory://", "log:///path/file.lcmlog").
  virtual std::string url() const = 0;

  /// When the message whose handler is running was received: LCM's receive
  /// stamp (the kernel's, where the socket gives one), the publish time on a
  /// MemoryTransport, the logged time on a LogTransport. Dispatch comes
  /// later, and across the lanes of the split layout not in receipt order
  /// (issue 19: a recorder stamping at dispatch wrote replies before their
  /// requests). Call it only from inside a handler, on the dispatching
  /// thread; this default (for transports that cannot know) is the time of
  /// the call.
  virtual WallTime ReceiveTime() const;

  /// The layout this transport's traffic travels in (what a server announces,
  /// so that its clients open the same): kSplit for RoutedLcmTransport, this
  /// default kSingle for every other.
  virtual TrafficLayout traffic_layout() const { return TrafficLayout::kSingle; }

 protected:
  Transport() = default;
  Transport(const Transport&) = delete;
  Transport& operator=(const Transport&) = delete;
};

/// `msg` (an lcm-gen type) as LCM bytes, fingerprint first: the one encoder
/// of the project (the codecs and Publish<Msg> use it). Throws ProtocolError
/// naming the type when LCM's encoder fails (a count field that disagrees
/// with its array).
template <typename Msg>
std::vector<std::uint8_t> EncodeMessage(const Msg& msg) {
  const int size = msg.getEncodedSize();
  std::vector<std::uint8_t> bytes(static_cast<std::size_t>(size));
  if (msg.encode(bytes.data(), 0, size) != size) {
    throw ProtocolError(std::string("encoding ") + Msg::getTypeName() +
                        " failed (do its counts match its arrays?)");
  }
  return bytes;
}

/// Encodes `msg` (an lcm-gen type, EncodeMessage) and publishes it. Throws
/// ProtocolError when it cannot be encoded, TransportError when the send fails.
template <typename Msg>
void Publish(Transport& transport, const std::string& channel, const Msg& msg) {
  transport.Publish(channel, EncodeMessage(msg));
}

/// Subscribes `channel_regex` and calls `handler` with each message decoded
/// as `Msg` (an lcm-gen type). A message that does not decode as `Msg` (wrong
/// fingerprint, truncated) raises a ProtocolError naming the channel and the
/// type, carried out of HandleFor() like a handler's exception. LCM's decoder
/// trusts array counts; for bytes from untrusted senders use the raw
/// Subscribe() with the bounds-checked decoders of request.h.
template <typename Msg>
std::unique_ptr<Subscription> Subscribe(
    Transport& transport, const std::string& channel_regex,
    std::function<void(const std::string& channel, const Msg& msg)> handler) {
  return transport.Subscribe(channel_regex, [handler = std::move(handler)](const std::string& channel,
                                                                           std::span<const std::uint8_t> b) {
    Msg msg{};
    const int size = static_cast<int>(b.size());
    if (b.size() > static_cast<std::size_t>(INT32_MAX) || msg.decode(b.data(), 0, size) != size) {
      throw ProtocolError("Subscribe<" + std::string(Msg::getTypeName()) + ">: " + std::to_string(b.size()) +
                          " bytes on '" + channel + "' do not decode as " + Msg::getTypeName());
    }
    handler(channel, msg);
  });
}

}  // namespace robotalk
