// OutstandingPackages: the client's retransmission bookkeeping
// (docs/protocol.md "Reliability"). A package stays outstanding until the
// server has acknowledged it AND every query and command in it has its final
// reply. Pure: no I/O; callers pass the client-clock time.
//
// Policy:
//  - Unacknowledged: resend after the retransmission timeout (RTO), then
//    RTO·backoff, RTO·backoff², ... capped at min(`max_interval`,
//    `give_up_after`/4) (or the measured RTO when that is longer). The RTO
//    adapts to the measured round trips as in TCP (RFC 6298: smoothed RTT +
//    4 × its variation, Karn's rule), never below `interval`, and doubles
//    after each timeout until a fresh round-trip sample (§5.5), within the
//    same cap. At most kMaxResendsPerCall packages leave per TakeDue(); the
//    rest are paced kPacingStep apart, earliest deadline first.
//  - Acknowledged but items unanswered: ask again (resend the same sequence;
//    the server re-sends the replies it has) only once the earliest unanswered
//    item's start time has passed, starting again from `interval` and backing
//    off the same way. A running GOTO is thus re-asked about every
//    `max_interval`, and the server re-acks each time.
//  - Give up when the server has said nothing about a package (no ack, no reply
//    to one of its items) for `give_up_after` while it was due an answer
//    (measured from the later of the last word and the earliest unanswered start
//    time once acknowledged). Its unanswered items are returned by TakeExpired()
//    so their waiters fail with a timeout.
//
// Cost: the packages are indexed by their next resend time and by the time
// their give-up silence counts from, so TakeDue() and TakeExpired() touch only
// the packages that are due (O(k log n)), not every outstanding one (issue
// 11: a linear scan per tick was 20 % of a loaded client's CPU).
//
// Thread safety: not thread-safe; RobotClient guards it with its mutex.
#pragma once

#include "robotalk/clock.h"
#include "robotalk/command.h"

#include <cstdint>
#include <deque>
#include <optional>
#include <set>
#include <unordered_map>
#include <utility>
#include <vector>

namespace robotalk::client {

struct RetransmitPolicy {
  Duration interval = std::chrono::milliseconds(100);
  double backoff = 2.0;
  Duration max_interval = std::chrono::seconds(1);
  Duration give_up_after = std::chrono::seconds(5);
};

class OutstandingPackages {
 public:
  struct Item {
    CommandId id = 0;
    /// Client-clock time at which the item is due to run; nullopt = now.
    std::optional<TimePoint> start;
  };
  struct AckInfo {
    bool known = false;          ///< the sequence is outstanding
    bool first = false;          ///< first ack of it
    bool retransmitted = false;  ///< it was sent more than once
    TimePoint first_send{};      ///< when it was first sent
    bool completed = false;      ///< the package is now complete and forgotten
  };
  struct Resend {
    std::int64_t sequence = 0;
    std::vector<std::uint8_t> bytes;
  };
  struct Expired {
    std::int64_t sequence = 0;
    bool acked = false;
    std::vector<CommandId> unanswered;
  };

  explicit OutstandingPackages(RetransmitPolicy policy = {}) : policy_(policy) {}

  /// Registers a package just sent at `now` (its encoded bytes for resending).
  /// REQUIRES: `sequence` not already outstanding.
  void Add(std::int64_t sequence, std::vector<std::uint8_t> bytes, std::vector<Item> items, TimePoint now);
  /// When an acknowledgement arrived (the socket's stamp on this process's
  /// clock, before this process got round to it) and how long the server held
  /// the package before the ack left (reply_package_t's server_send_us −
  /// server_receive_us).
  struct AckTiming {
    TimePoint received{};
    Duration server_hold{0};
  };
  /// The server acknowledged `sequence`, handled at `now`; `timing` when known
  /// (else the ack arrived at `now` and the server held it for no time).
  AckInfo OnAck(std::int64_t sequence, TimePoint now, std::optional<AckTiming> timing = std::nullopt);
  /// A final reply for `id` arrived; returns the package it completed, if any.
  std::optional<std::int64_t> OnReply(CommandId id, TimePoint now);

  /// The start time of an unanswered item became known (a playback frame once
  /// the server chose its delay): re-asking waits for it.
  void UpdateStart(CommandId id, TimePoint start, TimePoint now);
  /// Packages to resend now; schedules their next resend.
  std::vector<Resend> TakeDue(TimePoint now);
  /// Packages given up at `now`, removed from the bookkeeping.
  std::vector<Expired> TakeExpired(TimePoint now);
  /// The earliest time TakeDue() or TakeExpired() has something to do
  /// (TimePoint::max() when nothing is outstanding).
  TimePoint NextDeadline() const;
  /// Removes every package (client closing); returns their unanswered items.
  std::vector<CommandId> Clear();

  bool Contains(std::int64_t sequence) const { return packages_.count(sequence) != 0; }
  bool IsAcked(std::int64_t sequence) const;
  std::size_t size() const { return packages_.size(); }
  /// The current retransmission timeout, timer back-off included (see above).
  Duration retransmit_timeout() const;
  /// The smoothed round trip (RFC 6298 SRTT; nullopt before the first sample).
  std::optional<Duration> smoothed_round_trip() const { return srtt_; }
  /// The round trip every package reports (the header's round_trip_us;
  /// nullopt before the first sample): the median of the network round trips
  /// of the packages acknowledged in the last kRoundTripWindow (at most
  /// kMaxRoundTrips; the mean of the middle two of an even count). A
  /// network round trip is the ack's arrival (AckTiming::received) − the
  /// package's send − the server's hold: neither side's processing counts,
  /// and the median ignores what the stamps miss (a spike in the server's
  /// receiving thread). Half of it is the mean one-way delay of a link whose
  /// jitter is symmetric (issue 23; docs/server.md, Link health). Not the
  /// RTO's samples: those run to when this process handled the ack.
  std::optional<Duration> reported_round_trip() const { return reported_rtt_; }
  static constexpr Duration kRoundTripWindow = std::chrono::seconds(10);
  static constexpr std::size_t kMaxRoundTrips = 2048;
  /// Total resends so far.
  std::uint64_t retransmissions() const { return retransmissions_; }

 private:
  struct Package {
    std::vector<std::uint8_t> bytes;
    std::unordered_map<CommandId, std::optional<TimePoint>> pending;  // id -> start
    bool acked = false;
    int sends = 1;
    int backoff_step = 0;
    TimePoint first_send{};
    TimePoint next_send{};  ///< key in by_next_send_
    TimePoint last_heard{};
    TimePoint silent_since{};  ///< key in by_silence_: give-up silence counts from here
  };
  using Key = std::pair<TimePoint, std::int64_t>;  // (time, sequence)
  // Moves the package's next resend to `t`, keeping the index in step.
  void Reschedule(std::int64_t sequence, Package& p, TimePoint t);
  // Recomputes when its silence counts from (after acked/last_heard/pending changed).
  void RefreshSilence(std::int64_t sequence, Package& p);
  static TimePoint SilentSince(const Package& p);
  void Erase(std::unordered_map<std::int64_t, Package>::iterator it);
  Duration IntervalAt(int step) const;
  Duration Ceiling() const;
  static constexpr std::size_t kMaxResendsPerCall = 32;
  static constexpr Duration kPacingStep = std::chrono::milliseconds(1);
  Duration BaseTimeout() const;
  void AddRoundTrip(Duration rtt);
  void AddNetworkRoundTrip(Duration rtt, TimePoint now);
  std::optional<Duration> srtt_;
  std::deque<std::pair<TimePoint, Duration>> network_rtts_;  // (acked at, round trip), oldest first
  std::vector<Duration> scratch_;
  std::optional<Duration> reported_rtt_;
  std::size_t since_median_ = 0;
  Duration rttvar_{0};
  static constexpr int kMaxTimerBackoff = 6;  // at most 64 × the RTO
  int timer_backoff_ = 0;
  /// Earliest start among unanswered items (now-items count as `fallback`).
  static TimePoint EarliestStart(const Package& p, TimePoint fallback);

  RetransmitPolicy policy_;
  std::unordered_map<std::int64_t, Package> packages_;
  std::unordered_map<CommandId, std::int64_t> owner_;  // unanswered item -> its package
  std::set<Key> by_next_send_;                         // every package, by next_send
  std::set<Key> by_silence_;                           // every package, by silent_since
  std::uint64_t retransmissions_ = 0;
};

}  // namespace robotalk::client
