// LcmRelay: joins two LCM URLs and forwards every message both ways through
// an ImpairedChannel per direction (A->B and B->A).
//
// Threads: one receive thread polls both LCM file descriptors and feeds the
// channels; one release thread sleeps until the earliest absolute release
// deadline and publishes what is due. The relay's own publications, which
// LCM hands back on the side they were published on, are recognised by an
// EchoFilter and not forwarded (no loops). Bytes are relayed untouched.
//
// Thread safety: Run() blocks and is called from one thread; RequestStop()
// may be called from any thread and from a signal handler (one atomic store).
// Not copyable or movable (owns threads and LCM handles).
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <string>

#include "relay_options.h"

namespace robotalk::relay {

struct DirectionStats {
  ChannelStats channel;         ///< the impaired channel's own counters
  std::uint64_t received = 0;   ///< messages heard on the source side (echoes excluded)
  std::uint64_t filtered = 0;   ///< not matching --channels, not forwarded
  std::uint64_t echoes = 0;     ///< our own publications heard back on the source side
  std::uint64_t published = 0;  ///< copies published on the target side
  std::uint64_t publish_errors = 0;
  std::uint64_t unreleased = 0;     ///< copies still queued when the relay stopped
  std::uint64_t queue_dropped = 0;  ///< dropped on arrival: the release queue was full (QueueBound)
  Duration total_delay{0};          ///< sum over published copies of release - arrival
  Duration max_delay{0};
};

struct RelayStats {
  DirectionStats a2b, b2a;
};

/// "a2b: received=... lost=... ..." one line per direction (key=value).
std::string FormatStats(const RelayStats& stats);

class LcmRelay {
 public:
  /// Opens both LCM URLs and subscribes to every channel on each.
  /// Throws std::runtime_error naming the URL if LCM cannot open it, and
  /// std::invalid_argument for bad impairment parameters.
  explicit LcmRelay(const RelayOptions& options);
  ~LcmRelay();
  LcmRelay(const LcmRelay&) = delete;
  LcmRelay& operator=(const LcmRelay&) = delete;

  /// Relays until RequestStop() or, if duration_s > 0, for that long.
  /// Copies not yet due when it stops are discarded (counted as unreleased).
  /// Throws std::runtime_error if a relay thread failed.
  void Run();
  void RequestStop();

  /// Counters so far; safe while Run() is active.
  RelayStats Stats() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace robotalk::relay
