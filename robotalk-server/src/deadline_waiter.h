// How the RobotDaemon's thread waits for its next deadline (a start time, a
// driver period, a state sample), apart from what it does at it (issue 20).
//
// With `precise` timing: 1 ns timer slack (prctl PR_SET_TIMERSLACK) and
// SCHED_FIFO at `fifo_priority` when the process may (else SCHED_OTHER,
// silently: Apply() says which), and the last `final_spin` before a start
// time or sample is a busy wait with the lock released (a futex wake-up is
// tens of µs late on a loaded machine). The spin is bounded by final_spin per
// deadline and by SpinBudget over time (`spin_share` of a core): past that,
// deadlines are dense and waited for without a spin.
//
// Thread safety: one thread (the RobotDaemon's) uses it.
#pragma once

#include "robotalk/clock.h"

#include <chrono>
#include <condition_variable>
#include <functional>
#include <mutex>
#include <string>

namespace robotalk {

struct DeadlineOptions {
  bool precise = true;
  Duration final_spin = std::chrono::microseconds(50);
  double spin_share = 0.05;
  int fifo_priority = 10;
};

/// The spin's budget: `share` of the real time that passes is earned, at most
/// 20 spins saved up. Pure: the caller passes the steady clock's time.
class SpinBudget {
 public:
  using SteadyTime = std::chrono::steady_clock::time_point;
  SpinBudget(Duration final_spin, double share) : final_spin_(final_spin), share_(share) {}
  /// Earns share × (now − the last Refill), up to 20 spins' worth.
  void Refill(SteadyTime now);
  /// Whether a whole final spin may be spent now.
  bool CanSpin() const { return left_ >= final_spin_; }
  void Spend(Duration spun) { left_ -= spun; }
  Duration left() const { return left_; }

 private:
  Duration final_spin_;
  double share_;
  Duration left_{0};
  SteadyTime last_{};
};

class DeadlineWaiter {
 public:
  DeadlineWaiter(const Clock& clock, DeadlineOptions options);

  /// On the waiting thread, once: applies the timer slack and SCHED_FIFO
  /// when precise; returns what was applied ("1 ns timer slack, final spin
  /// 50 us, SCHED_FIFO priority 10", or "... precise_timing off").
  std::string Apply();
  /// Returns at `next` (on the waiter's clock), or earlier once `woken()` is
  /// true (checked under `lock`, woken through `wake`). `spin`: `next` is a
  /// start time or sample, worth a final spin. REQUIRES: `lock` held; it is
  /// held again on return. `next` may be TimePoint::min() (due at once) or
  /// TimePoint::max() (idle).
  void WaitUntil(std::unique_lock<std::mutex>& lock, std::condition_variable& wake, TimePoint next, bool spin,
                 const std::function<bool()>& woken);

 private:
  std::chrono::steady_clock::time_point SteadyDeadline(TimePoint t) const;

  const Clock& clock_;
  const DeadlineOptions options_;
  bool applied_ = false;  // Apply() ran with precise timing
  SpinBudget budget_;
};

}  // namespace robotalk
