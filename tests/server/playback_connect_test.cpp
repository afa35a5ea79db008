// Issue 23 item 3: a connect-time package lost on a WAN and retransmitted
// carries its first copy's send time, so its arrival − send time is the
// client's resend wait + a delay. It must not count as the channel's delay
// in playback's start (it tripped the adaptive start's gate: the paper's
// estimate, seconds, in 1 of 5 WAN 300 ms relay runs). Told from a slow
// package by its sequence: it came after a later-numbered one, and slower
// than the slowest recent first copies by more than link health's reorder
// tolerance (link_health.h). On a manual clock.
#include "robot_sessions.h"
#include "sessions_fixture.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <optional>
#include <vector>

namespace robotalk {
namespace {

using namespace robotalk::testing;  // NOLINT: the sessions fixture
using std::chrono::milliseconds;
using ::testing::HasSubstr;

class PlaybackConnectTest : public RobotSessionsTest {
 protected:
  explicit PlaybackConnectTest(SessionOptions options = {})
      : RobotSessionsTest(BaseType::kDifferential, options) {}
  struct Arrival {
    TimePoint at;
    Request request;
  };
  // Delivers the packages in arrival order, each at its arrival time; returns
  // the last one's immediate replies, and the delay reply of a playback start
  // that waited for its frame 0's second copy (none comes here: it starts
  // when the wait ends, with the start it would have taken at frame 0).
  std::map<CommandId, Reply> Deliver(std::vector<Arrival> arrivals) {
    std::stable_sort(arrivals.begin(), arrivals.end(),
                     [](const Arrival& a, const Arrival& b) { return a.at < b.at; });
    std::map<CommandId, Reply> last;
    for (const Arrival& a : arrivals) {
      clock_.Advance(a.at - clock_.Now());
      last = Handle(a.request);
    }
    if (const std::optional<TimePoint> next = sessions_->NextPlaybackDecision()) {
      clock_.Set(std::max(*next, clock_.Now()));
      EXPECT_TRUE(sessions_->DecidePlaybacks(clock_.Now()));
      for (const auto& [id, reply] : Replies(kAlice)) last.emplace(id, reply);
    }
    return last;
  }
  // Eight CLOCK rounds 40 ms apart from t0 (the client's clock reads 3 s
  // ahead) taking `delay_ms`; the one at `lost` (if any) lost and resent
  // 300 ms later with its first copy's send time. Then frame 0 of a 40-frame
  // sequence at 10 Hz, sent 1 s after the first round and 115 ms on the way:
  // its immediate replies.
  std::map<CommandId, Reply> ConnectThenFrame0(const std::vector<int>& delay_ms, std::int64_t playback_id,
                                               std::optional<std::size_t> lost = std::nullopt) {
    const TimePoint t0 = clock_.Now() + milliseconds(10);
    std::vector<Arrival> connect;
    for (std::size_t i = 0; i < delay_ms.size(); ++i) {
      const auto seq = static_cast<std::int64_t>(i + 1);
      Request r = Queries(kAlice, seq, {Query{.id = 100 + seq, .type = QueryType::kClock}});
      const TimePoint sent = t0 + milliseconds(40) * static_cast<int>(i);
      r.send_time = sent + kSkew;
      connect.push_back(
          {sent + (lost == i ? milliseconds(300) : Duration(0)) + milliseconds(delay_ms[i]), r});
    }
    Deliver(connect);
    const TimePoint frame_sent = t0 + std::chrono::seconds(1);
    Request frame0 =
        Playback(kAlice, 9, playback_id, 40, milliseconds(3900),
                 {Cmd(1, CommandType::kJointSetPoint, {0.1}, "pan", StartTime::After(Duration(0)))});
    frame0.send_time = frame_sent + kSkew;
    return Deliver({{frame_sent + milliseconds(115), frame0}});
  }
  static constexpr Duration kSkew = std::chrono::seconds(3);
};

// A WAN: 100-130 ms one way; the 3rd round is lost and resent 300 ms later
// (after the 4th and later ones arrived).
const std::vector<int> kWanRounds = {112, 127, 105, 118, 130, 101, 123, 109};

TEST_F(PlaybackConnectTest, ARetransmittedConnectTimePackageDoesNotTripTheAdaptiveStartsGate) {
  const auto immediate = ConnectThenFrame0(kWanRounds, 9200, 2);
  // Before: the retransmission's 405 ms among 101-130 ms spread the delays
  // by 304 ms, past 1.2 frame intervals: the paper's estimate, which waits
  // for 5 frames (no reply yet).
  ASSERT_TRUE(immediate.count(9200)) << "decided at the first frame";
  const Reply& r = immediate.at(9200);
  EXPECT_EQ(r.signal, Signal::kSuccess);
  EXPECT_THAT(r.message, HasSubstr("adaptive start"));
  // It covers the worst first copy, 130 ms, + the spread / n (29 ms / 8:
  // the 7 first copies and frame 0, counted once) + 2 ms, less this frame's
  // 115 ms and one gap's 10 ms stretch: 10.6 ms (10.2 ms while frame 0's
  // delay was in the history too: n = 9).
  EXPECT_NEAR(r.values.at(0), 0.130 + 0.029 / 8 + 0.002 - 0.115 - 0.010, 1e-4);
  EXPECT_EQ(sessions_->link(kAlice)->retransmitted, 1u) << "link health counts it too";
}

// --playback-resent-delays on: every package counts, as before (the paper's
// estimate here). With the queue follow (on by default) the spread beyond
// the gate is followed instead, the retransmission left out by the fence:
// off here, to show the gate as the option restores it.
class PlaybackConnectResentTest : public PlaybackConnectTest {
 protected:
  PlaybackConnectResentTest()
      : PlaybackConnectTest(
            SessionOptions{.playback = {.follow_queue = false}, .playback_resent_delays = true}) {}
};

TEST_F(PlaybackConnectResentTest, WithResentDelaysOnTheRetransmissionTripsTheGateAsBefore) {
  EXPECT_FALSE(ConnectThenFrame0(kWanRounds, 9202, 2).count(9202)) << "the paper's: waits for frames";
}

TEST_F(PlaybackConnectTest, ASlowFirstCopyStillCountsAndSoDoesAReorderedOne) {
  // The same rounds, none lost: the 3rd only slow (160 ms) and overtaken by
  // the 4th (reordered, not resent: within the reorder tolerance). Its delay
  // is the channel's and counts: the worst is 160 ms.
  const auto immediate = ConnectThenFrame0({112, 127, 160, 118, 130, 101, 123, 109}, 9201);
  ASSERT_TRUE(immediate.count(9201));
  // n = 9: 8 rounds and frame 0, once.
  EXPECT_NEAR(immediate.at(9201).values.at(0), 0.160 + 0.059 / 9 + 0.002 - 0.115 - 0.010, 1e-4);
  EXPECT_EQ(sessions_->link(kAlice)->retransmitted, 0u);
}

// Frame 0's delay is one sample, not two: the session records a package's
// delay after its items, so the history the first frame reads holds only the
// packages before it (it held frame 0 too, which then counted again as a
// frame: n + 1 samples for n packages). quick_min_delays (4) delays are 4
// packages: 2 clock rounds and frame 0 are too few for a start at the first
// frame (the paper's estimate waits for frames: no reply yet); 3 rounds and
// frame 0 are enough.
TEST_F(PlaybackConnectTest, FrameZerosDelayCountsOnceAmongTheDelaysTheStartNeeds) {
  EXPECT_FALSE(ConnectThenFrame0({112, 127}, 9203).count(9203)) << "3 delays, not 4";
}

TEST_F(PlaybackConnectTest, FourPackagesDelaysAreEnoughForAStartAtTheFirstFrame) {
  EXPECT_TRUE(ConnectThenFrame0({112, 127, 105}, 9204).count(9204));
}

// Issue 23 item 3, ninth session: on the relay's congested FIFO link the
// client's third connect-time package waited behind the client's own
// retransmission of the one before it (whose acknowledgement came after the
// 100 ms resend interval), and that wait set the start's worst delay. The
// ServerDaemon answers such a copy from the session table
// (ServerDaemon::Gate -> RobotSessions::Resend), never through Handle: the
// delay history must still see it, so the wait behind it is left out on a
// FIFO link as a burst package's is. Server times from t0, least delay 1 ms:
// packages 1 and 2 sent at 0 arrive at 61 and 106 ms; package 2's copy, resent
// at 100 ms, at 176 ms; package 3, sent at 115 ms, behind it at 196 ms (20 ms
// its own service); packages 4 and 5 at 300 (6 ms) and 500 ms (1 ms); frame 0,
// sent at 1 s, takes 8 ms.
class PlaybackCopyTest : public PlaybackConnectTest {
 protected:
  // The playback delay reply's value (s); `copy`: package 2's copy arrives
  // (else package 3 arrives at 136 ms, 21 ms on the way: no copy to wait behind).
  double StartWithCopy(bool copy, std::int64_t playback_id) {
    const TimePoint t0 = clock_.Now() + milliseconds(10);
    const auto at = [&](int ms) { return t0 + milliseconds(ms); };
    const auto package = [&](std::int64_t seq, int sent_ms) {
      Request r = Queries(kAlice, seq, {Query{.id = 100 + seq, .type = QueryType::kClock}});
      r.send_time = at(sent_ms) + kSkew;
      return r;
    };
    const Request second = package(2, 0);
    Deliver({{at(61), package(1, 0)}, {at(106), second}});
    if (copy) {
      clock_.Advance(at(176) - clock_.Now());
      sessions_->Resend(second, clock_.Now(), clock_.Now());  // as ServerDaemon::Gate does
    }
    Deliver(
        {{at(copy ? 196 : 136), package(3, 115)}, {at(306), package(4, 300)}, {at(501), package(5, 500)}});
    Request frame0 =
        Playback(kAlice, 6, playback_id, 40, milliseconds(3900),
                 {Cmd(1, CommandType::kJointSetPoint, {0.1}, "pan", StartTime::After(Duration(0)))});
    frame0.send_time = at(1000) + kSkew;
    const auto immediate = Deliver({{at(1008), frame0}});
    EXPECT_TRUE(immediate.count(playback_id)) << "decided at the first frame";
    return immediate.count(playback_id) ? immediate.at(playback_id).values.at(0) : -1;
  }
};

TEST_F(PlaybackCopyTest, AConnectPackagesWaitBehindARetransmittedCopyIsNoDelayOfTheChannel) {
  // The channel's delays: 61, 46 (package 2 less its wait behind package 1),
  // 21 (package 3 less its wait behind the copy), 6, 1 and 8 ms: the worst
  // 61 + the spread / n (60 / 6) ms, less frame 0's 8 ms and one gap's 10 ms
  // stretch, + 2 ms: 55 ms after frame 0, as if package 3 had not queued.
  // Before (the copy unseen): package 3's 81 ms set the worst, 78.3 ms.
  const double with_copy = StartWithCopy(true, 9300);
  EXPECT_NEAR(with_copy, 0.061 + 0.060 / 6 - 0.008 - 0.010 + 0.002, 1e-4);
}

TEST_F(PlaybackCopyTest, WithoutACopyTheSameServicesGiveTheSameStart) {
  EXPECT_NEAR(StartWithCopy(false, 9301), 0.061 + 0.060 / 6 - 0.008 - 0.010 + 0.002, 1e-4);
}

}  // namespace
}  // namespace robotalk
