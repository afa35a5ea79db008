// ReturnCache: the client's hash map CommandId -> Reply (paper §IV-B). The
// ReadDaemon files replies as they arrive, in any order; callers poll or wait
// for the reply of one id.
//
// Only ids registered with Expect() are accepted: a reply for an unknown id,
// a second reply for an id that already has one, or a reply for an id whose
// caller gave up (Forget) is ignored, so a duplicated reply is never seen twice
// and stray replies cannot fill the map. Answered replies are removed when
// collected (Take); answered-but-uncollected ones beyond `capacity` are
// evicted oldest first.
//
// Thread safety: every method may be called from any thread.
#pragma once

#include "robotalk/command.h"

#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <mutex>
#include <optional>
#include <stop_token>
#include <string>
#include <unordered_map>

namespace robotalk::client {

class ReturnCache {
 public:
  /// The outcome of one id as a waiter sees it.
  struct Outcome {
    enum class Kind { kPending, kReply, kFailed, kUnknown } kind = Kind::kPending;
    Reply reply;            ///< valid for kReply
    std::string failure;    ///< valid for kFailed: why no reply will come
    bool timed_out = true;  ///< kFailed: given up on (true) or client closed (false)
  };

  explicit ReturnCache(std::size_t capacity = 10000) : capacity_(capacity) {}

  /// Registers an id whose reply will be waited for. Re-registering is a no-op.
  void Expect(CommandId id);
  /// Files a reply. Returns false (and ignores it) when the id is not expected
  /// or already has an outcome.
  bool Put(const Reply& reply);
  /// Gives the id a failure instead of a reply (retransmission gave up, client
  /// closed). Ignored when the id already has an outcome or is unknown.
  bool Fail(CommandId id, const std::string& why, bool timed_out = true);
  /// Fails every pending id.
  void FailAll(const std::string& why, bool timed_out);
  /// Forgets the id (its caller lost interest); a later reply is ignored.
  void Forget(CommandId id);

  /// The outcome now; kReply/kFailed remove the entry (collected).
  Outcome Take(CommandId id);
  /// Waits until the id has an outcome, `deadline` passes or `stop` is
  /// requested (then kPending); wakes at once for each. A reply or failure
  /// is removed from the cache when returned.
  Outcome WaitTake(CommandId id, std::chrono::steady_clock::time_point deadline, std::stop_token stop = {});

  /// Ids registered and not yet collected (pending or answered).
  std::size_t size() const;
  /// Replies ignored so far (duplicates, unknown ids).
  std::uint64_t ignored() const;

 private:
  struct Entry {
    Outcome outcome;
  };
  Outcome TakeLocked(CommandId id);  // REQUIRES: mu_ held
  void EvictLocked();                // REQUIRES: mu_ held

  const std::size_t capacity_;
  mutable std::mutex mu_;
  std::condition_variable_any cv_;                // _any: waits that a std::stop_token can end
  std::unordered_map<CommandId, Entry> entries_;  // GUARDED_BY(mu_)
  std::deque<CommandId> answered_order_;          // GUARDED_BY(mu_), may hold stale ids
  std::size_t num_answered_ = 0;                  // GUARDED_BY(mu_)
  std::uint64_t ignored_ = 0;                     // GUARDED_BY(mu_)
};

}  // namespace robotalk::client
