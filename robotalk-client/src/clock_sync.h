// ClockSync: estimates the offset between the client's clock and a server's
// clock from NTP-style samples (docs/protocol.md "Clocks"). Pure: no I/O, no
// clock of its own; callers pass the four times of each round trip.
//
// Thread safety: not thread-safe; RobotClient guards it with its mutex.
#pragma once

#include "robotalk/clock.h"

#include <optional>

namespace robotalk::client {

class ClockSync {
 public:
  /// One round trip: t1 client send, t2 server receive, t3 server send,
  /// t4 client receive (t1, t4 on the client's clock; t2, t3 on the server's).
  /// A sample with a negative round trip (t4 < t1, t3 < t2, or a server
  /// interval t3 - t2 longer than the client's t4 - t1) is inconsistent and
  /// ignored, as is one whose arithmetic would overflow int64 nanoseconds
  /// (forged server times at the ends of the range) or whose offset would map
  /// t4 past the end of the range; returns whether it was used.
  bool AddSample(TimePoint t1, TimePoint t2, TimePoint t3, TimePoint t4);

  /// True once at least one sample was accepted.
  bool synced() const { return best_round_trip_.has_value() || restarted_; }
  /// A new server instance: the next sample replaces the offset whatever its
  /// round trip (until then the old offset stands).
  void Restart() {
    restarted_ = synced();
    best_round_trip_.reset();
    num_samples_ = 0;
  }
  /// server clock − client clock, from the sample with the smallest round trip
  /// (zero before the first sample).
  Duration offset() const { return offset_; }
  /// The smallest round trip seen (network time, server processing excluded).
  std::optional<Duration> best_round_trip() const { return best_round_trip_; }
  int num_samples() const { return num_samples_; }

  /// The server-clock time corresponding to a client-clock time, and back.
  TimePoint ServerTime(TimePoint client_time) const { return client_time + offset_; }
  TimePoint ClientTime(TimePoint server_time) const { return server_time - offset_; }

 private:
  Duration offset_{0};
  std::optional<Duration> best_round_trip_;
  int num_samples_ = 0;
  bool restarted_ = false;
};

}  // namespace robotalk::client
