#include "clock_sync.h"

#include <gtest/gtest.h>

namespace robotalk::client {
namespace {

using std::chrono::milliseconds;
const TimePoint kT0(std::chrono::seconds(100));

// Server clock = client clock + 5 s.
constexpr Duration kTrueOffset = std::chrono::seconds(5);

TEST(ClockSync, StartsUnsyncedWithZeroOffset) {
  ClockSync s;
  EXPECT_FALSE(s.synced());
  EXPECT_EQ(s.offset(), Duration::zero());
  EXPECT_EQ(s.ServerTime(kT0), kT0);
}

TEST(ClockSync, SymmetricRoundTripGivesTheExactOffset) {
  ClockSync s;
  // 10 ms each way, 2 ms server processing.
  const TimePoint t1 = kT0;
  const TimePoint t2 = t1 + milliseconds(10) + kTrueOffset;
  const TimePoint t3 = t2 + milliseconds(2);
  const TimePoint t4 = t1 + milliseconds(22);
  ASSERT_TRUE(s.AddSample(t1, t2, t3, t4));
  EXPECT_EQ(s.offset(), kTrueOffset);
  EXPECT_EQ(*s.best_round_trip(), milliseconds(20));
  EXPECT_EQ(s.ServerTime(kT0), kT0 + kTrueOffset);
  EXPECT_EQ(s.ClientTime(kT0 + kTrueOffset), kT0);
}

TEST(ClockSync, KeepsTheSampleWithTheSmallestRoundTrip) {
  ClockSync s;
  // A congested, asymmetric sample: 100 ms out, 10 ms back -> offset error 45 ms.
  TimePoint t1 = kT0;
  ASSERT_TRUE(s.AddSample(t1, t1 + milliseconds(100) + kTrueOffset, t1 + milliseconds(100) + kTrueOffset,
                          t1 + milliseconds(110)));
  EXPECT_EQ(s.offset(), kTrueOffset + milliseconds(45));
  // A fast one: 1 ms each way.
  t1 = kT0 + std::chrono::seconds(1);
  ASSERT_TRUE(s.AddSample(t1, t1 + milliseconds(1) + kTrueOffset, t1 + milliseconds(1) + kTrueOffset,
                          t1 + milliseconds(2)));
  EXPECT_EQ(s.offset(), kTrueOffset);
  // A later slow one does not replace it.
  t1 = kT0 + std::chrono::seconds(2);
  ASSERT_TRUE(s.AddSample(t1, t1 + milliseconds(50) + kTrueOffset, t1 + milliseconds(50) + kTrueOffset,
                          t1 + milliseconds(51)));
  EXPECT_EQ(s.offset(), kTrueOffset);
  EXPECT_EQ(s.num_samples(), 3);
  EXPECT_EQ(*s.best_round_trip(), milliseconds(2));
}

TEST(ClockSync, IgnoresInconsistentSamples) {
  ClockSync s;
  EXPECT_FALSE(s.AddSample(kT0, kT0, kT0, kT0 - milliseconds(1)));                    // t4 < t1
  EXPECT_FALSE(s.AddSample(kT0, kT0 + milliseconds(5), kT0, kT0 + milliseconds(9)));  // t3 < t2
  // Server claims 10 ms of processing inside a 5 ms round trip.
  EXPECT_FALSE(s.AddSample(kT0, kT0, kT0 + milliseconds(10), kT0 + milliseconds(5)));
  EXPECT_FALSE(s.synced());
}

}  // namespace
}  // namespace robotalk::client
