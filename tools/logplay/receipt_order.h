// ReceiptOrder: puts the recorder's events back in the order they were
// received. `robotalk-logplay record` hears the split layout's 66 lanes; each
// lane's LCM receive thread stamps a message when it arrives (recv_utime),
// but the recorder's thread dispatches the lanes one after the other, so a
// reply can be dispatched before the request that caused it (issue 19: 6 of
// 19 in a direct-mode session). Events wait here for `hold` (longer than any
// dispatch delay) and are written sorted by their receive time; equal times
// keep their dispatch order.
//
// Pure (no clock, no I/O): times are given by the caller, in µs since the
// UNIX epoch. Bounded: past `max_held` events or `max_held_bytes` of their
// bytes the oldest are written at once, before their hold is over (never
// dropped), and counted (early(), early_bytes()).
// Thread safety: none.
#pragma once

#include <algorithm>
#include <climits>
#include <cstddef>
#include <cstdint>
#include <map>
#include <span>
#include <string>
#include <utility>
#include <vector>

namespace robotalk::logplay {

class ReceiptOrder {
 public:
  struct Event {
    std::int64_t received_us = 0;
    std::string channel;
    std::vector<std::uint8_t> bytes;
  };

  static constexpr std::size_t kMaxHeld = 100000;
  static constexpr std::size_t kMaxHeldBytes = std::size_t{64} << 20;

  explicit ReceiptOrder(std::int64_t hold_us = 250000, std::size_t max_held = kMaxHeld,
                        std::size_t max_held_bytes = kMaxHeldBytes)
      : hold_us_(hold_us), max_held_(max_held), max_held_bytes_(max_held_bytes) {}

  /// Holds a copy of one dispatched message.
  void Add(std::int64_t received_us, const std::string& channel, std::span<const std::uint8_t> bytes) {
    held_.emplace(Key{received_us, next_++}, Event{received_us, channel, {bytes.begin(), bytes.end()}});
    held_bytes_ += bytes.size();
  }

  /// Calls `write(const Event&)` in receipt order for every event received
  /// at or before `now_us - hold`, and for the oldest ones beyond
  /// `max_held`; first, after a wall-clock step back, every event stamped
  /// more than `hold` after `now_us`. An event received before one already written (it waited
  /// longer than `hold` to be dispatched) is written at once and counted in
  /// late().
  template <typename Write>
  void Release(std::int64_t now_us, Write&& write) {
    // The wall clock stepped back (NTP, a date set by hand): an event stamped
    // more than `hold` after `now_us` came before the step. Those are written
    // at once and first (held until the clock caught up, a kill meanwhile
    // lost them), and the order starts again: nothing after the step is late.
    if (!held_.empty() && held_.rbegin()->first.first > now_us + hold_us_) {
      auto stepped = held_.upper_bound(Key{now_us + hold_us_, UINT64_MAX});
      for (auto it = stepped; it != held_.end(); ++it) {
        write(it->second);
        held_bytes_ -= it->second.bytes.size();
      }
      held_.erase(stepped, held_.end());
      last_written_us_ = INT64_MIN;
    }
    while (!held_.empty()) {
      const bool due = held_.begin()->first.first <= now_us - hold_us_;
      if (!due && held_.size() <= max_held_ && held_bytes_ <= max_held_bytes_) break;
      if (!due) {
        ++early_;
        early_bytes_ += held_.begin()->second.bytes.size();
      }
      WriteFirst(write);
    }
  }
  /// Writes every held event (at the end of a recording).
  template <typename Write>
  void ReleaseAll(Write&& write) {
    while (!held_.empty()) WriteFirst(write);
  }

  std::size_t held() const { return held_.size(); }
  std::size_t held_bytes() const { return held_bytes_; }
  /// Events (and their bytes) written before their hold was over because
  /// more than `max_held` events or `max_held_bytes` bytes were held.
  std::uint64_t early() const { return early_; }
  std::uint64_t early_bytes() const { return early_bytes_; }
  /// Events written after a later-received one (dispatched more than `hold` late).
  std::uint64_t late() const { return late_; }

 private:
  using Key = std::pair<std::int64_t, std::uint64_t>;  // (receive time, dispatch order)

  template <typename Write>
  void WriteFirst(Write& write) {
    auto first = held_.begin();
    if (first->first.first < last_written_us_) ++late_;
    last_written_us_ = std::max(last_written_us_, first->first.first);
    write(first->second);
    held_bytes_ -= first->second.bytes.size();
    held_.erase(first);
  }

  const std::int64_t hold_us_;
  const std::size_t max_held_;
  const std::size_t max_held_bytes_;
  std::map<Key, Event> held_;
  std::size_t held_bytes_ = 0;  // of held_'s events
  std::uint64_t early_ = 0, early_bytes_ = 0;
  std::uint64_t next_ = 0;
  std::int64_t last_written_us_ = INT64_MIN;
  std::uint64_t late_ = 0;
};

}  // namespace robotalk::logplay
