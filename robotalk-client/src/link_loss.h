// LinkLoss: the client's own count of messages its link lost, and the rule
// that decides a playback package's second copy from it
// (ClientOptions::playback_copies = kPlaybackCopiesAuto; docs/protocol.md
// "Playback", issue 23 item 3). Pure: no I/O; callers pass the client-clock time.
//
// How a loss is counted: the server acknowledges every copy of a package it
// receives (a first copy, a retransmission, a redundancy copy: each gets its
// own ack). So once every copy of a package has had time to be answered,
// fewer acks than copies sent means a message was lost, on the way out (a
// copy) or back (its ack). A spurious retransmission (the first copy was only
// slow, as at the relay's WAN 300 profile, whose round trip is 600 ms against
// a first retransmission timeout of 100 ms) gets two acks for its two copies:
// not a loss. A heartbeat (never resent) counts as a package sent once.
//
// When a package has had that time: `settle_after` after its last copy left
// (the caller passes twice the retransmission timeout, which is above the
// round trips measured), and never before the first round trip was measured.
//
// Thread safety: not thread-safe; RobotClient guards it with its mutex.
#pragma once

#include "robotalk/clock.h"

#include <cstddef>
#include <cstdint>
#include <optional>
#include <set>
#include <unordered_map>
#include <utility>

namespace robotalk::client {

class LinkLoss {
 public:
  /// How long a loss keeps the second copy on (the loss-free time after
  /// which a link is trusted again).
  static constexpr Duration kMemory = std::chrono::seconds(60);
  /// Packages awaiting their acks at most; beyond, the oldest are forgotten
  /// uncounted (a server that never answers, or a flood of packages, must
  /// not grow the bookkeeping, and is no evidence of loss).
  static constexpr std::size_t kMaxPending = 4096;

  /// `copies` copies of package `sequence` left at `now` (a first send with
  /// its redundancy copies, or a retransmission: 1).
  void OnSend(std::int64_t sequence, TimePoint now, int copies = 1);
  /// An acknowledgement of `sequence` arrived (one per copy the server got).
  void OnAck(std::int64_t sequence);
  /// Settles the packages whose last copy left `settle_after` or more before
  /// `now`: a package with fewer acks than copies counts its missing acks
  /// as lost messages.
  void Settle(TimePoint now, Duration settle_after);

  /// Messages lost so far (either direction), and packages settled.
  std::uint64_t lost() const { return lost_; }
  std::uint64_t settled() const { return settled_; }
  /// When the last loss was found (settled), if ever.
  std::optional<TimePoint> last_loss() const { return last_loss_; }
  /// Whether a loss was found within `kMemory` before `now`.
  bool LostRecently(TimePoint now) const { return last_loss_ && now - *last_loss_ < kMemory; }

  /// The rule (kPlaybackCopiesAuto): a playback package leaves twice when the
  /// link has lost a message within kMemory AND its retransmission would come
  /// too late: the retransmission timeout `rto` exceeds the package's
  /// `headroom`, how long after its first copy's arrival its earliest frame is
  /// due (nullopt: not known yet, before the server's delay reply: 0).
  bool WantsSecondCopy(TimePoint now, Duration rto, std::optional<Duration> headroom) const {
    return LostRecently(now) && rto > headroom.value_or(Duration(0));
  }

 private:
  struct Entry {
    int sent = 0;
    int acked = 0;
    TimePoint last_send{};
  };
  std::unordered_map<std::int64_t, Entry> entries_;
  std::set<std::pair<TimePoint, std::int64_t>> by_last_send_;
  std::uint64_t lost_ = 0;
  std::uint64_t settled_ = 0;
  std::optional<TimePoint> last_loss_;
};

}  // namespace robotalk::client
