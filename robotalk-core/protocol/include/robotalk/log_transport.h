// LogTransport: a read-only Transport over an LCM log file (as written by
// lcm-logger), read through LcmLogReader (lcm_log.h: a damaged event is
// skipped, never allocated as declared). Each HandleFor() dispatches
// the log's events in file order to the matching subscriptions, either as
// fast as possible or paced by their timestamps on a robotalk::Clock, so a
// recorded session can be replayed into the same code that served it live.
//
// Thread safety: as stated in transport.h. Publish() always throws.
#pragma once

#include "robotalk/transport.h"

#include <cstddef>
#include <memory>
#include <string>

namespace robotalk {

namespace internal {
class LogCore;  // log_transport.cpp: the open log and the subscriptions
}

struct LogTransportOptions {
  /// The LCM log file to read.
  std::string path;
  /// false: every event is due at once (HandleFor dispatches up to
  /// `max_per_call` per call); true: an event is due when the clock has moved
  /// past the log's first timestamp by its own timestamp's offset / `speed`.
  bool paced = false;
  /// Pacing clock; nullptr = the steady clock. Must outlive the transport.
  const Clock* clock = nullptr;
  /// Replay speed when paced: 2 = twice as fast as recorded. > 0.
  double speed = 1.0;
  /// Most events one HandleFor() dispatches (bounds the time one call takes).
  std::size_t max_per_call = 1000;
};

class LogTransport final : public Transport {
 public:
  /// Opens the log. Throws TransportError naming the file when it cannot be
  /// read, or for a speed that is not positive.
  explicit LogTransport(LogTransportOptions options);
  ~LogTransport() override;

  /// Always throws TransportError ("log transport is read-only").
  void Publish(const std::string& channel, std::span<const std::uint8_t> bytes) override;
  std::unique_ptr<Subscription> Subscribe(const std::string& channel_regex, Handler handler) override;
  /// Dispatches the due events (events no subscription matches are skipped
  /// and not counted). When none is due, waits for the next at most `timeout`
  /// in real time (re-reading the clock). Returns how many were dispatched;
  /// 0 once the log has ended. The pacing starts at the first call.
  int HandleFor(Duration timeout) override;
  /// -1: there is no descriptor to poll; call HandleFor().
  int fileno() const override { return -1; }
  std::string url() const override;
  /// The logged timestamp of the event being dispatched.
  WallTime ReceiveTime() const override;

  /// True once every event has been read.
  bool done() const;
  /// Events read so far (dispatched or skipped).
  std::size_t events_read() const;

 private:
  // Shared with the subscriptions (weakly), which may outlive the transport.
  std::shared_ptr<internal::LogCore> impl_;
};

}  // namespace robotalk
