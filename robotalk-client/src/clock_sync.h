// ClockSync: estimates the offset between the client's clock and a server's
// clock from NTP-style samples (docs/protocol.md "Clocks"). Pure: no I/O, no
// clock of its own; callers pass the four times of each round trip. Like
// NTP's dispersion, the best sample's error bound grows with its age by a
// drift allowance, so a fresh sample replaces it once that is tighter: hosts
// whose clocks drift apart stay synchronised as long as samples keep coming
// (RobotClient asks every clock_refresh_interval).
//
// Thread safety: not thread-safe; RobotClient guards it with its mutex.
#pragma once

#include "robotalk/clock.h"

#include <optional>

namespace robotalk::client {

class ClockSync {
 public:
  /// How fast two hosts' clocks may drift apart (two crystals of ±50 ppm,
  /// no NTP): a sample's error bound grows by this much per second of age.
  static constexpr double kDriftAllowance = 100e-6;

  /// One round trip: t1 client send, t2 server receive, t3 server send,
  /// t4 client receive (t1, t4 on the client's clock; t2, t3 on the server's).
  /// A sample with a negative round trip (t4 < t1, t3 < t2, or a server
  /// interval t3 - t2 longer than the client's t4 - t1) is inconsistent and
  /// ignored, as is one whose arithmetic would overflow int64 nanoseconds
  /// (forged server times at the ends of the range) or whose offset would map
  /// t4 past the end of the range; returns whether it was used.
  bool AddSample(TimePoint t1, TimePoint t2, TimePoint t3, TimePoint t4);

  /// True once at least one sample was accepted.
  bool synced() const { return best_.has_value() || restarted_; }
  /// A new server instance: the next sample replaces the offset whatever its
  /// round trip (until then the old offset stands).
  void Restart() {
    restarted_ = synced();
    best_.reset();
    num_samples_ = 0;
  }
  /// server clock − client clock, from the sample whose error bound is
  /// smallest as of the latest sample: half its round trip plus
  /// kDriftAllowance times its age (zero before the first sample).
  Duration offset() const { return offset_; }
  /// That sample's round trip (network time, server processing excluded).
  std::optional<Duration> best_round_trip() const {
    return best_ ? std::optional<Duration>(best_->round_trip) : std::nullopt;
  }
  int num_samples() const { return num_samples_; }

  /// The server-clock time corresponding to a client-clock time, and back.
  TimePoint ServerTime(TimePoint client_time) const { return client_time + offset_; }
  TimePoint ClientTime(TimePoint server_time) const { return server_time - offset_; }

 private:
  struct Sample {
    TimePoint received;  // t4, client clock
    Duration round_trip;
    Duration offset;
  };
  std::optional<Sample> best_;
  Duration offset_{0};  // kept through Restart() until the next sample
  int num_samples_ = 0;
  bool restarted_ = false;
};

}  // namespace robotalk::client
