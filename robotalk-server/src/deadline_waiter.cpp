#include "deadline_waiter.h"

#include <pthread.h>
#include <sched.h>
#include <sys/prctl.h>

#include <algorithm>
#include <cstdio>

namespace robotalk {

void SpinBudget::Refill(SteadyTime now) {
  const auto earned = std::chrono::duration_cast<Duration>(now - last_) * share_;
  left_ = std::min<Duration>(20 * final_spin_, left_ + std::chrono::duration_cast<Duration>(earned));
  last_ = now;
}

DeadlineWaiter::DeadlineWaiter(const Clock& clock, DeadlineOptions options)
    : clock_(clock), options_(options), budget_(options.final_spin, options.spin_share) {}

std::string DeadlineWaiter::Apply() {
  if (!options_.precise) return "default timer slack, no final spin, SCHED_OTHER (precise_timing off)";
  applied_ = true;
  const bool slack = prctl(PR_SET_TIMERSLACK, 1UL, 0UL, 0UL, 0UL) == 0;
  sched_param param{};
  param.sched_priority = options_.fifo_priority;
  const bool fifo = pthread_setschedparam(pthread_self(), SCHED_FIFO, &param) == 0;
  char buf[200];
  std::snprintf(buf, sizeof buf, "%s, final spin %lld us, %s",
                slack ? "1 ns timer slack" : "default timer slack",
                static_cast<long long>(
                    std::chrono::duration_cast<std::chrono::microseconds>(options_.final_spin).count()),
                fifo ? ("SCHED_FIFO priority " + std::to_string(param.sched_priority)).c_str()
                     : "SCHED_OTHER (SCHED_FIFO not permitted)");
  return buf;
}

// The condition variable sleeps on the steady clock; `t` is on clock_ (an
// offset or a test's clock): wait for the same distance from now. Saturating:
// neither TimePoint::min() nor TimePoint::max() may overflow (UBSan).
std::chrono::steady_clock::time_point DeadlineWaiter::SteadyDeadline(TimePoint t) const {
  using Steady = std::chrono::steady_clock;
  const Steady::time_point steady_now = Steady::now();
  const Duration distance = SaturatingSub(t, clock_.Now());
  if (distance <= Duration(0)) return steady_now;
  if (distance >= Steady::time_point::max() - steady_now) return Steady::time_point::max();
  return steady_now + distance;
}

void DeadlineWaiter::WaitUntil(std::unique_lock<std::mutex>& lock, std::condition_variable& wake,
                               TimePoint next, bool spin, const std::function<bool()>& woken) {
  if (next <= clock_.Now()) return;  // already due (an item "at once" has TimePoint::min())
  if (!applied_ || !spin || options_.final_spin.count() <= 0 || next == TimePoint::max()) {
    wake.wait_until(lock, SteadyDeadline(next), woken);
    return;
  }
  budget_.Refill(std::chrono::steady_clock::now());
  if (!budget_.CanSpin()) {  // dense deadlines: the spin would cost too much
    wake.wait_until(lock, SteadyDeadline(next), woken);
    return;
  }
  if (wake.wait_until(lock, SteadyDeadline(next - options_.final_spin), woken)) return;
  lock.unlock();
  // Bounded in real time too (a test's ManualClock does not move by itself).
  const auto start = std::chrono::steady_clock::now();
  budget_.Refill(start);
  const auto bound = start + 2 * options_.final_spin;
  while (clock_.Now() < next && std::chrono::steady_clock::now() < bound) {
#if defined(__x86_64__) || defined(__i386__)
    __builtin_ia32_pause();
#endif
  }
  budget_.Spend(std::chrono::duration_cast<Duration>(std::chrono::steady_clock::now() - start));
  lock.lock();
}

}  // namespace robotalk
