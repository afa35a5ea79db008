// EchoFilter: recognises the relay's own publications when LCM hands them
// back. On udpm the relay's receive socket for a side is joined to the same
// group and port it publishes on, and multicast loopback must stay on (other
// processes on this host listen there too), so every message the relay
// publishes on side B is also delivered to the relay's side-B subscriber.
// Without this filter it would be forwarded back to A, and round again.
//
// Before publishing, the relay calls Expect(fingerprint); when a message
// arrives on that side, ConsumeIfEcho(fingerprint) says whether it is one of
// ours (and forgets one expectation). Expectations expire after `window`, and
// at most `capacity` are kept (the oldest go first), so a lost echo costs
// little: only a genuine message with identical channel and bytes, arriving
// within the window, would be taken for an echo.
//
// Pure: no I/O, no clock of its own. Thread safety: none (the relay locks).
#pragma once

#include <cstddef>
#include <cstdint>
#include <deque>
#include <string_view>
#include <unordered_map>
#include <utility>

#include <robotalk/clock.h>

namespace robotalk::relay {

/// 64-bit FNV-1a of channel, a NUL, and payload.
inline std::uint64_t Fingerprint(std::string_view channel, const void* data, std::size_t size) {
  std::uint64_t h = 14695981039346656037ull;
  auto mix = [&h](unsigned char c) {
    h ^= c;
    h *= 1099511628211ull;
  };
  for (char c : channel) mix(static_cast<unsigned char>(c));
  mix(0);
  const auto* bytes = static_cast<const unsigned char*>(data);
  for (std::size_t i = 0; i < size; ++i) mix(bytes[i]);
  return h;
}

class EchoFilter {
 public:
  explicit EchoFilter(Duration window, std::size_t capacity = 65536) : window_(window), capacity_(capacity) {}

  /// We are about to publish a message with this fingerprint at `now`.
  void Expect(std::uint64_t fingerprint, TimePoint now) {
    Expire(now);
    if (order_.size() >= capacity_) Forget(order_.front().second), order_.pop_front();
    order_.emplace_back(now, fingerprint);
    ++pending_[fingerprint];
  }

  /// True (and one expectation consumed) if a message with this fingerprint
  /// arriving at `now` is one of our own publications.
  bool ConsumeIfEcho(std::uint64_t fingerprint, TimePoint now) {
    Expire(now);
    auto it = pending_.find(fingerprint);
    if (it == pending_.end()) return false;
    if (--it->second == 0) pending_.erase(it);
    return true;
  }

  std::size_t pending() const { return order_.size(); }

 private:
  void Expire(TimePoint now) {
    while (!order_.empty() && now - order_.front().first > window_) {
      Forget(order_.front().second);
      order_.pop_front();
    }
  }
  // An expectation already consumed leaves its entry in order_; forgetting it
  // then finds no count (or another copy's count), which only shortens that
  // copy's window. Harmless: echoes arrive within milliseconds.
  void Forget(std::uint64_t fingerprint) {
    auto it = pending_.find(fingerprint);
    if (it != pending_.end() && --it->second == 0) pending_.erase(it);
  }

  Duration window_;
  std::size_t capacity_;
  std::deque<std::pair<TimePoint, std::uint64_t>> order_;
  std::unordered_map<std::uint64_t, int> pending_;
};

}  // namespace robotalk::relay
