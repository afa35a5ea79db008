// One client session on the server (the paper's CClientConnection), the one
// entry of the server's session table (session_table.h) for it: who it is
// (session id, robot, client id; keyed mode: the key it is bound to and its
// session keys), when it expires, the package sequences it has sent, the
// final replies of its recent packages for re-sending to a retransmission,
// and its playback sequences still buffering. Its command queue lives in the
// RobotDaemon's Scheduler. Pure data, used by one thread (the ServerDaemon's).
#pragma once

#include "command_queue.h"
#include "link_health.h"
#include "playback_estimator.h"
#include "playback_schedule.h"
#include "robotalk/access_list.h"
#include "robotalk/command.h"
#include "robotalk/session_auth.h"
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

/// Final replies of a client's recent packages, by package sequence, so a
/// retransmission is answered without running anything again.
///
/// Bounds: at most `max_packages` packages, and bytes() (each reply's
/// struct, message and values, each id, the index entries) never above
/// `max_bytes`: past either, the oldest packages are forgotten. Items of a
/// forgotten package that still wait for their final reply keep a small
/// entry (counted) until it comes, so a retransmission is not told they were
/// forgotten while they wait; that reply is sent, not kept. At most
/// `max_packages` such entries are kept, the oldest dropped first. A
/// package's items named in another package (a playback's id comes with
/// each of its packages) stay until the last of them is forgotten.
class ReplyCache {
 public:
  struct Limits {
    std::size_t max_packages = 1024;
    std::size_t max_bytes = 256 * 1024;
  };
  ReplyCache() : ReplyCache(Limits{}) {}
  explicit ReplyCache(Limits limits) : limits_(limits) {}

  /// Remembers which item ids a package carried (evicts the oldest packages).
  void RecordPackage(std::int64_t sequence, std::vector<CommandId> ids);
  /// Remembers a final reply (ignored unless its id belongs to a recorded package).
  void RecordReply(const Reply& reply);
  /// The final replies known for a package's items (for a retransmission).
  std::vector<Reply> RepliesFor(std::int64_t sequence) const;
  /// True while the cache still holds `sequence`'s package.
  bool HasPackage(std::int64_t sequence) const { return packages_.count(sequence) != 0; }
  /// nullopt: the id is not in the cache; a nullopt inside: received, no
  /// final reply yet; else its final reply.
  std::optional<std::optional<Reply>> Lookup(CommandId id) const {
    const auto it = replies_.find(id);
    if (it == replies_.end()) return std::nullopt;
    return it->second.reply;
  }

  /// Memory held, as counted against `max_bytes`.
  std::size_t bytes() const { return bytes_; }
  std::size_t packages() const { return packages_.size(); }
  const Limits& limits() const { return limits_; }
  /// What one cached reply costs (its index entry, struct, message, values).
  static std::size_t Bytes(const std::optional<Reply>& reply);

 private:
  struct Entry {
    std::optional<Reply> reply;
    int packages = 0;       // recorded packages that carry it
    bool detached = false;  // its packages were forgotten while it waited
  };
  void Evict();
  void EvictOldestPackage();
  void Erase(std::unordered_map<CommandId, Entry>::iterator it);

  Limits limits_;
  std::size_t bytes_ = 0;
  std::deque<std::int64_t> order_;                                     // oldest first
  std::unordered_map<std::int64_t, std::vector<CommandId>> packages_;  // sequence -> item ids
  std::unordered_map<CommandId, Entry> replies_;                       // id -> final reply once known
  std::deque<CommandId> detached_;                                     // oldest first
};

/// One playback sequence of a client (paper §V-C): its frames wait in the
/// playback queue until the delay is estimated, then move to the command
/// queue. Once it started, the estimator and the buffer are freed; once every
/// declared frame was received, the sequence itself (Session::EndPlayback).
struct PlaybackSequence {
  PlaybackSequence(std::size_t total_frames, Duration duration, PlaybackEstimatorOptions options)
      : estimator(std::in_place, total_frames, duration, options), total(total_frames), duration(duration) {}

  std::optional<PlaybackEstimator> estimator;  ///< until the start is known
  struct Frame {
    Duration offset;  ///< from the sequence start
    QueuedItem item;  ///< its start is set once the sequence's start is known
    TimePoint arrival;
    std::optional<Duration> delay;  ///< arrival − client send time (OneWayDelay)
  };
  std::vector<Frame> frames;                 ///< the playback queue
  std::optional<TimePoint> start;            ///< when offset 0 plays, once estimated
  std::optional<PlaybackSchedule> schedule;  ///< when each frame plays, once started
  std::optional<TimePoint> first_arrival;
  /// Decided at frame 0 but not yet started: waiting for frame 0's second
  /// copy (the client's redundancy) until then (RobotSessions::DecidePlaybacks).
  std::optional<TimePoint> decide_by;
  std::size_t total;
  Duration duration;
  std::size_t received = 0;
  /// How its frames join (the first package's; every package must say the same).
  Interpolation interpolation = Interpolation::kStep;

  /// Memory it holds beyond its map entry (buffer and estimator).
  std::size_t bytes() const {
    return frames.capacity() * sizeof(Frame) + (estimator ? estimator->heap_bytes() : 0);
  }
};

struct Session {
  Session(std::int64_t id, TimePoint now, ReplyCache::Limits reply_limits = {})
      : client_id(id), created(now), last_heard(now), replies(reply_limits) {}

  // --- The session's identity: its own, never taken over (Continue).
  std::int64_t session_id = 0;
  int robot = 0;            ///< the robot's number in the session table
  bool live = false;        ///< false: pending (opened by a hello, no package accepted yet)
  std::uint64_t order = 0;  ///< opening order: the oldest pending session is dropped first
  Nonce hello_nonce{};      ///< the client nonce of the hello that opened it
  struct Keyed {
    SessionKeys keys;
    const AccessEntry* client = nullptr;  ///< the access-list entry its key is bound to
    ClientHello hello;                    ///< as received: a repeat must equal it
    ServerAnswer answer;                  ///< sent again to a repeat
  };
  std::optional<Keyed> keyed;  ///< keyed mode only

  // --- The client's side on its robot; a newer session of the same client
  // and robot takes it over when it goes live (Continue).
  std::int64_t client_id;
  std::string who;    ///< for logs: "client 503d..." or "'alice' (rt:1a2b:..., client 503d...)"
  TimePoint created;  ///< the hello (or the first package without one)
  /// The last new package the robot admitted (any new one while it is not
  /// `active`): the session expires a timeout after it.
  TimePoint last_heard;
  bool active = false;  ///< the robot serves it (a package was admitted): counts against its bound
  SequenceWindow seen;  ///< the one replay / duplicate window
  ReplyCache replies;
  DelayHistory delays;  ///< one-way delays of its latest packages (playback's quick start)
  LinkHealth link;      ///< how its link is doing (link_health.h)
  /// The link level last logged, when, and whether --link-stop acted on it.
  LinkHealth::Level link_logged = LinkHealth::Level::kUnknown;
  TimePoint link_logged_at{};
  bool link_stopped = false;
  std::map<std::int64_t, PlaybackSequence> playbacks;  ///< unfinished ones, by playback id
  /// Timed servo commands queued and not yet answered: id -> (start, actuator).
  std::unordered_map<CommandId, std::pair<TimePoint, int>> timed_servos;
  /// Per actuator, the latest start time of this client's servo commands that ran.
  std::map<int, TimePoint> latest_servo_start;
  /// Why a playback sequence is no longer in `playbacks`.
  enum class Ended { kPanic, kLinkStop, kComplete };
  /// Playback sequences that ended (the most recent kMaxEnded): their late
  /// frames are answered at once instead of starting a new sequence.
  std::deque<std::pair<std::int64_t, Ended>> ended_playbacks;
  static constexpr std::size_t kMaxEnded = 64;
  void EndPlayback(std::int64_t id, Ended why) {
    playbacks.erase(id);
    ended_playbacks.emplace_back(id, why);
    if (ended_playbacks.size() > kMaxEnded) ended_playbacks.pop_front();
  }
  std::optional<Ended> PlaybackEnded(std::int64_t id) const {
    for (const auto& [ended, why] : ended_playbacks) {
      if (ended == id) return why;
    }
    return std::nullopt;
  }
  /// Frames buffered over all playbacks (they count against the queue limit).
  std::size_t buffered_frames() const {
    std::size_t n = 0;
    for (const auto& [id, seq] : playbacks) n += seq.frames.size();
    return n;
  }
  /// Memory of its playback sequences: map nodes, buffers, estimators and
  /// the ended list.
  std::size_t playback_bytes() const;
  /// Takes over the client's side of `previous` (an older session of the
  /// same client on the same robot that this one replaces): its window,
  /// replies, playbacks and servo bookkeeping; keeps its own identity.
  void Continue(Session&& previous);
};

inline std::size_t Session::playback_bytes() const {
  constexpr std::size_t kNode = sizeof(std::pair<const std::int64_t, PlaybackSequence>) + 4 * sizeof(void*);
  std::size_t n = ended_playbacks.size() * sizeof(std::pair<std::int64_t, Ended>);
  for (const auto& [id, seq] : playbacks) n += kNode + seq.bytes();
  return n;
}

}  // namespace robotalk
