#include "outstanding_packages.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <random>

namespace robotalk::client {
namespace {

using std::chrono::milliseconds;
using std::chrono::seconds;
const TimePoint kT0(seconds(1000));

RetransmitPolicy Policy() {
  return {.interval = milliseconds(100),
          .backoff = 2.0,
          .max_interval = milliseconds(400),
          .give_up_after = seconds(2)};
}
std::vector<std::uint8_t> Bytes(std::uint8_t b) { return {b, b, b}; }

// Times at which a package is resent when nothing ever answers, over `span`.
std::vector<Duration> ResendTimes(OutstandingPackages& o, Duration span) {
  std::vector<Duration> times;
  for (Duration t{0}; t <= span; t += milliseconds(10)) {
    if (!o.TakeDue(kT0 + t).empty()) times.push_back(t);
  }
  return times;
}

TEST(OutstandingPackages, ResendsAnUnackedPackageWithBackoff) {
  OutstandingPackages o(Policy());
  o.Add(1, Bytes(1), {{.id = 10}}, kT0);
  const auto times = ResendTimes(o, milliseconds(2000));
  // 100 ms, then doubling, capped at max_interval (400 ms); the timer
  // back-off of unanswered timeouts (RFC 6298 §5.5) stays within that cap.
  const std::vector<Duration> expected = {milliseconds(100),  milliseconds(300),  milliseconds(700),
                                          milliseconds(1100), milliseconds(1500), milliseconds(1900)};
  EXPECT_EQ(times, expected);
  EXPECT_EQ(o.retransmissions(), 6u);
}

// Issue 9 / 11: the shared back-off reached 6.4 s, past the 5 s give-up, so a
// command that ran was given up without a single resend in its last seconds.
TEST(OutstandingPackages, TheBackoffNeverOutlastsAQuarterOfTheGiveUpBound) {
  RetransmitPolicy policy = Policy();
  policy.max_interval = seconds(30);  // a careless setting
  OutstandingPackages o(policy);
  for (int i = 0; i < 50; ++i) o.Add(i + 1, Bytes(1), {{.id = i + 1}}, kT0);  // nothing ever answers
  const auto times = ResendTimes(o, milliseconds(1900));
  ASSERT_GE(times.size(), 4u);
  for (std::size_t i = 1; i < times.size(); ++i) {
    EXPECT_LE(times[i] - times[i - 1], policy.give_up_after / 4 + milliseconds(10)) << "gap " << i;
  }
  EXPECT_LE(o.retransmit_timeout(), policy.give_up_after / 4);
}

// Issue 11: 1,000 packages in flight were all resent in one burst into a
// receive buffer that had just overflowed.
TEST(OutstandingPackages, ABurstOfDuePackagesIsPaced) {
  OutstandingPackages o(Policy());
  for (int i = 0; i < 100; ++i) o.Add(i + 1, Bytes(1), {{.id = i + 1}}, kT0);
  const TimePoint due = kT0 + milliseconds(100);
  EXPECT_EQ(o.TakeDue(due).size(), 32u);
  EXPECT_TRUE(o.TakeDue(due).empty()) << "the rest wait their pacing step";
  std::size_t sent = 32;
  for (int ms = 1; ms <= 4; ++ms) {
    const std::size_t n = o.TakeDue(due + milliseconds(ms)).size();
    EXPECT_LE(n, 32u);
    sent += n;
  }
  EXPECT_EQ(sent, 100u) << "every package left within a few milliseconds";
}

// Issue 11: TakeDue scanned every outstanding package on every tick; the
// index hands out the most overdue first.
TEST(OutstandingPackages, ABurstIsResentEarliestDeadlineFirst) {
  OutstandingPackages o(Policy());
  for (int i = 40; i >= 1; --i) o.Add(i, Bytes(1), {{.id = i}}, kT0 + milliseconds(i));
  const auto due = o.TakeDue(kT0 + milliseconds(200));
  ASSERT_EQ(due.size(), 32u);
  for (std::size_t k = 0; k < due.size(); ++k) EXPECT_EQ(due[k].sequence, static_cast<std::int64_t>(k + 1));
  const auto rest = o.TakeDue(kT0 + milliseconds(201));
  ASSERT_EQ(rest.size(), 8u);
  EXPECT_EQ(rest.front().sequence, 33);
}

TEST(OutstandingPackages, NextDeadlineIsTheEarliestResendOrGiveUp) {
  OutstandingPackages o(Policy());
  EXPECT_EQ(o.NextDeadline(), TimePoint::max());
  o.Add(1, Bytes(1), {{.id = 10, .start = kT0 + seconds(30)}}, kT0);
  o.Add(2, Bytes(2), {{.id = 20}}, kT0 + milliseconds(50));
  EXPECT_EQ(o.NextDeadline(), kT0 + milliseconds(100)) << "package 1's first resend";
  o.OnAck(1, kT0 + milliseconds(60));  // now waits for its start time
  EXPECT_EQ(o.NextDeadline(), kT0 + milliseconds(150)) << "package 2's first resend";
  o.OnAck(2, kT0 + milliseconds(70));
  o.OnReply(20, kT0 + milliseconds(80));
  EXPECT_FALSE(o.Contains(2));
  // Re-asked one RTO after its start; the 60 ms round trip made the RTO
  // srtt + 4 rttvar = 60 + 4 × 30 ms.
  EXPECT_EQ(o.NextDeadline(), kT0 + seconds(30) + milliseconds(180)) << "re-ask after the start";
  EXPECT_TRUE(o.TakeDue(o.NextDeadline() - Duration(1)).empty());
  EXPECT_EQ(o.TakeDue(o.NextDeadline()).size(), 1u);
}

TEST(OutstandingPackages, GivesUpAtTheDeadlineItAnnounces) {
  OutstandingPackages o(Policy());
  o.Add(1, Bytes(1), {{.id = 10}}, kT0);
  o.Add(2, Bytes(2), {{.id = 20}}, kT0 + milliseconds(500));
  o.OnAck(1, kT0 + milliseconds(300));  // heard of at 300 ms: gives up 2 s later
  TimePoint t = kT0;
  std::vector<std::int64_t> order;
  for (int step = 0; step < 1000 && o.size() > 0; ++step) {
    t = o.NextDeadline();
    o.TakeDue(t);
    for (const auto& e : o.TakeExpired(t)) {
      order.push_back(e.sequence);
      EXPECT_EQ(t, (e.sequence == 1 ? kT0 + milliseconds(300) : kT0 + milliseconds(500)) + seconds(2) +
                       Duration(1));
    }
  }
  EXPECT_EQ(order, (std::vector<std::int64_t>{1, 2}));
}

TEST(OutstandingPackages, AFreshRoundTripResetsTheTimerBackoff) {
  OutstandingPackages o(Policy());
  o.Add(1, Bytes(1), {{.id = 10}}, kT0);
  ResendTimes(o, milliseconds(1200));
  EXPECT_GT(o.retransmit_timeout(), milliseconds(100)) << "timeouts backed the timer off";
  o.Add(2, Bytes(2), {{.id = 20}}, kT0 + milliseconds(1300));
  o.OnAck(2, kT0 + milliseconds(1330));  // sent once: a valid 30 ms sample
  EXPECT_EQ(o.retransmit_timeout(), milliseconds(100)) << "srtt + 4 rttvar = 90 ms, floored at the interval";
}

TEST(OutstandingPackages, AdaptsTheTimeoutToASlowServer) {
  OutstandingPackages o(Policy());
  for (int i = 0; i < 20; ++i) {
    const TimePoint sent = kT0 + seconds(i);
    o.Add(i + 1, Bytes(1), {{.id = i + 1}}, sent);
    o.OnAck(i + 1, sent + milliseconds(600));  // a congested server answers in 600 ms
  }
  EXPECT_GE(o.retransmit_timeout(), milliseconds(600)) << "no resend before an answer could come";
}

// Issue 23: the round trip every package reports (header round_trip_us) is
// the median of the recent network round trips: a late ack (this process
// busy) does not inflate it; a resent package gives no sample (Karn); old
// samples age out.
TEST(OutstandingPackages, ReportsTheMedianOfItsRecentRoundTrips) {
  OutstandingPackages o(Policy());
  EXPECT_EQ(o.reported_round_trip(), std::nullopt);
  std::int64_t seq = 0;
  const auto sample = [&](Duration rtt) {
    const TimePoint sent = kT0 + seconds(++seq);
    o.Add(seq, Bytes(1), {}, sent);
    o.OnAck(seq, sent + rtt);
  };
  for (int ms : {45, 40, 70, 41}) sample(milliseconds(ms));
  EXPECT_EQ(o.reported_round_trip(), milliseconds(43)) << "the mean of the middle two";
  sample(milliseconds(44));
  EXPECT_EQ(o.reported_round_trip(), milliseconds(44));
  const TimePoint sent = kT0 + seconds(++seq);
  o.Add(seq, Bytes(1), {}, sent);
  ASSERT_EQ(o.TakeDue(sent + milliseconds(100)).size(), 1u);
  o.OnAck(seq, sent + seconds(5));  // resent: which copy does this ack answer?
  EXPECT_EQ(o.reported_round_trip(), milliseconds(44)) << "Karn: no sample";
  for (int i = 0; i < 11; ++i) sample(milliseconds(60));  // 1 s apart: the window is 10 s
  EXPECT_EQ(o.reported_round_trip(), milliseconds(60)) << "the old samples aged out";
}

// Issue 23's link health, the client's half: a link simulated on a manual
// clock, one package every 5 ms, each acknowledged. `up` and `down` draw the
// network's one-way delays; the server holds each package a while before its
// ack leaves (it says how long: server_send - server_receive), this process
// handles the ack late (its socket stamps the arrival), and 1 % of the
// packages wait 30 ms for the server's thread, which nobody measures. Half
// the reported round trip must be the mean one-way delay the link drew.
struct LinkRun {
  Duration reported_half{0};
  Duration mean_one_way{0};
};
template <typename Up, typename Down>
LinkRun RunLink(Up up, Down down, std::mt19937_64& rng) {
  OutstandingPackages o(Policy());
  std::bernoulli_distribution often(0.3), rarely(0.01);
  std::uniform_int_distribution<int> spike_us(0, 50000), small_us(0, 1000);
  Duration network{0};
  const int n = 2000;
  for (int i = 1; i <= n; ++i) {
    const TimePoint sent = kT0 + milliseconds(5 * i);
    const Duration u = up(rng), d = down(rng);
    network += u + d;
    const Duration hold = std::chrono::microseconds(often(rng) ? spike_us(rng) : small_us(rng));
    const Duration busy = std::chrono::microseconds(often(rng) ? spike_us(rng) : small_us(rng));
    const Duration unseen = rarely(rng) ? milliseconds(30) : Duration(0);
    const TimePoint arrived = sent + u + unseen + hold + d;
    o.Add(i, Bytes(1), {}, sent);
    o.OnAck(i, arrived + busy, OutstandingPackages::AckTiming{.received = arrived, .server_hold = hold});
  }
  EXPECT_TRUE(o.reported_round_trip().has_value());
  return {o.reported_round_trip().value_or(Duration(0)) / 2, network / (2 * n)};
}
std::function<Duration(std::mt19937_64&)> UniformMs(double mean, double half_width) {
  return [=](std::mt19937_64& rng) {
    return std::chrono::microseconds(std::llround(
        1000 * std::uniform_real_distribution<double>(mean - half_width, mean + half_width)(rng)));
  };
}

TEST(OutstandingPackages, HalfTheReportedRoundTripIsTheMeanDelayOfAJitteredLink) {
  std::mt19937_64 rng(23);
  // The WAN profile: 100 ms +- 50 ms, independently each way.
  const LinkRun wan = RunLink(UniformMs(100, 50), UniformMs(100, 50), rng);
  EXPECT_NEAR(ToSeconds(wan.reported_half), ToSeconds(wan.mean_one_way), 0.002);
  EXPECT_NEAR(ToSeconds(wan.reported_half), 0.100, 0.002);
  // A fixed 20 ms each way: exact, whatever the processing.
  const LinkRun fixed = RunLink(UniformMs(20, 0), UniformMs(20, 0), rng);
  EXPECT_EQ(fixed.reported_half, milliseconds(20));
}

// Without synchronised clocks no one can split a round trip into its two
// ways: on an asymmetric link the reported one-way delay is the mean of the
// two directions' means (docs/server.md, Link health).
TEST(OutstandingPackages, OnAnAsymmetricLinkHalfTheRoundTripIsTheMeanOfBothWays) {
  std::mt19937_64 rng(7);
  const LinkRun r = RunLink(UniformMs(30, 10), UniformMs(10, 5), rng);
  EXPECT_NEAR(ToSeconds(r.reported_half), 0.020, 0.002);
  EXPECT_NEAR(ToSeconds(r.reported_half), ToSeconds(r.mean_one_way), 0.002);
}

TEST(OutstandingPackages, ResendUsesTheSameBytes) {
  OutstandingPackages o(Policy());
  o.Add(7, Bytes(7), {{.id = 1}}, kT0);
  auto due = o.TakeDue(kT0 + milliseconds(100));
  ASSERT_EQ(due.size(), 1u);
  EXPECT_EQ(due[0].sequence, 7);
  EXPECT_EQ(due[0].bytes, Bytes(7));
}

TEST(OutstandingPackages, AckedAndAnsweredPackageIsForgotten) {
  OutstandingPackages o(Policy());
  o.Add(1, Bytes(1), {{.id = 10}, {.id = 11}}, kT0);
  auto ack = o.OnAck(1, kT0 + milliseconds(5));
  EXPECT_TRUE(ack.known);
  EXPECT_TRUE(ack.first);
  EXPECT_FALSE(ack.retransmitted);
  EXPECT_FALSE(ack.completed);
  EXPECT_FALSE(o.OnReply(11, kT0 + milliseconds(6)).has_value());
  EXPECT_EQ(o.OnReply(10, kT0 + milliseconds(7)), 1);
  EXPECT_EQ(o.size(), 0u);
  EXPECT_TRUE(o.TakeDue(kT0 + seconds(10)).empty());
}

// Issue 19 item 8: why a server that forgot a package's replies must still
// answer its items. Acknowledgements alone keep an acked package alive (a
// long GOTO is re-asked about this way), so the client would ask forever;
// the server's answer for a forgotten item (ERROR, outcome unknown) ends it.
TEST(OutstandingPackages, AcksWithoutTheReplyKeepAskingAndTheServersAnswerForAForgottenItemEndsIt) {
  OutstandingPackages o(Policy());
  o.Add(1, Bytes(1), {{.id = 10}}, kT0);
  o.OnAck(1, kT0 + milliseconds(5));
  int resends = 0;
  for (Duration t = milliseconds(10); t < seconds(60); t += milliseconds(10)) {
    if (!o.TakeDue(kT0 + t).empty()) {
      ++resends;
      o.OnAck(1, kT0 + t + milliseconds(1));  // the server re-acks, with no reply
    }
    ASSERT_TRUE(o.TakeExpired(kT0 + t).empty()) << "never given up while acked";
  }
  EXPECT_GT(resends, 100);
  EXPECT_EQ(o.OnReply(10, kT0 + seconds(60)), 1) << "the answer completes the package";
  EXPECT_EQ(o.size(), 0u);
}

TEST(OutstandingPackages, PackageWithoutItemsCompletesOnItsAck) {
  OutstandingPackages o(Policy());
  o.Add(3, Bytes(3), {}, kT0);  // a panic package
  EXPECT_TRUE(o.OnAck(3, kT0 + milliseconds(1)).completed);
  EXPECT_FALSE(o.Contains(3));
}

TEST(OutstandingPackages, SecondAckIsNotFirstAndRetransmissionIsReported) {
  OutstandingPackages o(Policy());
  o.Add(1, Bytes(1), {{.id = 10}}, kT0);
  o.TakeDue(kT0 + milliseconds(100));
  auto a1 = o.OnAck(1, kT0 + milliseconds(120));
  EXPECT_TRUE(a1.first);
  EXPECT_TRUE(a1.retransmitted);
  EXPECT_FALSE(o.OnAck(1, kT0 + milliseconds(130)).first);
  EXPECT_FALSE(o.OnAck(99, kT0).known);
}

TEST(OutstandingPackages, AckedPackageWaitsForTheStartTimeBeforeAskingAgain) {
  OutstandingPackages o(Policy());
  o.Add(1, Bytes(1), {{.id = 10, .start = kT0 + seconds(3)}}, kT0);
  o.OnAck(1, kT0 + milliseconds(10));
  // Nothing before the start time (+ one interval).
  for (Duration t = milliseconds(20); t < seconds(3) + milliseconds(100); t += milliseconds(10)) {
    ASSERT_TRUE(o.TakeDue(kT0 + t).empty()) << "resent at " << ToSeconds(t);
  }
  EXPECT_EQ(o.TakeDue(kT0 + seconds(3) + milliseconds(100)).size(), 1u);
  // Not given up while waiting for the start either.
  EXPECT_TRUE(o.TakeExpired(kT0 + seconds(3)).empty());
}

TEST(OutstandingPackages, UnackedFutureCommandIsResentAtOnce) {
  OutstandingPackages o(Policy());
  o.Add(1, Bytes(1), {{.id = 10, .start = kT0 + seconds(30)}}, kT0);
  EXPECT_EQ(o.TakeDue(kT0 + milliseconds(100)).size(), 1u);
}

TEST(OutstandingPackages, AReplyCountsAsAnAck) {
  OutstandingPackages o(Policy());
  o.Add(1, Bytes(1), {{.id = 10}, {.id = 11}}, kT0);
  o.OnReply(10, kT0 + milliseconds(50));
  EXPECT_TRUE(o.IsAcked(1));
}

TEST(OutstandingPackages, GivesUpOnASilentServerAndReturnsTheUnansweredItems) {
  OutstandingPackages o(Policy());
  o.Add(1, Bytes(1), {{.id = 11}, {.id = 10}, {.id = 12}}, kT0);
  o.OnReply(12, kT0 + milliseconds(10));
  EXPECT_TRUE(o.TakeExpired(kT0 + seconds(2)).empty());
  auto expired = o.TakeExpired(kT0 + seconds(2) + milliseconds(20));
  ASSERT_EQ(expired.size(), 1u);
  EXPECT_EQ(expired[0].sequence, 1);
  EXPECT_TRUE(expired[0].acked);
  EXPECT_EQ(expired[0].unanswered, (std::vector<CommandId>{10, 11}));
  EXPECT_EQ(o.size(), 0u);
  // A late reply for a given-up item belongs to nothing.
  EXPECT_FALSE(o.OnReply(10, kT0 + seconds(3)).has_value());
}

TEST(OutstandingPackages, AnAckKeepsAPackageAlive) {
  OutstandingPackages o(Policy());
  o.Add(1, Bytes(1), {{.id = 10}}, kT0);  // a long GOTO: acked again on every resend
  for (int s = 1; s <= 10; ++s) {
    o.OnAck(1, kT0 + seconds(s));
    EXPECT_TRUE(o.TakeExpired(kT0 + seconds(s) + milliseconds(500)).empty());
  }
}

TEST(OutstandingPackages, ClearReturnsEveryUnansweredItem) {
  OutstandingPackages o(Policy());
  o.Add(1, Bytes(1), {{.id = 1}, {.id = 2}}, kT0);
  o.Add(2, Bytes(2), {{.id = 3}}, kT0);
  auto ids = o.Clear();
  std::sort(ids.begin(), ids.end());
  EXPECT_EQ(ids, (std::vector<CommandId>{1, 2, 3}));
  EXPECT_EQ(o.size(), 0u);
}

}  // namespace
}  // namespace robotalk::client
