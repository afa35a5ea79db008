// Which package sequence numbers of one client the server has already seen,
// so a retransmitted or duplicated package is never executed twice. Pure.
//
// Exact, not a sliding window: every number between the session's first and
// its highest that has not arrived is remembered as unseen, however far below
// the highest it lies, so its package runs when it comes. (A sliding window
// forgot unseen numbers that fell behind the highest: a sender of packages
// under another client's id could push that client's next numbers out of the
// window with strides each under the jump guard, and its packages were then
// dropped as duplicates; issue 19.) The bound is on the unseen numbers
// instead: a sequence that would leave more than kMaxUnseen of them is
// refused. A client numbers its packages 1, 2, 3 ...; only loss and
// reordering leave numbers unseen, a few at a time.
//
// Memory: at most kMaxUnseen gaps (16 bytes each), whatever is sent.
#pragma once

#include <cstdint>
#include <utility>
#include <vector>

namespace robotalk {

class SequenceWindow {
 public:
  enum class Verdict {
    kNew,         ///< never seen: recorded (Observe) and to be executed
    kDuplicate,   ///< seen before: never execute again
    kTooManyGaps  ///< would leave more than kMaxUnseen numbers unseen: refused, not recorded
  };
  static constexpr std::int64_t kMaxUnseen = 4096;
  /// Numbers just before a session's first sequence that may still arrive
  /// (reordered at its start); they count as unseen.
  static constexpr std::int64_t kLead = 64;

  /// What Observe would say; changes nothing. Sequences <= 0 are duplicates.
  Verdict Check(std::int64_t sequence) const;
  /// Records `sequence` when new; returns Check's verdict.
  Verdict Observe(std::int64_t sequence);

  std::int64_t highest() const { return highest_; }
  /// Numbers below the highest not received (in the bound).
  std::int64_t unseen() const { return unseen_; }

 private:
  bool started_ = false;
  std::int64_t floor_ = 0;    // every sequence <= this is a duplicate (or before the session)
  std::int64_t highest_ = 0;  // the highest seen
  std::int64_t unseen_ = 0;   // total length of gaps_
  std::vector<std::pair<std::int64_t, std::int64_t>>
      gaps_;  // unseen [first, last], sorted, in (floor_, highest_)
};

}  // namespace robotalk
