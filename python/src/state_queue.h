// StateQueue: how a Python state-stream callback never stalls the C++
// client's ReadDaemon (docs/python.md, "The state stream").
//
// RobotClient::StartStateStream calls its callback on the ReadDaemon thread,
// which also files every reply, acknowledges and retransmits. Calling Python
// there would make the daemon wait for the GIL, and for however long the
// Python callback runs. Instead the daemon's callback only Push()es a copy of
// the sample into this bounded queue (a mutex held for a deque push, never
// the GIL); a Python thread (robotalk._stream.StateStream) Pop()s with the
// GIL released and calls the user's callback. When the consumer falls
// behind, the OLDEST sample is dropped and counted (dropped()): a slow
// callback sees the newest state, with gaps in StateSample.sample.
//
// Thread safety: every method may be called from any thread.
#pragma once

#include "robotalk/clock.h"
#include "robotalk/state_sample.h"

#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <mutex>
#include <optional>

namespace robotalk::python {

class StateQueue {
 public:
  /// REQUIRES: capacity >= 1.
  explicit StateQueue(std::size_t capacity) : capacity_(capacity) {}

  /// Called on the ReadDaemon thread: never blocks beyond the queue's mutex.
  void Push(const StateSample& sample);
  /// The oldest sample, waiting at most `most`; nullopt when none came or
  /// the queue is closed and empty.
  std::optional<StateSample> Pop(Duration most);
  /// No more samples will come: Pop() returns what is left, then nullopt at once.
  void Close();

  bool closed() const;
  std::size_t capacity() const { return capacity_; }
  std::size_t size() const;
  /// Samples dropped because the queue was full.
  std::uint64_t dropped() const;
  /// Samples pushed (received from the stream).
  std::uint64_t received() const;

 private:
  const std::size_t capacity_;
  mutable std::mutex mu_;
  std::condition_variable cv_;
  std::deque<StateSample> samples_;  // GUARDED_BY(mu_)
  bool closed_ = false;              // GUARDED_BY(mu_)
  std::uint64_t dropped_ = 0;        // GUARDED_BY(mu_)
  std::uint64_t received_ = 0;       // GUARDED_BY(mu_)
};

}  // namespace robotalk::python
