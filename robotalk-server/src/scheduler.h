// The RobotDaemon's scheduler for one robot (paper §IV-A, §V-D), as a pure
// class: no threads, no clock of its own, no I/O.
//
// - One start-time queue per client (CommandQueue): earlier start first, equal
//   starts in arrival order; items without a start time run "now", before any
//   timed item. TakeDue(now) takes the due items of EVERY client in that
//   order, so a STOP scheduled at t=40 s runs after a GOTO at t=20 s even if
//   the STOP arrived first.
// - The server's own items (the watchdog's or shutdown's STOP) run before any
//   client item that is due.
// - The broadcast timer: one state stream at the shortest period any client
//   asked for, on an absolute grid t0 + k·period (it never drifts; samples
//   missed while late are skipped, not burst).
//
// Thread safety: none; the owner (RobotDaemon) locks.
#pragma once

#include "command_queue.h"
#include "robotalk/clock.h"

#include <cstdint>
#include <map>
#include <vector>

namespace robotalk {

class Scheduler {
 public:
  Scheduler();

  /// Queues a checked item of `item.client_id` (0 = the server itself);
  /// assigns its arrival number.
  void Push(QueuedItem item);
  /// Items of one client waiting, and of all clients.
  std::size_t queued(std::int64_t client_id) const;
  std::size_t size() const { return size_; }

  /// Appends every item due at `now` to `out`, in run order: the server's
  /// items first, then all clients' by start time, ties in arrival order.
  void TakeDue(TimePoint now, std::vector<QueuedItem>& out);
  /// Removes every waiting item (panic), appending them to `out`.
  void FlushAll(std::vector<QueuedItem>& out);
  /// Removes one client's waiting items, appending them to `out` in run order.
  void FlushClient(std::int64_t client_id, std::vector<QueuedItem>& out);

  /// Broadcast: `client_id` wants a state sample every `period` (0 cancels).
  /// Returns the stream period now (the shortest asked for; 0 = off). A new
  /// or faster stream samples at `now`; a slower one keeps its phase.
  Duration SetStream(std::int64_t client_id, Duration period, TimePoint now);
  Duration stream_period() const { return stream_period_; }
  /// True when a sample is due at `now`; then moves the timer to the next
  /// grid point after `now`.
  bool TakeSampleDue(TimePoint now);

  /// When the next item or sample is due; TimePoint::max() when idle.
  TimePoint NextDeadline() const;

 private:
  std::map<std::int64_t, CommandQueue> queues_;  // by client id; 0 = the server
  std::size_t size_ = 0;
  std::uint64_t arrivals_ = 0;
  std::map<std::int64_t, Duration> stream_requests_;
  Duration stream_period_{0};
  TimePoint next_sample_{};
};

}  // namespace robotalk
