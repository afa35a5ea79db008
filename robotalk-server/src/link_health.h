// How good one client session's link is, measured by the server from what it
// already sees (issue 23), so an operator sees a link degrade before motion
// suffers. Pure: times come from the caller; no I/O. Thread safety: none (the
// ServerDaemon thread, through RobotSessions).
//
// Inputs, per package of the session (OnPackage): its sequence number, whether
// the session's SequenceWindow saw it before, the client's send time (its own
// clock) and the client's round trip (header round_trip_us: the median of
// its recent network round trips, outstanding_packages.h); per final reply
// (OnReply): its lateness, and whether it expired (expiry.h).
//
// Figures (Figures()):
//   - round trip: the latest the client reported (the report of its
//     highest-numbered package; never a copy's or an overtaken package's,
//     whose report is older): the median of its network
//     round trips (an ack's arrival, as its socket stamped it, − the
//     package's send − the server's hold: neither side's processing counts);
//   - delay (one-way, client -> server): half that round trip. Without
//     synchronised clocks nothing tells the two ways of a round trip apart
//     (this server's transits, arrival − the client's send time, carry the
//     clocks' unknown offset), so this is the mean of the two directions'
//     mean delays when each direction's jitter is symmetric about its mean
//     (the median of a sum of two such is its mean); the client's median
//     makes it robust to processing spikes;
//   - jitter: RFC 3550's inter-arrival jitter of the transit (arrival − send
//     time: the clocks' offset cancels in its differences), J += (|D| − J)/16,
//     over the packages that arrive in order (a retransmission carries its
//     first send time: its transit is the resend wait, not the network's);
//   - loss: first copies that never came. A sequence number below the highest
//     that was not received is missing; when it arrives its transit tells a
//     reordered copy (at most `reorder_tolerance` slower than the 90th
//     percentile of the recent first copies) from a retransmission (slower: it carries
//     its first copy's send time, so its transit includes the client's resend
//     wait, at least its 100 ms minimum timeout; the first copy was lost). A number still missing after
//     `loss_horizon` is lost (a heartbeat is never retransmitted). Loss is
//     lost / expected (the sequence numbers from the first to the highest,
//     minus those still undecided), cumulative and over the recent window;
//   - duplicates: copies of a package already received (a retransmission
//     whose acknowledgement was lost, a duplicated datagram);
//   - late: final replies whose lateness exceeds `late_threshold`; expired:
//     commands not executed past their deadline (expiry.h).
// The recent window: the counts of the current and the previous `window`.
//
// Verdict(): kDegraded when a recent figure passes a warn threshold, kBad when
// one passes a stop threshold (RobotSessions warns, rate-limited, and with
// the opt-in policy stops what the session owns; docs/server.md).
//
// Memory: bounded (64 recent transits, at most kMaxMissing missing numbers).
#pragma once

#include "robotalk/clock.h"
#include "robotalk/state_sample.h"

#include <array>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <utility>

namespace robotalk {

struct LinkThresholds {
  double loss = 0.05;                               ///< recent loss rate
  Duration delay = std::chrono::milliseconds(125);  ///< one-way delay (LinkFigures::delay)
  Duration jitter = std::chrono::milliseconds(50);
  std::uint64_t expired = 1;  ///< expired commands in the recent window
};

struct LinkHealthOptions {
  Duration reorder_tolerance = std::chrono::milliseconds(50);
  Duration loss_horizon = std::chrono::seconds(3);
  Duration late_threshold = std::chrono::milliseconds(5);
  Duration window = std::chrono::seconds(5);
  LinkThresholds warn;
  LinkThresholds stop{.loss = 0.25,
                      .delay = std::chrono::milliseconds(500),
                      .jitter = std::chrono::milliseconds(250),
                      .expired = 10};
};

/// What the server knows of one session's link.
struct LinkFigures {
  std::optional<Duration> round_trip;  ///< as the client reported it; nullopt: not yet
  Duration jitter{0};
  std::uint64_t packages = 0;       ///< distinct packages received
  std::uint64_t expected = 0;       ///< sequence numbers whose fate is known
  std::uint64_t lost = 0;           ///< of `expected`: first copy never came
  std::uint64_t retransmitted = 0;  ///< lost first copies a retransmission recovered
  std::uint64_t duplicates = 0;
  std::uint64_t reordered = 0;
  std::uint64_t replies = 0;  ///< final replies of its commands and queries
  std::uint64_t late = 0;
  std::uint64_t expired = 0;
  double loss = 0;         ///< lost / expected, cumulative
  double recent_loss = 0;  ///< over the recent window
  std::uint64_t recent_expired = 0;
  /// One-way: half the round trip (see above); nullopt before a round trip is known.
  std::optional<Duration> delay() const {
    return round_trip ? std::optional<Duration>(*round_trip / 2) : std::nullopt;
  }
};

class LinkHealth {
 public:
  /// The state stream's levels (unknown, good, degraded, bad; ToString in state_sample.h).
  using Level = LinkState::Level;
  struct Verdict {
    Level level = Level::kUnknown;
    std::string why;  ///< the figures past their threshold, "" when good
  };
  static constexpr std::size_t kMaxMissing = 4096;

  explicit LinkHealth(LinkHealthOptions options = {}) : options_(options) {}

  /// One package. `duplicate`: the session saw its sequence before. `sent`:
  /// the client's clock when sent (TimePoint{} = unknown). `round_trip`: the
  /// client's report (0 = none). Returns whether it came as a retransmission
  /// (after a later-numbered package, and slower than the slowest recent
  /// first copies by more than reorder_tolerance, or decided lost before):
  /// its send time is its first copy's, so arrival − send time includes the
  /// client's resend wait, not only the network's delay.
  bool OnPackage(std::int64_t sequence, bool duplicate, TimePoint sent, TimePoint received,
                 Duration round_trip);
  /// One final reply to the client (late, expired).
  void OnReply(Duration lateness, bool expired, TimePoint now);
  /// Decides the fate of numbers missing past the horizon, rolls the window.
  void Tick(TimePoint now);

  LinkFigures Figures() const;
  Verdict Evaluate() const;
  const LinkHealthOptions& options() const { return options_; }

 private:
  struct Window {
    std::uint64_t expected = 0, lost = 0, expired = 0;
  };
  void Decide(bool lost);
  // The 90th percentile of the recent first copies' transits.
  // REQUIRES: transit_count_ > 0.
  Duration SlowTransit() const;

  LinkHealthOptions options_;
  LinkFigures f_;
  bool started_ = false;
  std::int64_t highest_ = 0, lowest_ = 0;
  std::map<std::int64_t, TimePoint> missing_;  // sequence -> when a higher one arrived
  std::array<Duration, 64> transits_{};
  std::size_t transit_next_ = 0, transit_count_ = 0;
  std::optional<Duration> last_transit_;
  double jitter_us_ = 0;
  Window current_, previous_;
  TimePoint window_start_{};
  bool window_started_ = false;
};

}  // namespace robotalk
