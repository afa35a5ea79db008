// Deadlines and link health in the session layer (issue 23): a command past
// its expiry is not executed, answers INTERRUPTED and is counted; what holds
// its actuator; which limit applies; each session's link figures in
// SERVER_COUNTERS and on the state stream; the warnings and --link-stop.
#include "robot_sessions.h"

#include "robotalk/request.h"
#include "sessions_fixture.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <sstream>

namespace robotalk {
namespace {

using std::chrono::milliseconds;
using std::chrono::seconds;
using namespace robotalk::testing;  // the fixture
using ::testing::HasSubstr;

// The named values of a SERVER_COUNTERS reply.
std::map<std::string, double> Counters(const Reply& r) {
  std::map<std::string, double> out;
  std::istringstream names(r.message);
  std::string name;
  for (std::size_t i = 0; names >> name && i < r.values.size(); ++i) out[name] = r.values[i];
  return out;
}

class DeadlinesTest : public RobotSessionsTest {
 protected:
  DeadlinesTest() { clock_.Set(TimePoint(std::chrono::hours(3))); }
  std::map<std::string, double> AskCounters(std::int64_t client, std::int64_t seq) {
    return Counters(Handle(Queries(client, seq, {Query{.id = 900 + seq, .type = QueryType::kServerCounters}}))
                        .at(900 + seq));
  }
};

TEST_F(DeadlinesTest, ALateSetPointPastTheRobotsDefaultIsNotExecutedAndIsCounted) {
  const TimePoint now = clock_.Now();
  Handle(Package(kAlice, 1, {Cmd(1, CommandType::kJointSetPoint, {0.5}, "pan", now - milliseconds(840))}));
  Run();
  EXPECT_TRUE(fake_->calls.empty()) << "an expired set-point reached the driver";
  const Reply r = Replies(kAlice).at(1);
  EXPECT_EQ(r.signal, Signal::kInterrupted);
  EXPECT_EQ(r.message, "expired: arrived 0.84 s after its start, limit 0.1 s");
  EXPECT_EQ(r.lateness, milliseconds(840));
  EXPECT_TRUE(fake_->partial_stops.empty()) << "a set-point holds: nothing to stop";
  EXPECT_EQ(sessions_->expired_commands(), 1u);
  const auto counters = AskCounters(kAlice, 2);
  EXPECT_EQ(counters.at("expired_commands"), 1);
  EXPECT_EQ(counters.at("link_expired"), 1);
}

TEST_F(DeadlinesTest, WithinItsLimitALateSetPointRunsLate) {
  Handle(Package(kAlice, 1,
                 {Cmd(1, CommandType::kJointSetPoint, {0.5}, "pan", clock_.Now() - milliseconds(90))}));
  Run();
  ASSERT_EQ(fake_->calls.size(), 1u);
  EXPECT_EQ(Replies(kAlice).at(1).signal, Signal::kSuccess);
  EXPECT_EQ(Replies(kAlice).at(1).lateness, milliseconds(90));
}

TEST_F(DeadlinesTest, TheServerBeingLateIsToldApartFromALateArrival) {
  const TimePoint start = clock_.Now() + seconds(1);
  Handle(Package(kAlice, 1, {Cmd(1, CommandType::kJointSetPoint, {0.5}, "pan", start)}));
  clock_.Set(start + milliseconds(200));  // the RobotDaemon did not run in time
  Run();
  EXPECT_TRUE(fake_->calls.empty());
  EXPECT_EQ(Replies(kAlice).at(1).message,
            "expired: began 0.2 s after its start (it arrived in time), limit 0.1 s");
}

TEST_F(DeadlinesTest, AnExpiredSpeedStopsItsActuatorInsteadOfLettingTheOldSpeedRunOn) {
  Handle(Package(kAlice, 1, {Cmd(1, CommandType::kSetSpeed, {0.3, 0})}));
  Run();
  ASSERT_EQ(fake_->calls.size(), 1u);
  Handle(Package(kAlice, 2, {Cmd(2, CommandType::kSetSpeed, {0.5, 0}, "", clock_.Now() - seconds(5))}));
  Run();
  EXPECT_EQ(fake_->calls.size(), 1u) << "the expired SETSPEED was executed";
  ASSERT_EQ(fake_->partial_stops.size(), 1u);
  EXPECT_TRUE(fake_->partial_stops[0].base);
  EXPECT_TRUE(fake_->partial_stops[0].joints.empty());
  EXPECT_THAT(Replies(kAlice).at(2).message, HasSubstr("expired: arrived 5 s after its start"));
}

TEST_F(DeadlinesTest, AGotoRunsLateUnlessItsPackageCarriesALimit) {
  Handle(Package(kAlice, 1, {Cmd(1, CommandType::kGoto, {1, 0, 0}, "", clock_.Now() - seconds(2))}));
  Run();
  ASSERT_EQ(fake_->calls.size(), 1u) << "a GOTO keeps 'run late'";
  fake_->goto_id.reset();
  Request limited =
      Package(kAlice, 2, {Cmd(2, CommandType::kGoto, {2, 0, 0}, "", clock_.Now() - seconds(2))});
  limited.max_late = milliseconds(500);
  Handle(limited);
  Run();
  EXPECT_EQ(fake_->calls.size(), 1u);
  EXPECT_EQ(Replies(kAlice).at(2).message, "expired: arrived 2 s after its start, limit 0.5 s");
}

TEST_F(DeadlinesTest, APackageMayAskForNoDeadlineOrItsOwn) {
  Request never =
      Package(kAlice, 1, {Cmd(1, CommandType::kJointSetPoint, {0.1}, "pan", clock_.Now() - seconds(10))});
  never.max_late = kMaxLateNever;
  Handle(never);
  Run();
  ASSERT_EQ(fake_->calls.size(), 1u);
  EXPECT_EQ(Replies(kAlice).at(1).lateness, seconds(10));
  Request tight = Package(
      kAlice, 2, {Cmd(2, CommandType::kJointSetPoint, {0.2}, "pan", clock_.Now() - milliseconds(30))});
  tight.max_late = milliseconds(20);
  Handle(tight);
  Run();
  EXPECT_EQ(Replies(kAlice).at(2).message, "expired: arrived 0.03 s after its start, limit 0.02 s");
}

TEST_F(DeadlinesTest, AStopAlwaysRunsHoweverLate) {
  Request stop = Package(kAlice, 1, {Cmd(1, CommandType::kStop, {}, "", clock_.Now() - seconds(3))});
  stop.max_late = milliseconds(1);
  Handle(stop);
  Run();
  ASSERT_EQ(fake_->calls.size(), 1u);
  EXPECT_EQ(Replies(kAlice).at(1).signal, Signal::kSuccess);
}

class NoDefaultDeadlineTest : public RobotSessionsTest {
 protected:
  NoDefaultDeadlineTest()
      : RobotSessionsTest(BaseType::kDifferential, SessionOptions{.max_late = kNeverExpires}) {}
};

TEST_F(NoDefaultDeadlineTest, ARobotWithoutADefaultRunsLateServoCommandsLate) {
  Handle(Package(kAlice, 1, {Cmd(1, CommandType::kJointSetPoint, {0.5}, "pan", clock_.Now() - seconds(3))}));
  Run();
  ASSERT_EQ(fake_->calls.size(), 1u);
  EXPECT_EQ(Replies(kAlice).at(1).lateness, seconds(3));
}

// --- Link health ------------------------------------------------------------

Request Heartbeat(std::int64_t client, std::int64_t seq, TimePoint sent, Duration round_trip) {
  Request r{.client_id = client, .sequence = seq, .send_time = sent};
  r.round_trip = round_trip;
  return r;
}

TEST_F(DeadlinesTest, ServerCountersReportTheAskingSessionsLink) {
  // Every 10 ms, 1 ms on the wire; numbers 5 and 9 never arrive.
  for (int i = 1; i <= 20; ++i) {
    if (i == 5 || i == 9) continue;
    clock_.Set(TimePoint(std::chrono::hours(3)) + milliseconds(10 * i + 1));
    Handle(Heartbeat(kAlice, i, TimePoint(seconds(50)) + milliseconds(10 * i), milliseconds(30)));
  }
  clock_.Advance(seconds(4));  // past the loss horizon
  const auto c = AskCounters(kAlice, 21);
  EXPECT_EQ(c.at("link_lost"), 2);
  EXPECT_EQ(c.at("link_expected"), 21);  // 1 .. 21 (the query's own package too)
  EXPECT_NEAR(c.at("link_loss"), 2.0 / 21, 1e-9);
  EXPECT_NEAR(c.at("link_round_trip_s"), 0.030, 1e-9);
  EXPECT_NEAR(c.at("link_delay_s"), 0.015, 1e-9);
  EXPECT_EQ(c.at("link_duplicates"), 0);
  // Bob's session is its own.
  const auto bob = AskCounters(kBob, 1);
  EXPECT_EQ(bob.at("link_lost"), 0);
}

TEST_F(DeadlinesTest, TheStateStreamCarriesTheMotionOwnersLink) {
  EXPECT_EQ(sessions_->MotionLink().client_id, 0);
  Request move = Package(kAlice, 1, {Cmd(1, CommandType::kJointSetPoint, {0.5}, "pan")});
  move.round_trip = milliseconds(24);
  move.send_time = clock_.Now();
  Handle(move);
  Run();
  const LinkState link = sessions_->MotionLink();
  EXPECT_EQ(link.client_id, kAlice);
  EXPECT_EQ(link.level, LinkState::Level::kGood);
  EXPECT_EQ(link.round_trip, milliseconds(24));
  Handle(Package(kBob, 1, {Cmd(2, CommandType::kStop)}));
  Run();
  EXPECT_EQ(sessions_->MotionLink().client_id, 0) << "a STOP ends every ownership";
}

// A short loss horizon, so the sessions stay alive (2 s timeout) while the
// losses are decided.
SessionOptions ShortHorizon(bool link_stop) {
  SessionOptions o{.link_stop = link_stop};
  o.link.loss_horizon = milliseconds(200);
  return o;
}

class LinkTest : public RobotSessionsTest {
 protected:
  explicit LinkTest(bool link_stop = false) : LinkTest(ShortHorizon(link_stop)) {}
  explicit LinkTest(SessionOptions options) : RobotSessionsTest(BaseType::kDifferential, options) {}
  // Alice's packages first .. first+39 every 20 ms, every other one lost,
  // then 0.3 s of silence (past the horizon).
  void LoseHalf(std::int64_t first) {
    for (std::int64_t i = first; i < first + 40; ++i) {
      clock_.Advance(milliseconds(20));
      if ((i - first) % 2 == 1) continue;
      Handle(Heartbeat(kAlice, i, clock_.Now(), milliseconds(20)));
    }
    clock_.Advance(milliseconds(300));
  }
};

TEST_F(LinkTest, ABadLinkIsLoggedButNotStoppedByDefault) {
  Handle(Package(kAlice, 1, {Cmd(1, CommandType::kSetSpeed, {0.3, 0})}));
  Run();
  LoseHalf(2);
  sessions_->Expire(clock_.Now());
  const std::vector<std::string> log = sessions_->TakeLog();
  ASSERT_EQ(log.size(), 1u);
  EXPECT_THAT(log[0], HasSubstr("'s link is bad: loss "));
  EXPECT_TRUE(fake_->partial_stops.empty());
  EXPECT_EQ(sessions_->MotionLink().level, LinkState::Level::kBad);
  // Not repeated at once.
  clock_.Advance(milliseconds(100));
  sessions_->Expire(clock_.Now());
  EXPECT_TRUE(sessions_->TakeLog().empty());
}

class LinkStopTest : public LinkTest {
 protected:
  LinkStopTest() : LinkTest(/*link_stop=*/true) {}
};

TEST_F(LinkStopTest, StopsWhatTheSessionOwnsAndDropsItsQueueOncePerBadSpell) {
  Handle(Package(kAlice, 1, {Cmd(1, CommandType::kSetSpeed, {0.3, 0})}));
  Run();
  Handle(Package(kAlice, 2, {Cmd(2, CommandType::kSetSpeed, {0.4, 0}, "", clock_.Now() + seconds(60))}));
  LoseHalf(3);
  sessions_->Expire(clock_.Now());
  Run();
  ASSERT_EQ(fake_->partial_stops.size(), 1u);
  EXPECT_TRUE(fake_->partial_stops[0].base);
  const Reply dropped = Replies(kAlice).at(2);
  EXPECT_EQ(dropped.signal, Signal::kInterrupted);
  EXPECT_THAT(dropped.message, HasSubstr("link is bad"));
  EXPECT_THAT(dropped.message, HasSubstr("--link-stop"));
  clock_.Advance(milliseconds(100));
  sessions_->Expire(clock_.Now());
  Run();
  EXPECT_EQ(fake_->partial_stops.size(), 1u) << "once per bad spell";
}

// A copy of one of Alice's packages, recorded and replayed by someone who
// cannot forge one (keyed mode: the copy is hers, MAC and all; the session
// table answers it as a duplicate), carries the round trip she reported
// when she sent it. Her link's figure is her latest report: a replay from a
// bad spell neither makes her good link bad (--link-stop stopped her base)
// nor, from a good spell, hides her bad link (no stop).
TEST_F(LinkStopTest, AReplayedPackagesOldRoundTripNeitherStopsAGoodLinkNorHidesABadOne) {
  Handle(Heartbeat(kAlice, 1, clock_.Now(), milliseconds(1200)));  // a bad spell, recorded
  clock_.Advance(milliseconds(20));
  Handle(Package(kAlice, 2, {Cmd(1, CommandType::kSetSpeed, {0.3, 0})}));
  Run();
  for (std::int64_t i = 3; i <= 12; ++i) {
    clock_.Advance(milliseconds(20));
    Handle(Heartbeat(kAlice, i, clock_.Now(), milliseconds(20)));
  }
  sessions_->Expire(clock_.Now());
  Run();
  ASSERT_TRUE(fake_->partial_stops.empty());
  clock_.Advance(milliseconds(20));
  Handle(Heartbeat(kAlice, 1, clock_.Now() - milliseconds(220), milliseconds(1200)));  // the replay
  sessions_->Expire(clock_.Now());
  Run();
  EXPECT_TRUE(fake_->partial_stops.empty()) << "a replayed old report stopped a good link's base";
  EXPECT_EQ(sessions_->MotionLink().level, LinkState::Level::kGood);
  EXPECT_EQ(sessions_->MotionLink().round_trip, milliseconds(20));

  // Now her link is bad (she reports 1.2 s); a replay of a good spell's package hides nothing.
  for (std::int64_t i = 13; i <= 16; ++i) {
    clock_.Advance(milliseconds(20));
    Handle(Heartbeat(kAlice, i, clock_.Now(), milliseconds(1200)));
  }
  clock_.Advance(milliseconds(20));
  Handle(Heartbeat(kAlice, 3, clock_.Now() - milliseconds(300), milliseconds(20)));  // the replay
  sessions_->Expire(clock_.Now());
  Run();
  EXPECT_EQ(sessions_->MotionLink().round_trip, milliseconds(1200));
  EXPECT_EQ(fake_->partial_stops.size(), 1u) << "a replayed good report hid a bad link";
}

// A playback sequence waiting for its start (the paper's estimate, which a
// jittery link also gets: frames buffered in the session until enough came)
// is queued commands of the session: --link-stop drops them and ends the
// sequence, so frames that arrived before the stop never run after it, and
// its later frames are answered, never a sequence started without its first
// frames (review 10: the buffered frames ran once the sequence started).
SessionOptions PaperPlayback() {
  SessionOptions o = ShortHorizon(/*link_stop=*/true);
  o.playback.quick_start = false;
  o.playback.adaptive = false;
  return o;
}
class LinkStopPlaybackTest : public LinkTest {
 protected:
  LinkStopPlaybackTest() : LinkTest(PaperPlayback()) {}
};

TEST_F(LinkStopPlaybackTest, DropsTheFramesOfASequenceWaitingForItsStartAndEndsIt) {
  Handle(Package(kAlice, 1, {Cmd(1, CommandType::kSetSpeed, {0.3, 0})}));
  Run();
  Handle(Playback(kAlice, 2, 50, 10, seconds(1),
                  {Cmd(3, CommandType::kSetSpeed, {0.5, 0}, "", StartTime::After(Duration(0))),
                   Cmd(4, CommandType::kSetSpeed, {0.6, 0}, "", StartTime::After(milliseconds(100)))}));
  LoseHalf(3);
  sessions_->Expire(clock_.Now());
  Run();
  ASSERT_EQ(fake_->partial_stops.size(), 1u);
  const std::map<CommandId, Reply> replies = Replies(kAlice);
  for (CommandId id : {3, 4, 50}) {
    EXPECT_TRUE(replies.count(id)) << "buffered frame or delay reply " << id << " not answered at the stop";
    if (!replies.count(id)) continue;
    EXPECT_EQ(replies.at(id).signal, Signal::kInterrupted) << id;
    EXPECT_THAT(replies.at(id).message, HasSubstr("--link-stop")) << id;
  }
  // The client sends the rest of the sequence: answered, never run.
  std::vector<Command> rest;
  for (int k = 2; k < 10; ++k)
    rest.push_back(
        Cmd(3 + k, CommandType::kSetSpeed, {0.1 * k, 0}, "", StartTime::After(milliseconds(100 * k))));
  const std::map<CommandId, Reply> later = Handle(Playback(kAlice, 43, 50, 10, seconds(1), rest));
  for (int k = 2; k < 10; ++k) {
    EXPECT_TRUE(later.count(3 + k)) << "later frame " << 3 + k << " not answered at once";
    if (!later.count(3 + k)) continue;
    EXPECT_EQ(later.at(3 + k).signal, Signal::kInterrupted);
    EXPECT_THAT(later.at(3 + k).message, HasSubstr("--link-stop"));
  }
  for (int i = 0; i < 200; ++i) {
    clock_.Advance(milliseconds(10));
    Run();
  }
  for (const FakeDriver::Call& c : fake_->calls)
    EXPECT_FALSE(c.type == CommandType::kSetSpeed && c.values.at(0) > 0.35)
        << "a frame of the stopped sequence ran";
}

}  // namespace
}  // namespace robotalk
