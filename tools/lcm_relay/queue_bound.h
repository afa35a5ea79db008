// QueueBound: the bound of one direction's release queue (messages admitted
// and not yet released, whatever their impairment holds them for: latency,
// the congested link, an outage). A message that would take the queue past
// either limit is dropped on arrival and counted, as a router's full buffer
// drops it (tail drop): it never reaches the link, draws no random numbers,
// and the queue, and so the relay's memory, stays bounded whatever the
// congestion model's arrival rate and service time (before: unbounded).
//
// Thread safety: none; the relay uses it under its mutex.
#pragma once

#include <cstddef>
#include <cstdint>

namespace robotalk::relay {

/// The defaults of --max-queue and --max-queue-bytes (per direction).
inline constexpr std::size_t kDefaultMaxQueueMessages = 65536;
inline constexpr std::size_t kDefaultMaxQueueBytes = std::size_t{64} << 20;  // 64 MiB

struct QueueLimits {
  std::size_t max_messages = kDefaultMaxQueueMessages;  ///< >= 1
  std::size_t max_bytes = kDefaultMaxQueueBytes;        ///< >= 1
};

class QueueBound {
 public:
  explicit QueueBound(QueueLimits limits) : limits_(limits) {}
  /// Whether a message of `bytes` fits (then it is queued until Release);
  /// false when it would pass either limit: dropped, counted.
  bool TryAdmit(std::size_t bytes) {
    if (messages_ + 1 > limits_.max_messages || bytes > limits_.max_bytes - bytes_) {
      ++dropped_;
      return false;
    }
    ++messages_;
    bytes_ += bytes;
    return true;
  }
  /// A message admitted leaves the queue (released, or lost in the channel).
  void Release(std::size_t bytes) {
    --messages_;
    bytes_ -= bytes;
  }
  std::size_t messages() const { return messages_; }
  std::size_t bytes() const { return bytes_; }
  /// Messages dropped because the queue was full.
  std::uint64_t dropped() const { return dropped_; }

 private:
  QueueLimits limits_;
  std::size_t messages_ = 0;
  std::size_t bytes_ = 0;
  std::uint64_t dropped_ = 0;
};

}  // namespace robotalk::relay
