#include "robot_sessions.h"

#include "robotalk/config_message.h"
#include "robotalk/request.h"
#include "sessions_fixture.h"
#include "state_encoding.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <limits>

namespace robotalk {
namespace {

using std::chrono::milliseconds;
using std::chrono::seconds;
using namespace robotalk::testing;  // the fixture
using ::testing::HasSubstr;

TEST_F(RobotSessionsTest, ExecutesACommandAtItsStartTimeAndReportsLateness) {
  const TimePoint start = clock_.Now() + seconds(2);
  Handle(Package(kAlice, 1, {Cmd(1, CommandType::kJointSetPoint, {0.5}, "pan", start)}));
  EXPECT_EQ(last_.batch.ack_sequence, 1);
  Run();
  EXPECT_TRUE(fake_->calls.empty()) << "ran before its start time";
  EXPECT_EQ(daemon_->RunOnce(clock_.Now()), std::min(start, clock_.Now() + milliseconds(10)));
  clock_.Set(start + milliseconds(3));
  Run();
  ASSERT_EQ(fake_->calls.size(), 1u);
  EXPECT_EQ(fake_->calls[0].at, start + milliseconds(3));
  const Reply r = Replies(kAlice).at(1);
  EXPECT_EQ(r.signal, Signal::kSuccess);
  EXPECT_EQ(r.lateness, milliseconds(3));
}

TEST_F(RobotSessionsTest, RunsARecentPastStartAtOnceAndRefusesOneBeyondTheLimitEvenAHostileOne) {
  clock_.Set(TimePoint(std::chrono::hours(3)));
  const TimePoint now = clock_.Now();
  // The codec admits any start within +-292 years (kMaxWireMicros): the
  // furthest past one must be refused without overflowing (UBSan).
  const TimePoint hostile(-std::chrono::duration_cast<Duration>(std::chrono::microseconds(kMaxWireMicros)));
  Request package = Package(kAlice, 1,
                            {Cmd(1, CommandType::kJointSetPoint, {0.1}, "pan", now - seconds(10)),
                             Cmd(2, CommandType::kJointSetPoint, {0.2}, "pan", now - std::chrono::hours(2)),
                             Cmd(3, CommandType::kJointSetPoint, {0.3}, "pan", hostile)});
  package.max_late = kMaxLateNever;  // "run late" (the default limit: deadlines_test.cpp)
  auto immediate = Handle(package);
  ASSERT_EQ(immediate.count(1), 0u) << "10 s late is run, late";
  EXPECT_EQ(immediate.at(2).signal, Signal::kError);
  EXPECT_THAT(immediate.at(2).message, HasSubstr("start time is 7200 s in the past of the server clock"));
  EXPECT_THAT(immediate.at(2).message, HasSubstr("the limit is 3600 s"));
  EXPECT_EQ(immediate.at(3).signal, Signal::kError);
  EXPECT_THAT(immediate.at(3).message, HasSubstr("in the past of the server clock"));
  Run();
  ASSERT_EQ(fake_->calls.size(), 1u);
  const Reply late = Replies(kAlice).at(1);
  EXPECT_EQ(late.signal, Signal::kSuccess);
  EXPECT_EQ(late.lateness, seconds(10));
}

TEST(SaturatingSub, SaturatesInsteadOfOverflowing) {
  const TimePoint lo = TimePoint::min(), hi = TimePoint::max(), t(seconds(5));
  EXPECT_EQ(SaturatingSub(t, TimePoint(seconds(2))), seconds(3));
  EXPECT_EQ(SaturatingSub(lo, t), Duration::min());
  EXPECT_EQ(SaturatingSub(hi, TimePoint(-seconds(1))), Duration::max());
  EXPECT_EQ(SaturatingSub(hi, lo), Duration::max());
  EXPECT_EQ(SaturatingSub(lo, hi), Duration::min());
  EXPECT_EQ(SaturatingSub(lo, lo), Duration(0));
}

TEST_F(RobotSessionsTest, OrdersCommandsOfAllClientsByStartTimeThenArrival) {
  const TimePoint t = clock_.Now() + seconds(1);
  Handle(Package(kAlice, 1, {Cmd(1, CommandType::kStop, {}, "", t + seconds(40))}));
  Handle(Package(kBob, 1, {Cmd(1, CommandType::kGoto, {1, 0, 0}, "", t + seconds(20))}));
  Request setpoint = Package(kBob, 2, {Cmd(2, CommandType::kJointSetPoint, {0.1}, "pan", t + seconds(20))});
  setpoint.max_late = kMaxLateNever;  // it runs 40 s late below
  Handle(setpoint);
  clock_.Set(t + seconds(60));
  Run();
  ASSERT_EQ(fake_->calls.size(), 3u);
  EXPECT_EQ(fake_->calls[0].type, CommandType::kGoto);
  EXPECT_EQ(fake_->calls[1].type, CommandType::kJointSetPoint);
  EXPECT_EQ(fake_->calls[2].type, CommandType::kStop);
}

TEST_F(RobotSessionsTest, NeverExecutesADuplicatedPackageTwiceAndResendsItsReply) {
  const auto p = Package(kAlice, 7, {Cmd(1, CommandType::kJointSetPoint, {0.5}, "pan")});
  Handle(p);
  Run();
  ASSERT_EQ(Replies(kAlice).at(1).signal, Signal::kSuccess);
  auto again = Handle(p);  // the client did not see the reply and retransmits
  Run();
  EXPECT_EQ(fake_->calls.size(), 1u);
  EXPECT_EQ(last_.batch.ack_sequence, 7);
  ASSERT_EQ(again.count(1), 1u);
  EXPECT_EQ(again.at(1).signal, Signal::kSuccess);
}

TEST_F(RobotSessionsTest, AnswersEverySignal) {
  // SUCCESS, MODIFIED (the driver clamps), ERROR (unknown joint, NaN, too far ahead).
  auto immediate = Handle(Package(
      kAlice, 1,
      {Cmd(1, CommandType::kJointSetPoint, {0.5}, "pan"), Cmd(2, CommandType::kJointSetPoint, {3.0}, "pan"),
       Cmd(3, CommandType::kJointSetPoint, {0.5}, "nek"),
       Cmd(4, CommandType::kJointSetPoint, {std::nan("")}, "pan"),
       Cmd(5, CommandType::kJointSpeed, {0.1}, "pan"),
       Cmd(6, CommandType::kStop, {}, "", clock_.Now() + std::chrono::hours(2))}));
  EXPECT_EQ(immediate.at(3).signal, Signal::kError);
  EXPECT_THAT(immediate.at(3).message, HasSubstr("no joint named 'nek'"));
  EXPECT_EQ(immediate.at(4).signal, Signal::kError);
  EXPECT_THAT(immediate.at(4).message, HasSubstr("NaN"));
  EXPECT_EQ(immediate.at(5).signal, Signal::kNa) << "pan accepts only set-points";
  EXPECT_EQ(immediate.at(6).signal, Signal::kError);
  EXPECT_THAT(immediate.at(6).message, HasSubstr("ahead of the server clock"));
  Run();
  auto replies = Replies(kAlice);
  EXPECT_EQ(replies.at(1).signal, Signal::kSuccess);
  EXPECT_EQ(replies.at(2).signal, Signal::kModified);
  // BUSY and INTERRUPTED: a GOTO is running, a second one is refused, STOP interrupts the first.
  Handle(
      Package(kAlice, 2, {Cmd(10, CommandType::kGoto, {1, 0, 0}), Cmd(11, CommandType::kGoto, {2, 0, 0})}));
  Run();
  EXPECT_EQ(Replies(kAlice).at(11).signal, Signal::kBusy);
  EXPECT_EQ(Replies(kAlice).count(10), 0u) << "the GOTO is still running";
  Handle(Package(kAlice, 3, {Cmd(12, CommandType::kStop)}));
  Run();
  EXPECT_EQ(Replies(kAlice).at(10).signal, Signal::kInterrupted);
  EXPECT_EQ(Replies(kAlice).at(12).signal, Signal::kSuccess);
  // PANIC.
  Handle(Package(kBob, 1, {}, /*panic=*/true));
  auto refused = Handle(Package(kAlice, 4, {Cmd(13, CommandType::kJointSetPoint, {0.1}, "pan")}));
  EXPECT_EQ(refused.at(13).signal, Signal::kPanic);
}

TEST_F(RobotSessionsTest, CompletesAGotoWhenTheDriverReportsIt) {
  Handle(Package(kAlice, 1, {Cmd(1, CommandType::kGoto, {1, 2, 0})}));
  for (int i = 0; i < 5; ++i) {
    clock_.Advance(milliseconds(10));
    Run();
  }
  EXPECT_EQ(Replies(kAlice).at(1).signal, Signal::kSuccess);
}

class FixedBaseSessionsTest : public RobotSessionsTest {
 protected:
  FixedBaseSessionsTest() : RobotSessionsTest(BaseType::kFixed) {}
};

TEST_F(FixedBaseSessionsTest, AnswersNaToABaseCommandOnAFixedBase) {
  auto r = Handle(Package(kAlice, 1, {Cmd(1, CommandType::kGoto, {1, 0, 0})}));
  EXPECT_EQ(r.at(1).signal, Signal::kNa);
  EXPECT_THAT(r.at(1).message, HasSubstr("fixed base"));
  Run();
  EXPECT_TRUE(fake_->calls.empty()) << "refused before it reached the driver";
}

TEST_F(RobotSessionsTest, RefusesAMixedPackageWithErrorForEveryItem) {
  // A mixed package: the encoder writes what it is given; the decoder flags it.
  Request mixed{.client_id = kAlice, .sequence = 1};
  mixed.commands.push_back(Cmd(1, CommandType::kStop));
  mixed.queries.push_back(Query{2, QueryType::kJointState, ""});
  const Request request = DecodeRequest(EncodeRequest(mixed));
  ASSERT_THAT(request.header_error, HasSubstr("mixes"));
  auto r = Handle(request);
  ASSERT_EQ(r.size(), 2u);
  for (const auto& [id, reply] : r) EXPECT_EQ(reply.signal, Signal::kError);
  Run();
  EXPECT_TRUE(fake_->calls.empty());
}

class SmallQueueSessionsTest : public RobotSessionsTest {
 protected:
  SmallQueueSessionsTest() : RobotSessionsTest(BaseType::kDifferential, SessionOptions{.max_queue = 2}) {}
};

TEST_F(SmallQueueSessionsTest, RefusesCommandsBeyondTheQueueLimit) {
  const TimePoint later = clock_.Now() + seconds(10);
  auto r =
      Handle(Package(kAlice, 1,
                     {Cmd(1, CommandType::kStop, {}, "", later), Cmd(2, CommandType::kStop, {}, "", later),
                      Cmd(3, CommandType::kStop, {}, "", later)}));
  ASSERT_EQ(r.size(), 1u);
  EXPECT_THAT(r.at(3).message, HasSubstr("client 00000000000a11ce has 2 commands queued on robot 'bot'; "
                                         "the limit is 2 (--max-queue)"));
  EXPECT_EQ(daemon_->queued(kAlice), 2u);
}

TEST_F(RobotSessionsTest, PanicFlushesEveryQueueHaltsTheDriverAndRefusesUntilReset) {
  const TimePoint later = clock_.Now() + seconds(5);
  Handle(Package(kAlice, 1, {Cmd(1, CommandType::kGoto, {1, 0, 0})}));
  Run();  // the GOTO is in progress
  Handle(Package(kAlice, 2, {Cmd(2, CommandType::kJointSetPoint, {0.5}, "pan", later)}));
  Handle(Package(kBob, 1, {Cmd(1, CommandType::kStop, {}, "", later)}));

  auto panic = Handle(Package(kBob, 2, {Cmd(2, CommandType::kJointSetPoint, {0.2}, "pan")}, /*panic=*/true));
  EXPECT_EQ(panic.at(2).signal, Signal::kPanic) << "a panic package is never executed";
  EXPECT_TRUE(daemon_->in_panic());
  // Flushed at once, before the RobotDaemon runs.
  EXPECT_EQ(Replies(kAlice).at(2).signal, Signal::kInterrupted);
  EXPECT_EQ(Replies(kBob).at(1).signal, Signal::kInterrupted);
  Run();
  EXPECT_TRUE(fake_->halted);
  EXPECT_EQ(Replies(kAlice).at(1).signal, Signal::kInterrupted) << "the GOTO in progress";

  auto refused = Handle(Package(kAlice, 3, {Cmd(3, CommandType::kJointSetPoint, {0.1}, "pan")}));
  EXPECT_EQ(refused.at(3).signal, Signal::kPanic);
  // Queries are still answered during a panic.
  Handle(Queries(kAlice, 4, {Query{4, QueryType::kJointState, ""}}));
  Run();
  EXPECT_EQ(Replies(kAlice).at(4).signal, Signal::kSuccess);

  // Any client may reset; the robot then accepts commands again.
  auto reset = Handle(Package(kAlice, 5, {Cmd(5, CommandType::kPanicReset)}));
  EXPECT_EQ(reset.at(5).signal, Signal::kSuccess);
  Run();
  EXPECT_FALSE(fake_->halted);
  Handle(Package(kBob, 3, {Cmd(3, CommandType::kJointSetPoint, {0.3}, "pan")}));
  Run();
  EXPECT_EQ(Replies(kBob).at(3).signal, Signal::kSuccess);
  EXPECT_DOUBLE_EQ(fake_->position, 0.3);
}

TEST_F(RobotSessionsTest, HoldsWhatAVanishedClientMovedWhileTheRobotMoves) {
  Handle(Package(kAlice, 1, {Cmd(1, CommandType::kJointSetPoint, {0.5}, "pan")}));
  Handle(Queries(kBob, 1, {Query{1, QueryType::kJointState, ""}}));
  Run();
  EXPECT_EQ(sessions_->joint_owner(0), kAlice);
  clock_.Advance(seconds(1));
  Handle(Queries(kBob, 2, {}));  // Bob keeps his session alive with a heartbeat
  clock_.Advance(milliseconds(1500));
  const auto expired = sessions_->Expire(clock_.Now());
  ASSERT_EQ(expired.size(), 1u);
  EXPECT_EQ(expired[0].client_id, kAlice);
  EXPECT_TRUE(expired[0].moved_robot);
  Run();
  ASSERT_EQ(fake_->partial_stops.size(), 1u) << "pan stopped where it is (StopOnly)";
  EXPECT_EQ(fake_->partial_stops[0].joints, std::vector<int>{0});
  EXPECT_FALSE(fake_->partial_stops[0].base);
  EXPECT_EQ(sessions_->joint_owner(0), 0);
}

// Issue 9: `robotalk send pioneer joint_setpoint pan 0.5; robotalk send pioneer
// goto 3 0 0` -- the first CLI's session expired and its watchdog STOP
// interrupted the second CLI's GOTO.
TEST_F(RobotSessionsTest, TheWatchdogLeavesAnotherClientsGotoRunning) {
  fake_->goto_updates = 1000;
  Handle(Package(kAlice, 1, {Cmd(1, CommandType::kJointSetPoint, {0.5}, "pan")}));
  Run();
  Handle(Package(kBob, 1, {Cmd(1, CommandType::kGoto, {3, 0, 0})}));
  Run();
  fake_->moving = true;
  EXPECT_EQ(sessions_->base_owner(), kBob);
  for (int i = 1; i <= 25; ++i) {  // 2.5 s: Bob's client sends heartbeats, Alice's is gone
    clock_.Advance(milliseconds(100));
    Handle(Queries(kBob, 1 + i, {}));
    sessions_->Expire(clock_.Now());
    Run();
  }
  EXPECT_EQ(Replies(kBob).count(1), 0u) << "the GOTO is still running, not INTERRUPTED";
  for (const auto& call : fake_->calls) EXPECT_NE(call.type, CommandType::kStop);
  EXPECT_EQ(fake_->goto_id.has_value(), true);
}

TEST_F(RobotSessionsTest, NeitherDuplicatesNorRefusedPackagesRefreshASession) {
  const Request p = Package(kAlice, 1, {Cmd(1, CommandType::kJointSetPoint, {0.5}, "pan")});
  Handle(p);
  Run();
  for (int i = 0; i < 30; ++i) {  // 3 s of replayed copies, and a package with a bad header
    clock_.Advance(milliseconds(100));
    Handle(p);
    Request bad = Package(kAlice, 100 + i, {Cmd(2, CommandType::kStop)});
    bad.header_error = "package: header payload size 9 but 1 commands";
    Handle(bad);
  }
  const auto expired = sessions_->Expire(clock_.Now());
  ASSERT_EQ(expired.size(), 1u) << "the session expired despite the replays";
  EXPECT_EQ(expired[0].client_id, kAlice);
}

// Issue 9: one spoofed heartbeat with sequence INT64_MAX made every later
// call of the victim time out (the window follows the highest number seen).
TEST_F(RobotSessionsTest, RefusesASequenceJumpSoItCannotPoisonTheWindow) {
  Handle(Package(kAlice, 1, {Cmd(1, CommandType::kJointSetPoint, {0.1}, "pan")}));
  auto forged = Handle(Package(kAlice, std::numeric_limits<std::int64_t>::max(),
                               {Cmd(66, CommandType::kJointSetPoint, {-1}, "pan")}));
  EXPECT_EQ(forged.at(66).signal, Signal::kError);
  EXPECT_THAT(forged.at(66).message, HasSubstr("never received; refused"));
  auto next = Handle(Package(kAlice, 2, {Cmd(2, CommandType::kJointSetPoint, {0.2}, "pan")}));
  EXPECT_TRUE(next.empty()) << "the victim's next package is accepted";
  Run();
  EXPECT_EQ(Replies(kAlice).at(2).signal, Signal::kSuccess);
  EXPECT_DOUBLE_EQ(fake_->position, 0.2);
  EXPECT_EQ(sessions_->refused_packages(), 1u);
}

// Issue 19 item 12 (open mode): strides of +4000 under the victim's id, each
// within the old 4096-jump guard, made the victim's next package a
// "duplicate": it never ran and the client saw UnknownOutcome after 4.3 s.
TEST_F(RobotSessionsTest, StridesUnderTheGuardCannotMakeTheVictimsNextPackageADuplicate) {
  Handle(Package(kAlice, 1, {Cmd(1, CommandType::kJointSetPoint, {0.1}, "pan")}));
  for (std::int64_t i = 1; i <= 40; ++i) Handle(Package(kAlice, 1 + 4000 * i, {}));
  auto next = Handle(Package(kAlice, 2, {Cmd(2, CommandType::kJointSetPoint, {0.2}, "pan")}));
  EXPECT_TRUE(next.empty()) << "the victim's next package is accepted";
  Run();
  ASSERT_EQ(Replies(kAlice).count(2), 1u) << "and answered";
  EXPECT_EQ(Replies(kAlice).at(2).signal, Signal::kSuccess);
  EXPECT_DOUBLE_EQ(fake_->position, 0.2);
}

TEST_F(RobotSessionsTest, NeverEchoesALongBadTargetInFull) {
  const std::string target(50000, 'x');
  auto r = Handle(Package(kAlice, 1, {Cmd(1, CommandType::kJointSetPoint, {0.1}, target)}));
  EXPECT_EQ(r.at(1).signal, Signal::kError);
  EXPECT_LT(r.at(1).message.size(), 160u);
  EXPECT_THAT(r.at(1).message, HasSubstr("xxx...' (50000 bytes)"));
}

class FewSessionsTest : public RobotSessionsTest {
 protected:
  FewSessionsTest()
      : RobotSessionsTest(BaseType::kDifferential,
                          SessionOptions{.max_queue = 100, .max_sessions_per_robot = 2}) {}
};

TEST_F(FewSessionsTest, RefusesANewClientBeyondTheSessionBoundAndServesKnownOnes) {
  Handle(Queries(kAlice, 1, {Query{1, QueryType::kClock, ""}}));
  Handle(Queries(kBob, 1, {Query{1, QueryType::kClock, ""}}));
  auto third = Handle(Queries(0xC0FFEE, 1, {Query{1, QueryType::kClock, ""}}));
  EXPECT_EQ(third.at(1).signal, Signal::kError);
  // Issue 19 item 12: it named --max-sessions, the server-wide bound.
  EXPECT_THAT(third.at(1).message, HasSubstr("(the --max-sessions-per-robot bound)"));
  EXPECT_EQ(sessions_->num_sessions(), 2u);
  auto alice = Handle(Queries(kAlice, 2, {Query{2, QueryType::kClock, ""}}));
  EXPECT_EQ(alice.at(2).signal, Signal::kSuccess);
}

TEST_F(FewSessionsTest, APanicFromAClientBeyondTheSessionBoundIsStillTakenAndSaysSo) {
  Handle(Queries(kAlice, 1, {Query{1, QueryType::kClock, ""}}));
  Handle(Queries(kBob, 1, {Query{1, QueryType::kClock, ""}}));
  const ImmediateAnswer answer = sessions_->Handle(Package(0xC0FFEE, 1, {}, /*panic=*/true), clock_.Now());
  EXPECT_TRUE(daemon_->in_panic());
  EXPECT_EQ(answer.batch.panic, PanicStatus::kTaken);
}

TEST_F(FewSessionsTest, RefusesAPlaybackDeclaringMoreFramesThanTheQueueHolds) {
  auto r = Handle(Playback(kAlice, 1, 5, std::numeric_limits<std::int32_t>::max(), seconds(10),
                           {Cmd(1, CommandType::kStop, {}, "", TimePoint(Duration(0)))}));
  EXPECT_EQ(r.at(1).signal, Signal::kError);
  EXPECT_THAT(r.at(1).message, HasSubstr("the queue limit is 100"));
}

// The watchdog does not trust a driver's `moving` (a driver may never set
// it): what the vanished client owned is stopped, which leaves a still
// robot still, and nothing else is touched.
TEST_F(RobotSessionsTest, StopsOnlyWhatAVanishedClientOwnedEvenOnAStillRobot) {
  Handle(Package(kAlice, 1, {Cmd(1, CommandType::kJointSetPoint, {0.5}, "pan")}));
  Run();
  fake_->moving = false;  // the set-point has been reached
  clock_.Advance(seconds(3));
  ASSERT_EQ(sessions_->Expire(clock_.Now()).size(), 1u);
  Run();
  EXPECT_EQ(fake_->calls.back().type, CommandType::kJointSetPoint) << "no STOP of everything";
  ASSERT_EQ(fake_->partial_stops.size(), 1u);
  EXPECT_EQ(fake_->partial_stops[0].joints, std::vector<int>{0});
}

TEST_F(RobotSessionsTest, DoesNotStopTheRobotWhenAQueryOnlyClientVanishes) {
  Handle(Queries(kBob, 1, {Query{1, QueryType::kJointState, ""}}));
  Run();
  clock_.Advance(seconds(3));
  EXPECT_EQ(sessions_->Expire(clock_.Now()).size(), 1u);
  Run();
  EXPECT_TRUE(fake_->calls.empty());
}

TEST_F(RobotSessionsTest, AnswersClockAndConfigQueriesOnReceipt) {
  auto r = Handle(Queries(kAlice, 1, {Query{1, QueryType::kClock, ""}, Query{2, QueryType::kConfig, ""}}));
  EXPECT_EQ(r.at(1).signal, Signal::kSuccess);
  EXPECT_EQ(r.at(1).exec_time, clock_.Now());
  EXPECT_EQ(last_.batch.server_receive, clock_.Now());
  EXPECT_TRUE(last_.publish_config);
  char hex[17];
  std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(ConfigHash(daemon_->model())));
  EXPECT_EQ(r.at(2).message, hex);
}

TEST_F(RobotSessionsTest, AnswersJointStateAndPoseQueries) {
  fake_->position = 0.5;
  Handle(Queries(kAlice, 1,
                 {Query{1, QueryType::kJointState, "pan"}, Query{2, QueryType::kLinkPoses, "head"},
                  Query{3, QueryType::kBasePose, ""}, Query{4, QueryType::kFramePoses, "nope"}}));
  EXPECT_EQ(last_.batch.replies.size(), 1u) << "only the bad frame name is answered at once";
  Run();
  auto replies = Replies(kAlice);
  EXPECT_EQ(replies.at(1).values, (std::vector<double>{0.5, 0.25, -0.5}));
  ASSERT_EQ(replies.at(2).values.size(), 7u);
  EXPECT_NEAR(replies.at(2).values[3], std::cos(0.25), 1e-12) << "qw of a 0.5 rad yaw";
  EXPECT_EQ(replies.at(3).values.size(), 5u);
}

TEST_F(RobotSessionsTest, PlaybackHoldsFramesUntilItCanEstimateThenKeepsTheirTiming) {
  // 20 frames every 100 ms; the channel delivers one every 150 ms (slower).
  // One timeline in 1 ms steps: frames arrive, the RobotDaemon runs.
  constexpr int kFrames = 20;
  constexpr std::int64_t kPlayback = 9000;
  const Duration period = milliseconds(100), duration = period * (kFrames - 1);
  const TimePoint first_arrival = clock_.Now();
  std::optional<Reply> delay_reply;
  int sent = 0;
  for (TimePoint t = first_arrival; t < first_arrival + seconds(5); t += milliseconds(1)) {
    clock_.Set(t);
    if (sent < kFrames && t >= first_arrival + milliseconds(150) * sent) {
      const Command frame =
          Cmd(sent + 1, CommandType::kJointSetPoint, {0.01 * sent}, "pan", StartTime::After(period * sent));
      auto immediate = Handle(Playback(kAlice, sent + 1, kPlayback, kFrames, duration, {frame}));
      if (immediate.count(kPlayback)) delay_reply = immediate.at(kPlayback);
      ++sent;
      if (sent < 5) {
        EXPECT_FALSE(delay_reply) << "still estimating after " << sent << " frames";
      }
    }
    Run();
    if (!delay_reply) {
      EXPECT_TRUE(fake_->calls.empty()) << "frames wait in the playback queue";
    }
  }
  ASSERT_TRUE(delay_reply) << "the client learns the delay";
  EXPECT_EQ(delay_reply->signal, Signal::kSuccess);
  // The backlog grows 50 ms per frame: 19 x 50 ms = 0.95 s, plus the margin.
  EXPECT_GE(FromSeconds(delay_reply->values.at(0)), milliseconds(950));
  const TimePoint start = FromWireMicros(static_cast<std::int64_t>(delay_reply->values.at(1)));
  // Every frame ran at start + its offset (within one 1 ms step), never
  // before it arrived: the inter-frame timing is kept exactly.
  ASSERT_EQ(fake_->calls.size(), static_cast<size_t>(kFrames));
  for (int i = 0; i < kFrames; ++i) {
    const Duration late = fake_->calls[static_cast<size_t>(i)].at - (start + period * i);
    EXPECT_GE(late, Duration(0)) << "frame " << i;
    EXPECT_LT(late, milliseconds(1) + std::chrono::microseconds(1)) << "frame " << i;
    EXPECT_GE(fake_->calls[static_cast<size_t>(i)].at, first_arrival + milliseconds(150) * i)
        << "frame " << i;
  }
}

TEST_F(RobotSessionsTest, PlaybackStartsAtTheFirstFrameFromTheSessionsSendTimesWhenTheChannelIsQuiet) {
  // A client whose clock reads 7 days ahead of the server's; its packages
  // take 300-500 us. Connect-time packages (clock rounds) give the history.
  const Duration skew = std::chrono::hours(24 * 7);
  std::int64_t seq = 0;
  auto stamped = [&](Request r, Duration took) {
    r.send_time = clock_.Now() - took + skew;
    return r;
  };
  for (int i = 0; i < 6; ++i) {
    Handle(stamped(Queries(kAlice, ++seq, {Query{.id = 100 + i, .type = QueryType::kClock}}),
                   std::chrono::microseconds(300 + 40 * i)));
    clock_.Advance(milliseconds(1));
  }
  constexpr std::int64_t kPlayback = 9100;
  const Duration period = milliseconds(100);
  const TimePoint first_arrival = clock_.Now();
  const Command frame0 = Cmd(1, CommandType::kJointSetPoint, {0.1}, "pan", StartTime::After(Duration(0)));
  auto immediate = Handle(
      stamped(Playback(kAlice, ++seq, kPlayback, 10, period * 9, {frame0}), std::chrono::microseconds(400)));
  ASSERT_TRUE(immediate.count(kPlayback)) << "decided at the first frame";
  const Reply& r = immediate.at(kPlayback);
  EXPECT_EQ(r.signal, Signal::kSuccess);
  EXPECT_THAT(r.message, HasSubstr("adaptive start"));
  EXPECT_THAT(r.message, HasSubstr("up to 10 % longer"));
  EXPECT_THAT(r.message, HasSubstr("starts 0.01 s below the worst delay"));
  // The worst delay (500 us) + the 200 us spread / 7 delays, less this
  // frame's 400 us, + the 2 ms margin: 2.13 ms (the quick start: 10.1 ms);
  // less one gap's stretch (10 ms, the start lead), but never before the
  // frame's arrival + the 2 ms margin: 2 ms.
  const Duration delay = FromSeconds(r.values.at(0));
  EXPECT_EQ(delay, milliseconds(2));
  const TimePoint start = FromWireMicros(static_cast<std::int64_t>(r.values.at(1)));
  EXPECT_EQ(start, first_arrival + std::chrono::duration_cast<std::chrono::microseconds>(delay));
  // Frames 1-9 every 100 ms, taking 400 us, except frame 4 (6 ms: later than
  // the start covered). Its gap stretches; none runs before it arrived.
  std::vector<TimePoint> arrivals = {first_arrival};
  for (int i = 1; i < 10; ++i) {
    const Duration took = std::chrono::microseconds(i == 4 ? 6000 : 400);
    const TimePoint arrival = first_arrival + period * i + took - std::chrono::microseconds(400);
    while (clock_.Now() + milliseconds(1) <= arrival) {
      clock_.Advance(milliseconds(1));
      Run();
    }
    clock_.Set(arrival);
    const Command frame =
        Cmd(1 + i, CommandType::kJointSetPoint, {0.1 * i}, "pan", StartTime::After(period * i));
    Handle(stamped(Playback(kAlice, ++seq, kPlayback, 10, period * 9, {frame}), took));
    arrivals.push_back(arrival);
  }
  for (int k = 0; k < 300; ++k) {
    clock_.Advance(milliseconds(1));
    Run();
  }
  ASSERT_EQ(fake_->calls.size(), 10u);
  for (int i = 0; i < 10; ++i) {
    const TimePoint at = fake_->calls[static_cast<size_t>(i)].at;
    EXPECT_GE(at, arrivals[static_cast<size_t>(i)] + milliseconds(1))
        << "frame " << i << " ran before it arrived";
    if (i == 0) continue;
    const double gap = ToSeconds(at - fake_->calls[static_cast<size_t>(i) - 1].at);
    EXPECT_GE(gap, 0.099) << "frame " << i;  // within one 1 ms step of the RobotDaemon
    EXPECT_LE(gap, 0.111) << "frame " << i << ": a gap stretches by 10 % at most";
  }
  const double stretched = ToSeconds(fake_->calls[4].at - fake_->calls[3].at);
  EXPECT_GT(stretched, 0.102) << "frame 4's gap took its extra delay";
}

TEST_F(RobotSessionsTest, PlaybackWithoutSendTimesWaitsForFramesAsThePaperDoes) {
  for (int i = 0; i < 6; ++i) {
    Handle(Queries(kAlice, i + 1, {Query{.id = 100 + i, .type = QueryType::kClock}}));
    clock_.Advance(milliseconds(1));
  }
  const Command frame0 = Cmd(1, CommandType::kJointSetPoint, {0.1}, "pan", StartTime::After(Duration(0)));
  EXPECT_FALSE(Handle(Playback(kAlice, 7, 9200, 10, milliseconds(900), {frame0})).count(9200));
}

// Soak finding: a playback sequence that met a panic was never answered
// (COMMAND_STATUS said "has not ended" forever).
TEST_F(RobotSessionsTest, APlaybackSentDuringAPanicIsAnsweredNotHeld) {
  Handle(Package(kBob, 1, {}, /*panic=*/true));
  auto r =
      Handle(Playback(kAlice, 1, 500, 20, seconds(2),
                      {Cmd(1, CommandType::kJointSetPoint, {0.1}, "pan", StartTime::After(Duration(0)))}));
  EXPECT_EQ(r.at(1).signal, Signal::kPanic);
  ASSERT_TRUE(r.count(500)) << "the sequence itself is answered";
  EXPECT_EQ(r.at(500).signal, Signal::kPanic);
}

// Soak finding: frames arriving after a panic and its reset were held
// forever by a new sequence waiting for frames it would never see.
TEST_F(RobotSessionsTest, FramesOfASequenceAPanicEndedAreAnsweredEvenAfterTheReset) {
  const auto frame = [](int i) {
    return Cmd(i, CommandType::kJointSetPoint, {0.01 * i}, "pan", StartTime::After(milliseconds(100) * i));
  };
  for (int i = 1; i <= 3; ++i) Handle(Playback(kAlice, i, 600, 20, seconds(2), {frame(i)}));  // buffered
  Handle(Package(kBob, 1, {}, /*panic=*/true));
  const auto during = Replies(kAlice);
  ASSERT_TRUE(during.count(600));
  EXPECT_EQ(during.at(600).signal, Signal::kInterrupted) << "the sequence that never started is answered";
  for (int i = 1; i <= 3; ++i) EXPECT_EQ(during.at(i).signal, Signal::kInterrupted) << "buffered frame " << i;
  Handle(Package(kBob, 2, {Cmd(90, CommandType::kPanicReset)}));
  for (int i = 4; i <= 6; ++i) {
    auto r = Handle(Playback(kAlice, i, 600, 20, seconds(2), {frame(i)}));
    ASSERT_TRUE(r.count(i)) << "frame " << i << " answered at once";
    EXPECT_EQ(r.at(i).signal, Signal::kInterrupted);
    EXPECT_THAT(r.at(i).message, HasSubstr("ended by a panic"));
  }
  Run();
  EXPECT_TRUE(fake_->calls.empty()) << "nothing of the ended sequence ran";
}

// Issue 9 / soak finding 1: a delay-mode set-point lost twice reached the
// server after later ones had run, and ran at once (the head ended at an old
// target).
TEST_F(RobotSessionsTest, ASetPointArrivingAfterALaterOneRanIsAnsweredNotRun) {
  const TimePoint t0 = clock_.Now();
  Handle(Package(kAlice, 1, {Cmd(1, CommandType::kJointSetPoint, {0.2}, "pan", t0 + milliseconds(100))}));
  clock_.Set(t0 + milliseconds(150));
  Run();
  ASSERT_EQ(Replies(kAlice).at(1).signal, Signal::kSuccess);
  auto late =
      Handle(Package(kAlice, 2, {Cmd(2, CommandType::kJointSetPoint, {0.1}, "pan", t0 + milliseconds(50))}));
  ASSERT_TRUE(late.count(2));
  EXPECT_EQ(late.at(2).signal, Signal::kInterrupted);
  EXPECT_THAT(late.at(2).message, HasSubstr("superseded"));
  // Another client's command, or the same client's on another actuator, is not superseded.
  Handle(Package(kBob, 1, {Cmd(3, CommandType::kJointSetPoint, {0.3}, "pan", t0 + milliseconds(60))}));
  Handle(Package(kAlice, 3, {Cmd(4, CommandType::kSetSpeed, {0.1, 0.0}, "", t0 + milliseconds(70))}));
  Run();
  EXPECT_EQ(Replies(kBob).at(3).signal, Signal::kSuccess);
  EXPECT_EQ(Replies(kAlice).at(4).signal, Signal::kSuccess);
  ASSERT_EQ(fake_->calls.size(), 3u);
  for (const auto& call : fake_->calls) {
    EXPECT_FALSE(call.type == CommandType::kJointSetPoint && call.values == std::vector<double>{0.1})
        << "the stale pan 0.1 ran";
  }
}

TEST_F(RobotSessionsTest, PlaybackRefusesFramesBeyondWhatWasDeclared) {
  auto r = Handle(Playback(kAlice, 1, 77, 2, seconds(1),
                           {Cmd(1, CommandType::kStop, {}, "", StartTime::After(seconds(2)))}));
  EXPECT_EQ(r.at(1).signal, Signal::kError);
  EXPECT_THAT(r.at(1).message, HasSubstr("beyond the declared"));
}

TEST_F(RobotSessionsTest, BroadcastsStateAtItsPeriodWithoutDriftUntilCancelled) {
  auto r = Handle(Queries(kAlice, 1, {Query{1, QueryType::kStateStream, "", milliseconds(100)}}));
  ASSERT_EQ(r.at(1).signal, Signal::kSuccess);
  const TimePoint t0 = clock_.Now();
  std::vector<StateSample>& states = states_;
  // A minute of daemon iterations at an irregular 7 ms step.
  while (clock_.Now() < t0 + seconds(60)) {
    Run();
    clock_.Advance(milliseconds(7));
    if ((clock_.Now() - t0) % seconds(1) < milliseconds(7))
      Handle(Queries(kAlice, 100 + states.size(), {}));  // heartbeat
  }
  ASSERT_EQ(states.size(), 600u);
  for (size_t k = 0; k < states.size(); ++k) {
    const TimePoint due = t0 + milliseconds(100) * static_cast<int>(k);
    const TimePoint sampled = states[k].server_time;
    ASSERT_GE(sampled, due) << "sample " << k;
    ASSERT_LT(sampled, due + milliseconds(7)) << "sample " << k << " drifted";
  }
  EXPECT_EQ(states.back().sample, 600);
  EXPECT_EQ(states.back().positions.size(), 1u);
  EXPECT_EQ(states.back().robot, "bot");

  Handle(Queries(kAlice, 1000 + static_cast<std::int64_t>(states.size()),
                 {Query{2, QueryType::kStateStreamCancel, ""}}));
  states.clear();
  for (int i = 0; i < 50; ++i) {
    clock_.Advance(milliseconds(10));
    Run();
  }
  EXPECT_TRUE(states.empty()) << "cancelled";
}

TEST_F(RobotSessionsTest, SharesOneStreamAtTheShortestPeriodAndEndsItWithTheSessions) {
  Handle(Queries(kAlice, 1, {Query{1, QueryType::kStateStream, "", milliseconds(200)}}));
  Handle(Queries(kBob, 1, {Query{1, QueryType::kStateStream, "", milliseconds(50)}}));
  EXPECT_EQ(daemon_->stream_period(), milliseconds(50));
  Handle(Queries(kBob, 2, {Query{2, QueryType::kStateStreamCancel, ""}}));
  EXPECT_EQ(daemon_->stream_period(), milliseconds(200));
  clock_.Advance(seconds(3));
  sessions_->Expire(clock_.Now());
  EXPECT_EQ(daemon_->stream_period(), Duration(0)) << "nobody left to ask";
  auto bad = Handle(Queries(kAlice, 2, {Query{3, QueryType::kStateStream, "", Duration(0)}}));
  EXPECT_EQ(bad.at(3).signal, Signal::kError);
}

}  // namespace
}  // namespace robotalk
