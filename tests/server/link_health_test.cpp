// A session's link health (link_health.h, issue 23) on a manual clock: loss
// from sequence gaps, reordering and retransmissions told apart by transit,
// duplicates, jitter, late and expired replies, and the verdict.
#include "link_health.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

namespace robotalk {
namespace {

using std::chrono::milliseconds;

TimePoint At(Duration d) { return TimePoint{} + std::chrono::hours(1) + d; }

// A client sending every 10 ms with a constant client-clock offset of 7 s.
struct Link {
  LinkHealth health;
  void Send(std::int64_t seq, Duration sent, Duration transit, bool duplicate = false,
            Duration rtt = milliseconds(40)) {
    const TimePoint client_sent = At(sent) - std::chrono::seconds(7);
    health.OnPackage(seq, duplicate, client_sent, At(sent + transit), rtt);
  }
};

TEST(LinkHealth, ACleanLinkIsGoodWithItsRoundTripAndNoLoss) {
  Link l;
  EXPECT_EQ(l.health.Evaluate().level, LinkHealth::Level::kUnknown);
  for (int i = 1; i <= 100; ++i) l.Send(i, milliseconds(10 * i), milliseconds(20));
  const LinkFigures f = l.health.Figures();
  EXPECT_EQ(f.packages, 100u);
  EXPECT_EQ(f.expected, 100u);
  EXPECT_EQ(f.lost, 0u);
  EXPECT_EQ(f.jitter, Duration(0));
  EXPECT_EQ(f.round_trip, milliseconds(40));
  EXPECT_EQ(f.delay(), milliseconds(20));
  EXPECT_EQ(l.health.Evaluate().level, LinkHealth::Level::kGood);
  EXPECT_EQ(l.health.Evaluate().why, "");
}

TEST(LinkHealth, ANumberThatNeverComesIsLostAfterTheHorizon) {
  Link l;
  for (int i = 1; i <= 100; ++i) {
    if (i % 10 == 0) continue;  // 10 % never arrive (heartbeats: never resent)
    l.Send(i, milliseconds(10 * i), milliseconds(20));
  }
  EXPECT_EQ(l.health.Figures().lost, 0u);  // undecided: they may still come
  l.health.Tick(At(milliseconds(1000) + l.health.options().loss_horizon));
  const LinkFigures f = l.health.Figures();
  EXPECT_EQ(f.expected, 99u);  // 1 .. 99: the 100th was never passed
  EXPECT_EQ(f.lost, 9u);
  EXPECT_NEAR(f.loss, 9.0 / 99, 1e-12);
}

TEST(LinkHealth, AReorderedCopyIsNotLossButALateRetransmissionIs) {
  Link l;
  for (int i = 1; i <= 20; ++i) l.Send(i, milliseconds(10 * i), milliseconds(20));
  l.Send(22, milliseconds(220), milliseconds(20));
  l.Send(21, milliseconds(210), milliseconds(35));  // 15 ms late: reordered
  l.Send(24, milliseconds(240), milliseconds(20));
  const Duration jitter = l.health.Figures().jitter;
  EXPECT_GT(jitter, Duration(0)) << "the reordered copy's 15 ms is the network's jitter";
  l.Send(23, milliseconds(230), milliseconds(20) + milliseconds(200));  // resent after 200 ms
  const LinkFigures f = l.health.Figures();
  EXPECT_EQ(f.jitter, jitter) << "a retransmission's transit is the resend wait, not jitter";
  EXPECT_EQ(f.reordered, 1u);
  EXPECT_EQ(f.retransmitted, 1u);
  EXPECT_EQ(f.lost, 1u);
  EXPECT_EQ(f.expected, 24u);
}

TEST(LinkHealth, DuplicatesAreCountedApart) {
  Link l;
  l.Send(1, milliseconds(0), milliseconds(20));
  l.Send(1, milliseconds(0), milliseconds(120), /*duplicate=*/true);
  EXPECT_EQ(l.health.Figures().duplicates, 1u);
  EXPECT_EQ(l.health.Figures().packages, 1u);
}

TEST(LinkHealth, JitterFollowsRfc3550OnTheTransitDifferences) {
  Link l;
  // Transit alternating 20 and 30 ms: |D| = 10 ms each time; J converges to 10 ms.
  for (int i = 1; i <= 400; ++i) l.Send(i, milliseconds(10 * i), milliseconds(i % 2 == 0 ? 20 : 30));
  EXPECT_NEAR(ToSeconds(l.health.Figures().jitter), 0.010, 1e-5);
  EXPECT_EQ(l.health.Evaluate().level, LinkHealth::Level::kGood);  // warn at 50 ms
}

TEST(LinkHealth, SeededRandomLossIsMeasuredExactly) {
  Link l;
  std::mt19937_64 rng(7);
  std::bernoulli_distribution drop(0.05);
  std::uint64_t dropped = 0, dropped_then = 0;  // drops below the last received
  const int n = 4000;
  for (int i = 1; i <= n; ++i) {
    if (drop(rng)) {
      ++dropped;
      continue;
    }
    dropped_then = dropped;
    l.Send(i, milliseconds(10 * i), milliseconds(20));
  }
  l.health.Tick(At(milliseconds(10 * n) + std::chrono::seconds(10)));
  const LinkFigures f = l.health.Figures();
  EXPECT_GT(dropped_then, 150u);
  EXPECT_EQ(f.lost, dropped_then);
}

// A WAN-like link (issue 23's profile): 100 ms +- 50 ms, so packages sent
// every 5 ms overtake each other all the time; 1 % lost and resent after the
// client's timeout (300 ms). Reordering is not loss; every resent one is.
TEST(LinkHealth, HeavyJitterReordersWithoutLookingLikeLoss) {
  struct Arrival {
    TimePoint at, sent;
    std::int64_t seq;
  };
  std::mt19937_64 rng(23);
  std::uniform_real_distribution<double> jitter(-50, 50);
  std::bernoulli_distribution drop(0.01);
  std::vector<Arrival> arrivals;
  std::uint64_t dropped = 0;
  const auto transit = [&] {
    return milliseconds(100) + std::chrono::microseconds(std::llround(1000 * jitter(rng)));
  };
  for (int i = 1; i <= 3000; ++i) {
    const TimePoint sent = At(milliseconds(5 * i));
    if (drop(rng)) {
      ++dropped;
      arrivals.push_back({sent + milliseconds(300) + transit(), sent, i});  // the retransmission
    } else {
      arrivals.push_back({sent + transit(), sent, i});
    }
  }
  std::sort(arrivals.begin(), arrivals.end(), [](const Arrival& a, const Arrival& b) { return a.at < b.at; });
  LinkHealth health;
  // The client's median round trip: 2 x 100 ms.
  for (const Arrival& a : arrivals) health.OnPackage(a.seq, false, a.sent, a.at, milliseconds(200));
  health.Tick(arrivals.back().at + std::chrono::seconds(10));
  const LinkFigures f = health.Figures();
  EXPECT_GT(f.reordered, 500u);
  EXPECT_EQ(f.lost, dropped);
  EXPECT_EQ(f.retransmitted, dropped);
  // Half the client's median round trip: the mean delay (the spread of the
  // transits the server sees adds nothing: it is in the round trip already).
  EXPECT_EQ(f.delay(), milliseconds(100));
}

// The one-way delay is half the round trip the client reports (the median of
// its network round trips, outstanding_packages.h), on any link: the
// server's own transits (arrival - the client's send time) carry the clocks'
// unknown offset, so they can say how much the delay varies, never how long
// it is. Jittered (20 ms +- 15 ms) and asymmetric (the client measured 40 ms:
// 30 ms up and 10 ms down): half the round trip, the mean of the two ways.
TEST(LinkHealth, TheDelayIsHalfTheReportedRoundTripWhateverTheTransitsSpread) {
  std::mt19937_64 rng(5);
  std::uniform_int_distribution<int> jitter_us(-15000, 15000);
  Link symmetric, asymmetric;
  for (int i = 1; i <= 500; ++i) {
    symmetric.Send(i, milliseconds(10 * i), milliseconds(20) + std::chrono::microseconds(jitter_us(rng)),
                   false, milliseconds(40));
    asymmetric.Send(i, milliseconds(10 * i), milliseconds(30) + std::chrono::microseconds(jitter_us(rng) / 3),
                    false, milliseconds(40));
  }
  EXPECT_EQ(symmetric.health.Figures().delay(), milliseconds(20));
  EXPECT_EQ(asymmetric.health.Figures().delay(), milliseconds(20));
  EXPECT_GT(symmetric.health.Figures().jitter, milliseconds(5)) << "the spread shows as jitter";
}

TEST(LinkHealth, LateAndExpiredRepliesAreCountedAndExpiredOnesWarn) {
  Link l;
  l.Send(1, milliseconds(0), milliseconds(20));
  l.health.OnReply(milliseconds(2), false, At(milliseconds(30)));
  l.health.OnReply(milliseconds(40), false, At(milliseconds(40)));
  EXPECT_EQ(l.health.Evaluate().level, LinkHealth::Level::kGood);
  l.health.OnReply(milliseconds(840), true, At(milliseconds(50)));
  const LinkFigures f = l.health.Figures();
  EXPECT_EQ(f.replies, 3u);
  EXPECT_EQ(f.late, 1u);
  EXPECT_EQ(f.expired, 1u);
  const LinkHealth::Verdict v = l.health.Evaluate();
  EXPECT_EQ(v.level, LinkHealth::Level::kDegraded);
  EXPECT_EQ(v.why, "1 expired commands (limit 1)");
  // Two windows later the expiry is no longer recent.
  l.health.Tick(At(milliseconds(50) + 2 * l.health.options().window));
  EXPECT_EQ(l.health.Evaluate().level, LinkHealth::Level::kGood);
  EXPECT_EQ(l.health.Figures().expired, 1u);  // cumulative
}

TEST(LinkHealth, HeavyLossAndALongRoundTripAreBad) {
  Link l;
  for (int i = 1; i <= 100; ++i) {
    if (i % 2 == 0) continue;
    l.Send(i, milliseconds(10 * i), milliseconds(20), false, milliseconds(1500));
  }
  l.health.Tick(At(milliseconds(1100) + l.health.options().loss_horizon));
  const LinkHealth::Verdict v = l.health.Evaluate();
  EXPECT_EQ(v.level, LinkHealth::Level::kBad);
  EXPECT_EQ(v.why, "loss 49.5 % > 25.0 %, delay 750 ms > 500 ms");
}

// The round trip is the latest the client reported: the report of its
// highest-numbered package. A copy of a package seen before (a duplicated
// datagram, a retransmission whose answer was lost, or a recording replayed
// by someone who cannot forge a package: keyed mode) and a package
// overtaken by a later-numbered one carry an older report, which must not
// replace it: a replay of a package from a bad spell made a good link bad
// (--link-stop stopped the robot), one from a good spell hid a bad link.
TEST(LinkHealth, OnlyTheHighestNumberedPackagesRoundTripCountsNotACopyOrAnOvertakenOne) {
  // Package 1 reports `first`, 2 .. 30 `then`; then a copy of package 1 comes.
  const auto replay_first = [](Duration first, Duration then, LinkHealth::Level level) {
    Link l;
    l.Send(1, milliseconds(0), milliseconds(20), false, first);
    for (int i = 2; i <= 30; ++i) l.Send(i, milliseconds(10 * i), milliseconds(20), false, then);
    ASSERT_EQ(l.health.Evaluate().level, level);
    l.Send(1, milliseconds(0), milliseconds(400), /*duplicate=*/true, first);
    EXPECT_EQ(l.health.Figures().round_trip, then) << "a copy's older report";
    EXPECT_EQ(l.health.Evaluate().level, level);
  };
  replay_first(milliseconds(1200), milliseconds(20), LinkHealth::Level::kGood);  // stays good
  replay_first(milliseconds(20), milliseconds(1200), LinkHealth::Level::kBad);   // stays bad

  Link overtaken;
  overtaken.Send(2, milliseconds(10), milliseconds(20), false, milliseconds(30));
  overtaken.Send(1, milliseconds(0), milliseconds(35), false, milliseconds(900));
  EXPECT_EQ(overtaken.health.Figures().round_trip, milliseconds(30)) << "package 2's report is the later";
  overtaken.Send(3, milliseconds(20), milliseconds(20), false, milliseconds(50));
  EXPECT_EQ(overtaken.health.Figures().round_trip, milliseconds(50));
}

// A send time no client's clock has (the wire's extremes, ±292 years) is no
// transit: arrival − send time overflowed (undefined behaviour), and the
// wrapped values made the jitter 6.9e8 s and the link bad (review 10). Such a
// package counts as received, its transit unknown (OneWayDelay, as
// playback's delays).
TEST(LinkHealth, ASendTimeAtTheWiresExtremesIsNoTransitAndLeavesTheJitterAlone) {
  Link l;
  for (int i = 1; i <= 20; ++i) l.Send(i, milliseconds(10 * i), milliseconds(20));
  for (const std::int64_t extreme : {-kMaxWireMicros, kMaxWireMicros}) {
    l.health.OnPackage(l.health.Figures().packages + 1, false, FromWireMicros(extreme), At(milliseconds(300)),
                       milliseconds(40));
  }
  for (int i = 23; i <= 30; ++i) l.Send(i, milliseconds(10 * i), milliseconds(20));
  const LinkFigures f = l.health.Figures();
  EXPECT_EQ(f.packages, 30u);
  EXPECT_EQ(f.lost, 0u);
  EXPECT_EQ(f.jitter, Duration(0));
  EXPECT_EQ(l.health.Evaluate().level, LinkHealth::Level::kGood) << l.health.Evaluate().why;
}

// OnPackage says which packages came as retransmissions (playback's delay
// history leaves them out, issue 23): one after a later-numbered package and
// slower than the slowest recent first copies by more than the reorder
// tolerance, the very first numbers included (they are counted as reordered:
// their loss cannot be judged); not a reordered copy within the tolerance,
// not one in order, not a duplicate.
TEST(LinkHealth, SaysWhichPackagesCameAsRetransmissions) {
  LinkHealth h;
  const auto send = [&](std::int64_t seq, int sent_ms, int transit_ms) {
    return h.OnPackage(seq, false, At(milliseconds(sent_ms)), At(milliseconds(sent_ms + transit_ms)),
                       Duration(0));
  };
  EXPECT_FALSE(send(2, 10, 20)) << "the first that came";
  EXPECT_TRUE(send(1, 0, 120)) << "sent before it, 100 ms slower: its first copy was lost";
  EXPECT_FALSE(send(3, 20, 20));
  EXPECT_FALSE(send(5, 40, 20));
  EXPECT_FALSE(send(4, 30, 45)) << "reordered, 25 ms slower: within the 50 ms tolerance";
  EXPECT_FALSE(send(7, 60, 20));
  EXPECT_TRUE(send(6, 50, 150)) << "a retransmission 130 ms slower";
  EXPECT_FALSE(send(8, 70, 300)) << "in order: slow, not resent";
  EXPECT_FALSE(h.OnPackage(8, true, At(milliseconds(70)), At(milliseconds(400)), Duration(0)))
      << "a duplicate";
  EXPECT_EQ(h.Figures().retransmitted, 1u) << "the first number's copy counts as reordered";
}

}  // namespace
}  // namespace robotalk
