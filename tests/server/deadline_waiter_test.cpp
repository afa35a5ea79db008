#include "deadline_waiter.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <thread>

namespace robotalk {
namespace {

using std::chrono::microseconds;
using std::chrono::milliseconds;
using Steady = std::chrono::steady_clock;

TEST(SpinBudget, EarnsItsShareOfTimeUpToTwentySpins) {
  SpinBudget budget(microseconds(50), 0.05);
  const Steady::time_point t0{std::chrono::seconds(1000)};
  budget.Refill(t0);
  EXPECT_EQ(budget.left(), microseconds(1000)) << "a long idle time saves 20 spins, no more";
  EXPECT_TRUE(budget.CanSpin());
  for (int i = 0; i < 20; ++i) budget.Spend(microseconds(50));
  EXPECT_FALSE(budget.CanSpin()) << "dense deadlines spent it";
  budget.Refill(t0 + microseconds(500));
  EXPECT_EQ(budget.left(), microseconds(25)) << "5 % of 500 us";
  EXPECT_FALSE(budget.CanSpin());
  budget.Refill(t0 + microseconds(1000));
  EXPECT_EQ(budget.left(), microseconds(50));
  EXPECT_TRUE(budget.CanSpin());
}

TEST(DeadlineWaiter, SaysItsTimingWhenPreciseTimingIsOff) {
  ManualClock clock;
  DeadlineWaiter waiter(clock, DeadlineOptions{.precise = false});
  EXPECT_EQ(waiter.Apply(), "default timer slack, no final spin, SCHED_OTHER (precise_timing off)");
}

TEST(DeadlineWaiter, ReturnsAtOnceForADeadlineDueAndWhenWoken) {
  ManualClock clock;
  DeadlineWaiter waiter(clock, DeadlineOptions{.precise = false});
  std::mutex mutex;
  std::condition_variable wake;
  std::unique_lock lock(mutex);
  waiter.WaitUntil(lock, wake, TimePoint::min(), true, [] { return false; });  // due at once
  waiter.WaitUntil(lock, wake, clock.Now(), true, [] { return false; });
  // Idle (no deadline) ends only when woken: the condition is already true.
  waiter.WaitUntil(lock, wake, TimePoint::max(), false, [] { return true; });
  EXPECT_TRUE(lock.owns_lock());
}

// The deadline is on the waiter's clock, which may run ahead of the steady
// clock (an offset clock): it waits for the distance, not the steady time.
TEST(DeadlineWaiter, WaitsForTheDistanceToADeadlineOnItsOwnClockWithAndWithoutTheSpin) {
  SteadyClock steady;
  OffsetClock clock(steady, std::chrono::seconds(1000));
  for (const bool precise : {false, true}) {
    DeadlineWaiter waiter(clock, DeadlineOptions{.precise = precise, .final_spin = microseconds(200)});
    if (precise) waiter.Apply();
    std::mutex mutex;
    std::condition_variable wake;
    std::unique_lock lock(mutex);
    const TimePoint deadline = clock.Now() + milliseconds(20);
    waiter.WaitUntil(lock, wake, deadline, /*spin=*/true, [] { return false; });
    EXPECT_GE(clock.Now(), deadline) << "precise " << precise;
    EXPECT_LT(clock.Now(), deadline + std::chrono::seconds(5)) << "precise " << precise;
    EXPECT_TRUE(lock.owns_lock());
  }
}

}  // namespace
}  // namespace robotalk
