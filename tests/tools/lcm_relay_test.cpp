// Tests of the impairment relay's pure parts: ImpairedChannel, EchoFilter and
// the option parser (tools/lcm_relay). All deterministic: fixed seeds and
// synthetic arrival times, no clock, no network.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>
#include <vector>

#include "echo_filter.h"
#include "impaired_channel.h"
#include "queue_bound.h"
#include "relay_options.h"

namespace robotalk::relay {
namespace {

using std::chrono::milliseconds;

const TimePoint kStart = TimePoint(std::chrono::seconds(1000));

// Arrivals every `interval`, starting at kStart.
std::vector<Releases> Feed(ImpairedChannel& channel, int n, Duration interval) {
  std::vector<Releases> out;
  out.reserve(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) out.push_back(channel.Admit(kStart + i * interval));
  return out;
}

double Ms(Duration d) { return ToSeconds(d) * 1e3; }

ImpairmentParams Everything() {
  ImpairmentParams p;
  p.latency = milliseconds(20);
  p.jitter = milliseconds(5);
  p.loss = 0.1;
  p.duplicate = 0.05;
  p.reorder = 0.1;
  p.reorder_delay = milliseconds(30);
  p.congestion_max = milliseconds(8);
  return p;
}

TEST(ImpairedChannel, WithoutImpairmentsReleasesEveryMessageOnceInOrderWithNoDelay) {
  ImpairedChannel channel(ImpairmentParams{}, 42);
  const auto releases = Feed(channel, 1000, milliseconds(1));
  for (int i = 0; i < 1000; ++i) {
    ASSERT_EQ(releases[i].count, 1);
    EXPECT_EQ(releases[i].at[0], kStart + i * milliseconds(1));
  }
  // Several at the same instant: still one each, no delay.
  EXPECT_EQ(channel.Admit(kStart).at[0], kStart);
  EXPECT_EQ(channel.stats().copies, 1001u);
}

TEST(ImpairedChannel, SameSeedGivesTheSameScheduleAndAnotherSeedAnother) {
  ImpairedChannel a(Everything(), 7), b(Everything(), 7), c(Everything(), 8);
  const auto ra = Feed(a, 2000, milliseconds(10));
  const auto rb = Feed(b, 2000, milliseconds(10));
  const auto rc = Feed(c, 2000, milliseconds(10));
  bool differs = false;
  for (int i = 0; i < 2000; ++i) {
    ASSERT_EQ(ra[i].count, rb[i].count) << i;
    for (int k = 0; k < ra[i].count; ++k) ASSERT_EQ(ra[i].at[k], rb[i].at[k]) << i;
    differs = differs || ra[i].count != rc[i].count || (ra[i].count > 0 && ra[i].at[0] != rc[i].at[0]);
  }
  EXPECT_TRUE(differs);
}

TEST(ImpairedChannel, NormalJitterScheduleIsReproducibleToo) {
  ImpairmentParams p = Everything();
  p.jitter_distribution = JitterDistribution::kNormal;
  ImpairedChannel a(p, 99), b(p, 99);
  const auto ra = Feed(a, 500, milliseconds(10));
  const auto rb = Feed(b, 500, milliseconds(10));
  for (int i = 0; i < 500; ++i) {
    ASSERT_EQ(ra[i].count, rb[i].count);
    for (int k = 0; k < ra[i].count; ++k) ASSERT_EQ(ra[i].at[k], rb[i].at[k]);
  }
}

TEST(ImpairedChannel, LossAndDuplicationRatesAreCloseToConfiguredOverTenThousandMessages) {
  ImpairmentParams p;
  p.loss = 0.1;
  p.duplicate = 0.05;
  ImpairedChannel channel(p, 1);
  const int n = 10000;
  Feed(channel, n, milliseconds(1));
  // Binomial standard deviations: sqrt(n p (1-p)) = 30 for loss, ~21 for dup
  // among the ~9000 kept; allow 4 of them.
  EXPECT_NEAR(static_cast<double>(channel.stats().lost), 1000.0, 120.0);
  const double kept = n - static_cast<double>(channel.stats().lost);
  EXPECT_NEAR(static_cast<double>(channel.stats().duplicated), 0.05 * kept,
              4 * std::sqrt(kept * 0.05 * 0.95));
  EXPECT_EQ(channel.stats().copies, static_cast<std::uint64_t>(kept) + channel.stats().duplicated);
}

TEST(ImpairedChannel, LossPatternDoesNotDependOnTheOtherParameters) {
  ImpairmentParams lossy;
  lossy.loss = 0.3;
  ImpairmentParams lossy_and_slow = Everything();
  lossy_and_slow.loss = 0.3;
  ImpairedChannel a(lossy, 5), b(lossy_and_slow, 5);
  const auto ra = Feed(a, 3000, milliseconds(3));
  const auto rb = Feed(b, 3000, milliseconds(3));
  for (int i = 0; i < 3000; ++i) ASSERT_EQ(ra[i].lost, rb[i].lost) << i;
}

TEST(ImpairedChannel, UniformJitterStaysWithinLatencyPlusOrMinusJitterAndCoversIt) {
  ImpairmentParams p;
  p.latency = milliseconds(50);
  p.jitter = milliseconds(10);
  ImpairedChannel channel(p, 3);
  const auto releases = Feed(channel, 10000, milliseconds(1));
  double lo = 1e9, hi = 0, sum = 0;
  for (int i = 0; i < 10000; ++i) {
    const double d = Ms(releases[i].at[0] - (kStart + i * milliseconds(1)));
    lo = std::min(lo, d);
    hi = std::max(hi, d);
    sum += d;
  }
  EXPECT_GE(lo, 40.0);
  EXPECT_LE(hi, 60.0);
  EXPECT_LT(lo, 40.1);
  EXPECT_GT(hi, 59.9);
  EXPECT_NEAR(sum / 10000, 50.0, 0.2);  // sd of the mean: 10/sqrt(3)/100 = 0.06 ms
}

TEST(ImpairedChannel, NormalJitterHasTheConfiguredSigmaAndIsClampedAtThreeSigma) {
  ImpairmentParams p;
  p.latency = milliseconds(50);
  p.jitter = milliseconds(5);
  p.jitter_distribution = JitterDistribution::kNormal;
  ImpairedChannel channel(p, 11);
  const auto releases = Feed(channel, 10000, milliseconds(1));
  std::vector<double> d;
  for (int i = 0; i < 10000; ++i) d.push_back(Ms(releases[i].at[0] - (kStart + i * milliseconds(1))));
  const double mean = std::accumulate(d.begin(), d.end(), 0.0) / 10000;
  double var = 0;
  for (double x : d) var += (x - mean) * (x - mean);
  EXPECT_NEAR(mean, 50.0, 0.2);
  EXPECT_NEAR(std::sqrt(var / 9999), 5.0, 0.15);
  EXPECT_GE(*std::min_element(d.begin(), d.end()), 35.0);
  EXPECT_LE(*std::max_element(d.begin(), d.end()), 65.0);
}

TEST(ImpairedChannel, JitterLargerThanLatencyNeverReleasesBeforeArrival) {
  ImpairmentParams p;
  p.latency = milliseconds(1);
  p.jitter = milliseconds(5);
  ImpairedChannel channel(p, 4);
  const auto releases = Feed(channel, 2000, milliseconds(1));
  int at_arrival = 0;
  for (int i = 0; i < 2000; ++i) {
    const TimePoint arrival = kStart + i * milliseconds(1);
    ASSERT_GE(releases[i].at[0], arrival);
    at_arrival += releases[i].at[0] == arrival;
  }
  EXPECT_GT(at_arrival, 600);  // P(latency + U[-5, 5] < 0) = 0.4
}

TEST(ImpairedChannel, ReorderingHoldsBackTheConfiguredShareAndReordersTheStream) {
  ImpairmentParams p;
  p.latency = milliseconds(10);
  p.reorder = 0.2;
  p.reorder_delay = milliseconds(35);
  ImpairedChannel channel(p, 9);
  const int n = 5000;
  const auto releases = Feed(channel, n, milliseconds(10));
  int held = 0;
  for (int i = 0; i < n; ++i) {
    const Duration delay = releases[i].at[0] - (kStart + i * milliseconds(10));
    EXPECT_EQ(delay, releases[i].reordered[0] ? milliseconds(45) : milliseconds(10));
    held += releases[i].reordered[0];
  }
  EXPECT_NEAR(held, 0.2 * n, 4 * std::sqrt(n * 0.2 * 0.8));
  // Release order differs from arrival order: a held message is overtaken by
  // the next three.
  std::vector<int> order(n);
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(),
                   [&](int a, int b) { return releases[a].at[0] < releases[b].at[0]; });
  int inversions = 0;
  for (int i = 1; i < n; ++i) inversions += order[i] < order[i - 1];
  EXPECT_GT(inversions, n / 10);
}

// The congested link is a D/U/1 queue: arrivals every T, service U[0, X]
// (mean X/2, utilisation rho = X / 2T). Lindley: the backlog
// W_k = link_exit_k - arrival_k = max(0, W_{k-1} - T) + S_k.
std::vector<double> Backlogs(Duration interval, Duration x, int n, std::uint64_t seed) {
  ImpairmentParams p;
  p.congestion_max = x;
  ImpairedChannel channel(p, seed);
  const auto releases = Feed(channel, n, interval);
  std::vector<double> w;
  for (int i = 0; i < n; ++i) w.push_back(Ms(releases[i].at[0] - (kStart + i * interval)));
  return w;
}

double Mean(const std::vector<double>& v, std::size_t from, std::size_t to) {
  return std::accumulate(v.begin() + static_cast<long>(from), v.begin() + static_cast<long>(to), 0.0) /
         static_cast<double>(to - from);
}

TEST(ImpairedChannel, CongestionWithServiceUpToTheSendIntervalHoldsEachMessageButNeverQueues) {
  // X = T: a service never outlasts the gap to the next arrival, so no
  // message waits for another: the backlog is just the service time, in
  // [0, X], mean X/2, and does not grow.
  const auto w = Backlogs(milliseconds(100), milliseconds(100), 10000, 2);
  EXPECT_LE(*std::max_element(w.begin(), w.end()), 100.0);
  EXPECT_NEAR(Mean(w, 0, 10000), 50.0, 1.5);
  EXPECT_NEAR(Mean(w, 9000, 10000), Mean(w, 0, 1000), 5.0);
}

TEST(ImpairedChannel, CongestionAtTwiceTheSendIntervalGrowsTheBacklogLikeARandomWalk) {
  // X = 2T: rho = 1, critically loaded; the backlog is a reflected random
  // walk with step sd X/sqrt(12), so it grows like sqrt(k), without bound.
  const auto w = Backlogs(milliseconds(100), milliseconds(200), 10000, 2);
  const double early = Mean(w, 0, 100), late = Mean(w, 9000, 10000);
  EXPECT_GT(late, 4 * early);
  EXPECT_GT(late, 1000.0);  // E|walk| after 9500 steps ~ 57.7 ms * sqrt(2*9500/pi) = 4.5 s
}

TEST(ImpairedChannel, CongestionBeyondTwiceTheSendIntervalGrowsTheBacklogLinearly) {
  // X = 3T: each message adds X/2 - T = 50 ms of backlog on average.
  const auto w = Backlogs(milliseconds(100), milliseconds(300), 2000, 2);
  EXPECT_NEAR(w[1999] / 1999, 50.0, 3.0);  // sd of the slope: 86.6 / sqrt(2000) = 1.9 ms
  for (int k = 200; k < 2000; k += 200) EXPECT_GT(w[k], w[k - 200]) << k;
}

TEST(ImpairedChannel, CongestionKeepsFifoOrderAndAddsLatencyAfterTheLink) {
  ImpairmentParams p;
  p.congestion_max = milliseconds(150);
  p.latency = milliseconds(20);
  ImpairedChannel channel(p, 6);
  const auto r = Feed(channel, 1000, milliseconds(100));
  for (int i = 0; i < 1000; ++i) {
    EXPECT_EQ(r[i].at[0], r[i].link_exit + milliseconds(20));
    if (i > 0) {
      EXPECT_GE(r[i].link_exit, r[i - 1].link_exit);
    }
  }
  EXPECT_EQ(channel.link_free_at(), r[999].link_exit);
}

TEST(ImpairedChannel, DuplicateCopiesHaveTheirOwnDelay) {
  ImpairmentParams p;
  p.duplicate = 1.0;
  p.latency = milliseconds(10);
  p.jitter = milliseconds(5);
  ImpairedChannel channel(p, 12);
  const auto r = Feed(channel, 200, milliseconds(1));
  int different = 0;
  for (const auto& x : r) {
    ASSERT_EQ(x.count, 2);
    different += x.at[0] != x.at[1];
  }
  EXPECT_GT(different, 190);
}

// Issue 23: a stalled link holds what arrives in its window and then lets it
// all go at once; before and after, nothing changes; no random number is drawn.
TEST(ImpairedChannel, AnOutageHoldsItsWindowAndReleasesItAsABurst) {
  ImpairmentParams p;
  p.latency = milliseconds(10);
  p.outage_at = milliseconds(1000);
  p.outage = milliseconds(500);
  ImpairedChannel channel(p, 3);
  const std::vector<Releases> r = Feed(channel, 30, milliseconds(100));  // arrivals 0 .. 2.9 s
  for (int i = 0; i < 30; ++i) {
    const TimePoint arrival = kStart + i * milliseconds(100);
    const bool held = i >= 10 && i < 15;  // arrivals in [1.0, 1.5) s
    EXPECT_EQ(r[static_cast<std::size_t>(i)].at[0],
              held ? kStart + milliseconds(1500) : arrival + milliseconds(10))
        << "message " << i;
  }
  EXPECT_EQ(channel.stats().held, 5u);
  ImpairedChannel plain(Everything(), 9), stalled(
                                              [] {
                                                ImpairmentParams q = Everything();
                                                q.outage_at = milliseconds(50);
                                                q.outage = milliseconds(100);
                                                return q;
                                              }(),
                                              9);
  const std::vector<Releases> a = Feed(plain, 200, milliseconds(10)),
                              b = Feed(stalled, 200, milliseconds(10));
  for (std::size_t i = 0; i < a.size(); ++i)
    EXPECT_EQ(a[i].lost, b[i].lost) << "the same fates, message " << i;
  EXPECT_THROW(ImpairedChannel(
                   [] {
                     ImpairmentParams q;
                     q.outage = -milliseconds(1);
                     return q;
                   }(),
                   1),
               std::invalid_argument);
}

TEST(ImpairedChannel, RejectsOutOfRangeParametersNamingTheField) {
  ImpairmentParams p;
  p.loss = 1.5;
  try {
    ImpairedChannel channel(p, 1);
    FAIL() << "no throw";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("loss"), std::string::npos) << e.what();
  }
  p.loss = 0;
  p.latency = milliseconds(-1);
  EXPECT_THROW(Validate(p), std::invalid_argument);
}

TEST(EchoFilter, RecognisesEachExpectedCopyOnceAndNothingElse) {
  EchoFilter f(milliseconds(100));
  const char data[] = "abc";
  const auto fp = Fingerprint("CH", data, 3);
  EXPECT_NE(fp, Fingerprint("CH2", data, 3));
  EXPECT_NE(fp, Fingerprint("CH", data, 2));
  f.Expect(fp, kStart);
  f.Expect(fp, kStart);  // a duplicated release
  EXPECT_FALSE(f.ConsumeIfEcho(fp + 1, kStart));
  EXPECT_TRUE(f.ConsumeIfEcho(fp, kStart + milliseconds(1)));
  EXPECT_TRUE(f.ConsumeIfEcho(fp, kStart + milliseconds(1)));
  EXPECT_FALSE(f.ConsumeIfEcho(fp, kStart + milliseconds(2)));  // a genuine message after the echoes
}

TEST(EchoFilter, ForgetsExpectationsAfterTheWindowAndBeyondItsCapacity) {
  EchoFilter f(milliseconds(100), 2);
  f.Expect(1, kStart);
  EXPECT_FALSE(f.ConsumeIfEcho(1, kStart + milliseconds(101)));
  f.Expect(2, kStart);
  f.Expect(3, kStart);
  f.Expect(4, kStart);  // capacity 2: 2 is forgotten
  EXPECT_FALSE(f.ConsumeIfEcho(2, kStart));
  EXPECT_TRUE(f.ConsumeIfEcho(3, kStart));
  EXPECT_TRUE(f.ConsumeIfEcho(4, kStart));
}

RelayOptions Parse(std::vector<std::string> extra) {
  std::vector<std::string> args = {"--a", "udpm://239.255.76.67:7701?ttl=0", "--b",
                                   "udpm://239.255.76.67:7801?ttl=0"};
  args.insert(args.end(), extra.begin(), extra.end());
  return ParseRelayOptions(args);
}

TEST(RelayOptions, DefaultsForwardEverythingUnimpairedWithSeedOne) {
  const RelayOptions o = Parse({});
  EXPECT_EQ(o.seed, 1u);
  EXPECT_EQ(o.a2b.channels, ".*");
  EXPECT_EQ(o.b2a.impairment.latency, Duration::zero());
  EXPECT_EQ(o.a2b.impairment.loss, 0.0);
  EXPECT_FALSE(o.stats);
  EXPECT_NE(DerivedSeed(1), 1u);
}

TEST(RelayOptions, TheReleaseQueueIsBoundedByDefaultAndTheBoundIsAnOption) {
  EXPECT_EQ(Parse({}).queue.max_messages, kDefaultMaxQueueMessages);
  EXPECT_EQ(Parse({}).queue.max_bytes, kDefaultMaxQueueBytes);
  const RelayOptions o = Parse({"--max-queue", "10", "--max-queue-bytes=4096"});
  EXPECT_EQ(o.queue.max_messages, 10u);
  EXPECT_EQ(o.queue.max_bytes, 4096u);
}

// gaps14: the congestion model's backlog grows without bound when messages
// arrive faster than the link serves them; the release queue holding them
// is bounded in messages and bytes, what arrives past it dropped and counted.
TEST(QueueBound, DropsAndCountsWhatWouldPassEitherLimitAndTakesMoreOnceReleased) {
  QueueBound count({.max_messages = 3, .max_bytes = 1000});
  for (int i = 0; i < 3; ++i) EXPECT_TRUE(count.TryAdmit(10));
  EXPECT_FALSE(count.TryAdmit(10)) << "a fourth message";
  EXPECT_FALSE(count.TryAdmit(0));
  EXPECT_EQ(count.dropped(), 2u);
  count.Release(10);
  EXPECT_TRUE(count.TryAdmit(10)) << "room again once one left";
  EXPECT_EQ(count.messages(), 3u);
  EXPECT_EQ(count.bytes(), 30u);

  QueueBound bytes({.max_messages = 100, .max_bytes = 100});
  EXPECT_TRUE(bytes.TryAdmit(60));
  EXPECT_FALSE(bytes.TryAdmit(41)) << "101 bytes";
  EXPECT_TRUE(bytes.TryAdmit(40)) << "exactly 100";
  EXPECT_FALSE(bytes.TryAdmit(static_cast<std::size_t>(-1))) << "no overflow of the sum";
  EXPECT_EQ(bytes.dropped(), 2u);
  EXPECT_EQ(bytes.bytes(), 100u);
}

// The congestion model with a bound: messages arriving twice as fast as the
// link serves them keep at most the bound queued (the backlog of the model
// alone grows linearly, CongestionBeyondTwiceTheSendIntervalGrowsTheBacklogLinearly).
TEST(QueueBound, KeepsTheCongestedLinksBacklogBounded) {
  ImpairmentParams p;
  p.congestion_max = std::chrono::milliseconds(40);  // mean service 20 ms
  ImpairedChannel channel(p, 7);
  QueueBound bound({.max_messages = 50, .max_bytes = 1 << 20});
  std::vector<TimePoint> queued;  // release times
  std::size_t most = 0;
  for (int i = 0; i < 5000; ++i) {
    const TimePoint now = TimePoint{} + std::chrono::milliseconds(10) * i;
    std::erase_if(queued, [&](TimePoint at) {
      if (at > now) return false;
      bound.Release(100);
      return true;
    });
    if (!bound.TryAdmit(100)) continue;
    const Releases r = channel.Admit(now);
    queued.push_back(r.at[0]);
    most = std::max(most, queued.size());
  }
  EXPECT_LE(most, 50u);
  EXPECT_GT(bound.dropped(), 1000u) << "about half of 5,000 past the link's rate";
  EXPECT_LE(channel.link_free_at() - (TimePoint{} + std::chrono::milliseconds(10) * 4999),
            std::chrono::seconds(2))
      << "the backlog stays within the bound's worth of service (50 x 40 ms at most)";
}

TEST(RelayOptions, PerDirectionOptionsWinOverSharedOnesInAnyOrder) {
  const RelayOptions o =
      Parse({"--a2b-loss", "0.25", "--loss", "0.1", "--latency-ms=40", "--b2a-latency-ms", "5",
             "--congestion-max-ms", "100", "--jitter-dist", "normal", "--a2b-channels", "ROBOTALK/.*",
             "--seed", "17", "--stats", "--duration", "2.5"});
  EXPECT_DOUBLE_EQ(o.a2b.impairment.loss, 0.25);
  EXPECT_DOUBLE_EQ(o.b2a.impairment.loss, 0.1);
  EXPECT_EQ(o.a2b.impairment.latency, milliseconds(40));
  EXPECT_EQ(o.b2a.impairment.latency, milliseconds(5));
  EXPECT_EQ(o.b2a.impairment.congestion_max, milliseconds(100));
  EXPECT_EQ(o.a2b.impairment.jitter_distribution, JitterDistribution::kNormal);
  EXPECT_EQ(o.a2b.channels, "ROBOTALK/.*");
  EXPECT_EQ(o.b2a.channels, ".*");
  EXPECT_EQ(o.seed, 17u);
  EXPECT_TRUE(o.stats);
  EXPECT_DOUBLE_EQ(o.duration_s, 2.5);
}

TEST(RelayOptions, TheWanProfileSetsBothDirectionsAndOtherOptionsOverrideIt) {
  const std::vector<std::string> base = {"--a", "udpm://239.255.76.67:7100", "--b",
                                         "udpm://239.255.76.67:7300"};
  auto with = [&](std::vector<std::string> extra) {
    extra.insert(extra.begin(), base.begin(), base.end());
    return ParseRelayOptions(extra);
  };
  const RelayOptions wan = with({"--profile", "wan"});
  for (const DirectionOptions* d : {&wan.a2b, &wan.b2a}) {
    EXPECT_EQ(d->impairment.latency, std::chrono::milliseconds(100));
    EXPECT_EQ(d->impairment.jitter, std::chrono::milliseconds(50));
    EXPECT_EQ(d->impairment.jitter_distribution, JitterDistribution::kUniform);
    EXPECT_DOUBLE_EQ(d->impairment.loss, 0.01);
  }
  EXPECT_EQ(with({"--profile", "wan-300"}).b2a.impairment.latency, std::chrono::milliseconds(300));
  // Given before or after the profile, an option overrides its part.
  const RelayOptions o = with({"--loss", "0", "--profile", "wan", "--b2a-latency-ms", "5"});
  EXPECT_DOUBLE_EQ(o.a2b.impairment.loss, 0.0);
  EXPECT_EQ(o.a2b.impairment.latency, std::chrono::milliseconds(100));
  EXPECT_EQ(o.b2a.impairment.latency, std::chrono::milliseconds(5));
  EXPECT_EQ(o.b2a.impairment.jitter, std::chrono::milliseconds(50));
  try {
    with({"--profile", "moon"});
    ADD_FAILURE() << "an unknown profile was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("--profile 'moon'"), std::string::npos) << e.what();
  }
}

TEST(RelayOptions, RejectsBadValuesNamingTheOption) {
  for (const std::vector<std::string>& bad : {std::vector<std::string>{"--loss", "1.2"},
                                              {"--dup", "x"},
                                              {"--latency-ms", "-1"},
                                              {"--a2b-jitter-dist", "pareto"},
                                              {"--channels", "("},
                                              {"--frobnicate", "1"},
                                              {"--c2d-loss", "0.1"},
                                              {"--seed", "-3"},
                                              {"--max-queue", "0"},
                                              {"--max-queue", "2.5"},
                                              {"--max-queue-bytes", "-1"},
                                              {"--a2b-max-queue", "10"},
                                              {"--loss"}}) {
    try {
      Parse(bad);
      ADD_FAILURE() << "accepted " << bad[0];
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(bad[0]), std::string::npos) << e.what();
    }
  }
}

TEST(RelayOptions, RefusesUrlsThatWouldHearEachOther) {
  EXPECT_THROW(ParseRelayOptions({"--a", "udpm://239.255.76.67:7701", "--b", "udpm://239.255.76.67:7701"}),
               std::invalid_argument);
  EXPECT_THROW(
      ParseRelayOptions({"--a", "udpm://239.255.76.67:7701?ttl=0", "--b", "udpm://239.255.76.68:7701"}),
      std::invalid_argument);
  EXPECT_THROW(ParseRelayOptions({"--a", "udpm://239.255.76.67"}), std::invalid_argument);
  // The split layout's lanes: 7701..7766 and 7702..7767 share 65 ports.
  EXPECT_THROW(
      ParseRelayOptions({"--a", "udpm://239.255.76.67:7701?ttl=0", "--b", "udpm://239.255.76.67:7702?ttl=0"}),
      std::invalid_argument);
  EXPECT_THROW(
      ParseRelayOptions({"--a", "udpm://239.255.76.67:7701?ttl=0", "--b", "udpm://239.255.76.67:7766?ttl=0"}),
      std::invalid_argument);
  EXPECT_NO_THROW(ParseRelayOptions(
      {"--a", "udpm://239.255.76.67:7701?ttl=0", "--b", "udpm://239.255.76.67:7767?ttl=0"}));
  // Single layouts use one port each.
  EXPECT_NO_THROW(ParseRelayOptions({"--a", "udpm://239.255.76.67:7701?ttl=0&traffic=single", "--b",
                                     "udpm://239.255.76.67:7702?ttl=0&traffic=single"}));
  EXPECT_THROW(ParseRelayOptions({"--a", "udpm://239.255.76.67:7701?traffic=maybe", "--b", "memq://"}),
               std::invalid_argument);
  EXPECT_EQ(UdpmPort("udpm://239.255.76.67?ttl=0"), 7667);
  EXPECT_EQ(UdpmPort("udpm://239.255.76.67:7702?ttl=0"), 7702);
  EXPECT_EQ(UdpmPort("memq://"), -1);
  EXPECT_TRUE(ParseRelayOptions({"--help"}).help);
}

TEST(RelayOptions, RelaysEveryLaneOfASplitUrlAndTheOneUrlOfASingleOne) {
  const std::vector<std::string> split = RelayLaneUrls("udpm://239.255.76.67:7701?ttl=0");
  ASSERT_EQ(split.size(), 66u);
  EXPECT_EQ(split.front(), "udpm://239.255.76.67:7701?ttl=0");
  EXPECT_EQ(split[1], "udpm://239.255.76.67:7702?ttl=0");
  EXPECT_EQ(split.back(), "udpm://239.255.76.67:7766?ttl=0");
  EXPECT_EQ(RelayLaneUrls("udpm://239.255.76.67:7701?traffic=single&ttl=0"),
            std::vector<std::string>{"udpm://239.255.76.67:7701?ttl=0"});
  EXPECT_EQ(RelayLaneUrls("memq://"), std::vector<std::string>{"memq://"});
}

}  // namespace
}  // namespace robotalk::relay
