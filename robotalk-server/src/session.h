// One client's state on the server (the paper's CClientConnection), as the
// ServerDaemon keeps it: the package sequences it has sent, the final replies
// of its recent packages for re-sending to a retransmission, and its playback
// sequences still buffering. Its command queue lives in the RobotDaemon's
// Scheduler. Pure data, used by one thread (the ServerDaemon's RobotSessions).
#pragma once

#include "command_queue.h"
#include "playback_estimator.h"
#include "robotalk/command.h"
#include "sequence_window.h"

#include <algorithm>
#include <cstdint>
#include <deque>
#include <map>
#include <optional>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

namespace robotalk {

/// Final replies of a client's recent packages, by package sequence.
class ReplyCache {
 public:
  explicit ReplyCache(size_t max_packages = 1024) : max_packages_(max_packages) {}
  /// Remembers which item ids a package carried (evicts the oldest package).
  void RecordPackage(std::int64_t sequence, std::vector<CommandId> ids);
  /// Remembers a final reply (ignored unless its id belongs to a recorded package).
  void RecordReply(const Reply& reply);
  /// The final replies known for a package's items (for a retransmission).
  std::vector<Reply> RepliesFor(std::int64_t sequence) const;
  /// nullopt: the id is not in the cache; a nullopt inside: received, no
  /// final reply yet; else its final reply.
  std::optional<std::optional<Reply>> Lookup(CommandId id) const {
    const auto it = replies_.find(id);
    if (it == replies_.end()) return std::nullopt;
    return it->second;
  }

 private:
  size_t max_packages_;
  std::deque<std::int64_t> order_;                                     // oldest first
  std::unordered_map<std::int64_t, std::vector<CommandId>> packages_;  // sequence -> item ids
  std::unordered_map<CommandId, std::optional<Reply>> replies_;        // id -> final reply once known
};

/// One playback sequence of a client (paper §V-C): its frames wait in the
/// playback queue until the delay is estimated, then move to the command queue.
struct PlaybackSequence {
  PlaybackSequence(std::size_t total_frames, Duration duration, PlaybackEstimatorOptions options)
      : estimator(total_frames, duration, options), total(total_frames), duration(duration) {}

  PlaybackEstimator estimator;
  struct Frame {
    Duration offset;  ///< from the sequence start
    QueuedItem item;  ///< its start is set once the sequence's start is known
  };
  std::vector<Frame> frames;       ///< the playback queue
  std::optional<TimePoint> start;  ///< when offset 0 plays, once estimated
  std::optional<TimePoint> first_arrival;
  std::size_t total;
  Duration duration;
  std::size_t received = 0;
};

struct Session {
  Session(std::int64_t id, TimePoint now) : client_id(id), created(now), last_heard(now) {}

  std::int64_t client_id;
  std::string who;  ///< for logs: the sender as the session gate names it
  TimePoint created;
  TimePoint last_heard;
  SequenceWindow seen;
  ReplyCache replies;
  DelayHistory delays;  ///< one-way delays of its latest packages (playback's quick start)
  std::map<std::int64_t, PlaybackSequence> playbacks;  ///< by playback id
  /// Timed servo commands queued and not yet answered: id -> (start, actuator).
  std::unordered_map<CommandId, std::pair<TimePoint, int>> timed_servos;
  /// Per actuator, the latest start time of this client's servo commands that ran.
  std::map<int, TimePoint> latest_servo_start;
  /// Playback sequences a panic ended (the most recent kMaxEnded): their
  /// late frames are answered at once instead of starting a new sequence.
  std::deque<std::int64_t> ended_playbacks;
  static constexpr std::size_t kMaxEnded = 64;
  void EndPlayback(std::int64_t id) {
    playbacks.erase(id);
    ended_playbacks.push_back(id);
    if (ended_playbacks.size() > kMaxEnded) ended_playbacks.pop_front();
  }
  bool PlaybackEnded(std::int64_t id) const {
    return std::find(ended_playbacks.begin(), ended_playbacks.end(), id) != ended_playbacks.end();
  }
  /// Frames buffered over all playbacks (they count against the queue limit).
  std::size_t buffered_frames() const {
    std::size_t n = 0;
    for (const auto& [id, seq] : playbacks) n += seq.frames.size();
    return n;
  }
};

}  // namespace robotalk
