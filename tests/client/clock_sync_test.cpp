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

// A forged (or corrupt) reply may carry server times anywhere in the wire's
// range: a sample whose arithmetic would overflow is rejected, not added
// (it was undefined behaviour, in practice a wrapped difference that passed
// the checks and set an absurd offset).
TEST(ClockSync, RejectsForgedTimesAtTheEndsOfTheRange) {
  const TimePoint lo = TimePoint::min(), hi = TimePoint::max();
  const TimePoint t1 = kT0, t4 = kT0 + milliseconds(2);
  ClockSync s;
  EXPECT_FALSE(s.AddSample(t1, lo, hi, t4)) << "server interval t3 - t2 overflows";
  EXPECT_FALSE(s.AddSample(t1, hi, lo, t4)) << "t3 < t2";
  EXPECT_FALSE(s.AddSample(lo, kT0, kT0, hi)) << "client interval t4 - t1 overflows";
  EXPECT_FALSE(s.AddSample(hi, kT0, kT0, lo)) << "t4 < t1";
  EXPECT_FALSE(s.AddSample(t1, lo, lo, t4)) << "t2 - t1 overflows";
  EXPECT_FALSE(s.AddSample(t1, hi, hi, t4)) << "t3 - t4 overflows";
  // Each difference fits, their sum does not: an offset of more than 146 years.
  const TimePoint far = lo + std::chrono::seconds(200);
  EXPECT_FALSE(s.AddSample(t1, far, far, t4)) << "(t2 - t1) + (t3 - t4) overflows";
  // The offset fits but maps the client's receive time past the end of the range.
  const Duration off = hi.time_since_epoch() / 4;
  const TimePoint t(hi.time_since_epoch() - off - std::chrono::microseconds(1500));
  const TimePoint server = t + milliseconds(1) + off;  // hi - 0.5 ms
  EXPECT_FALSE(s.AddSample(t, server, server, t + milliseconds(2))) << "ServerTime(t4) overflows";
  EXPECT_FALSE(s.synced());
  EXPECT_EQ(s.num_samples(), 0);
  EXPECT_EQ(s.offset(), Duration::zero());
  // A sane sample after them is used as usual.
  EXPECT_TRUE(s.AddSample(t1, t1 + milliseconds(1) + kTrueOffset, t1 + milliseconds(1) + kTrueOffset, t4));
  EXPECT_EQ(s.offset(), kTrueOffset);
}

}  // namespace
}  // namespace robotalk::client
