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

// Two hosts' steady clocks drift apart (tens of ppm without NTP). The best
// sample of a long session must not stand for it: before, the offset from
// the session's first (best) round trip stood for its whole life, 1.44 s
// wrong after 2 h at 200 ppm, which turned a keyed client's panic path off
// (FreshAnnouncementTime) and shifted every delay-mode start. Now the best
// sample's error bound grows with its age, so with a sample every 10 s (the
// client's refresh) the offset follows the drift within a few round trips'
// worth.
TEST(ClockSync, FollowsAServerClockThatDriftsOverALongSession) {
  ClockSync s;
  constexpr double kDrift = 200e-6;  // the server's clock runs 200 ppm fast
  const auto server_at = [&](TimePoint client) {
    const Duration since = client - kT0;
    return client + kTrueOffset +
           std::chrono::duration_cast<Duration>(
               std::chrono::duration<double, std::nano>(since.count() * kDrift));
  };
  // The session's first sample is the best it will ever see: 0.1 ms.
  ASSERT_TRUE(s.AddSample(kT0, server_at(kT0 + std::chrono::microseconds(50)),
                          server_at(kT0 + std::chrono::microseconds(50)),
                          kT0 + std::chrono::microseconds(100)));
  Duration worst{0};
  std::uint32_t lcg = 7;
  for (int k = 1; k <= 720; ++k) {  // every 10 s for 2 h
    const TimePoint t1 = kT0 + std::chrono::seconds(10) * k;
    lcg = lcg * 1664525u + 1013904223u;
    const Duration one_way = std::chrono::microseconds(500 + lcg % 9500);  // 0.5-10 ms, symmetric
    const TimePoint t2 = server_at(t1 + one_way);
    ASSERT_TRUE(s.AddSample(t1, t2, t2, t1 + 2 * one_way));
    const Duration error = s.ServerTime(t1 + 2 * one_way) - server_at(t1 + 2 * one_way);
    worst = std::max(worst, error < Duration::zero() ? -error : error);
  }
  // Within what fresh samples allow: their round trips (up to 20 ms), and
  // the drift (200 ppm, twice the allowance) over the ~100 s a sample can
  // stand before a fresh one's bound (up to 10 ms) is tighter: 20 ms.
  EXPECT_LT(worst, milliseconds(40)) << "worst offset error " << ToSeconds(worst) << " s";
}

// The first sample after a long quiet spell replaces a best sample grown
// old, even when its round trip is longer: the old one's bound has grown by
// the drift allowance over its age.
TEST(ClockSync, AnOldBestSampleGivesWayToAFreshOneWhoseBoundIsTighter) {
  ClockSync s;
  ASSERT_TRUE(s.AddSample(kT0, kT0 + milliseconds(1) + kTrueOffset, kT0 + milliseconds(1) + kTrueOffset,
                          kT0 + milliseconds(2)));
  // An hour later (an allowance of 100 ppm: 360 ms of possible drift), a
  // 10 ms round trip that says the offset moved by 100 ms.
  const TimePoint t1 = kT0 + std::chrono::hours(1);
  const Duration moved = kTrueOffset + milliseconds(100);
  ASSERT_TRUE(
      s.AddSample(t1, t1 + milliseconds(5) + moved, t1 + milliseconds(5) + moved, t1 + milliseconds(10)));
  EXPECT_EQ(s.offset(), moved);
  EXPECT_EQ(*s.best_round_trip(), milliseconds(10));
  // A second later, a slower sample does not replace the fresh one.
  const TimePoint t2 = t1 + std::chrono::seconds(1);
  ASSERT_TRUE(s.AddSample(t2, t2 + milliseconds(25) + kTrueOffset, t2 + milliseconds(25) + kTrueOffset,
                          t2 + milliseconds(50)));
  EXPECT_EQ(s.offset(), moved);
}

}  // namespace
}  // namespace robotalk::client
