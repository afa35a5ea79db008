// Issue 19 item 8: every per-session store of the server has a bound in
// bytes and freed state is freed. The reproducers (well-formed packages that
// grew the server to gigabytes) as deterministic tests: they count the bytes
// and entries the stores account, never RSS or time.
#include "robot_sessions.h"

#include "robotalk/server.h"
#include "sessions_fixture.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdio>
#include <string>
#include <utility>

namespace robotalk {
namespace {

using std::chrono::milliseconds;
using std::chrono::seconds;
using namespace robotalk::testing;  // the fixture
using ::testing::HasSubstr;

Reply Answer(CommandId id, std::string message) {
  Reply r;
  r.id = id;
  r.signal = Signal::kError;
  r.message = std::move(message);
  r.values = {1.0, 2.0, 3.0};
  return r;
}

TEST(ReplyCache, StaysUnderItsByteBudgetWithLongRepliesAndKeepsTheLatestPackages) {
  ReplyCache cache(ReplyCache::Limits{.max_packages = 1024, .max_bytes = 256 * 1024});
  CommandId next = 1;
  for (std::int64_t seq = 1; seq <= 1024; ++seq) {
    std::vector<CommandId> ids;
    for (int i = 0; i < 100; ++i) ids.push_back(next++);
    cache.RecordPackage(seq, ids);
    for (CommandId id : ids) cache.RecordReply(Answer(id, std::string(500, 'x')));
    ASSERT_LE(cache.bytes(), 256u * 1024) << "package " << seq;
  }
  EXPECT_LT(cache.packages(), 10u) << "100 replies of 500 bytes take ~60 KiB a package";
  EXPECT_FALSE(cache.HasPackage(1));
  ASSERT_TRUE(cache.HasPackage(1024));
  EXPECT_EQ(cache.RepliesFor(1024).size(), 100u);
  EXPECT_EQ(cache.RepliesFor(1024).front().message, std::string(500, 'x'));
  EXPECT_FALSE(cache.Lookup(1)) << "forgotten with its package";
}

TEST(ReplyCache, CountsWhatItHoldsAndReturnsToEmpty) {
  ReplyCache cache(ReplyCache::Limits{.max_packages = 2, .max_bytes = 1 << 20});
  cache.RecordPackage(1, {1});
  const std::size_t one = cache.bytes();
  EXPECT_GT(one, 0u);
  cache.RecordReply(Answer(1, std::string(1000, 'm')));
  EXPECT_GE(cache.bytes(), one + 1000 + 3 * sizeof(double)) << "the message and values count";
  cache.RecordPackage(2, {2});
  cache.RecordPackage(3, {3});
  cache.RecordPackage(4, {4});
  EXPECT_EQ(cache.packages(), 2u);
  EXPECT_FALSE(cache.Lookup(1));
  // Items still waiting when their package is forgotten keep a small entry
  // until their reply comes; that reply is sent, not kept.
  EXPECT_TRUE(cache.Lookup(2)) << "waiting";
  cache.RecordReply(Answer(2, "done"));
  EXPECT_FALSE(cache.Lookup(2));
  cache.RecordReply(Answer(3, "done"));
  cache.RecordReply(Answer(4, "done"));
  cache.RecordPackage(5, {5});
  cache.RecordPackage(6, {6});
  cache.RecordReply(Answer(5, "done"));
  cache.RecordReply(Answer(6, "done"));
  const std::size_t two = cache.bytes();
  cache.RecordPackage(7, {7});
  cache.RecordPackage(8, {8});
  cache.RecordReply(Answer(7, "done"));
  cache.RecordReply(Answer(8, "done"));
  EXPECT_EQ(cache.packages(), 2u);
  EXPECT_EQ(cache.bytes(), two) << "what it forgot was freed from the count";
}

TEST(ReplyCache, KeepsAPlaybackIdSharedByItsPackagesUntilTheLastIsForgotten) {
  ReplyCache cache(ReplyCache::Limits{.max_packages = 2, .max_bytes = 1 << 20});
  cache.RecordPackage(1, {1, 100});
  cache.RecordPackage(2, {2, 100});
  cache.RecordPackage(3, {3});  // forgets package 1; 100 is still package 2's
  cache.RecordReply(Answer(100, "delay"));
  ASSERT_EQ(cache.RepliesFor(2).size(), 1u);
  EXPECT_EQ(cache.RepliesFor(2).front().id, 100);
}

class SessionMemoryTest : public RobotSessionsTest {
 protected:
  explicit SessionMemoryTest(SessionOptions options = {})
      : RobotSessionsTest(BaseType::kDifferential, std::move(options)) {}
};

// The first reproducer: packages of 1,500 commands naming long
// unknown joints filled 243 MB of reply cache per session.
TEST_F(SessionMemoryTest, LongNamedUnknownJointsKeepTheReplyCacheUnderItsBudget) {
  const SessionOptions defaults;
  CommandId id = 1;
  for (std::int64_t seq = 1; seq <= 64; ++seq) {
    std::vector<Command> commands;
    for (int i = 0; i < 1500; ++i) {
      commands.push_back(
          Cmd(id++, CommandType::kJointSetPoint, {0.1}, std::string(200, 'j') + std::to_string(i)));
    }
    auto replies = Handle(Package(kAlice, seq, commands));
    ASSERT_EQ(replies.size(), 1500u);
    const Reply& first = replies.begin()->second;
    ASSERT_EQ(first.signal, Signal::kError);
    EXPECT_LT(first.message.size(), 160u) << first.message;
    EXPECT_THAT(first.message, HasSubstr("(201 bytes)"));
    ASSERT_LE(sessions_->memory(kAlice).reply_cache, defaults.replies.max_bytes) << "package " << seq;
  }
  EXPECT_LE(defaults.replies.max_bytes, 1u << 20) << "the documented goal: at most 1 MiB a session";
}

class SmallReplyCacheTest : public SessionMemoryTest {
 protected:
  SmallReplyCacheTest() : SessionMemoryTest(SessionOptions{.replies = {.max_packages = 4}}) {}
};

TEST_F(SmallReplyCacheTest, ARetransmissionOfAForgottenPackageIsAnsweredAndNeverRunsTwice) {
  Handle(Package(kAlice, 1, {Cmd(1, CommandType::kJointSetPoint, {0.2}, "pan")}));
  Run();
  ASSERT_EQ(fake_->calls.size(), 1u);
  ASSERT_EQ(Replies(kAlice).at(1).signal, Signal::kSuccess);
  for (std::int64_t seq = 2; seq <= 10; ++seq)
    Handle(Queries(kAlice, seq, {Query{seq, QueryType::kClock, ""}}));
  // Package 1 again (its reply was lost): acknowledged, not run, answered.
  auto again = Handle(Package(kAlice, 1, {Cmd(1, CommandType::kJointSetPoint, {0.2}, "pan")}));
  EXPECT_EQ(last_.batch.ack_sequence, 1);
  ASSERT_EQ(again.count(1), 1u) << "a defined answer, not silence the client would re-ask forever";
  EXPECT_EQ(again.at(1).signal, Signal::kError);
  EXPECT_THAT(again.at(1).message, HasSubstr("does not run again"));
  EXPECT_THAT(again.at(1).message, HasSubstr("outcome is unknown"));
  Run();
  EXPECT_EQ(fake_->calls.size(), 1u);
}

TEST_F(SmallReplyCacheTest, ACommandStillWaitingIsNotCalledForgottenAndItsReplyStillComes) {
  const TimePoint later = clock_.Now() + seconds(5);
  Handle(Package(kAlice, 1, {Cmd(1, CommandType::kJointSetPoint, {0.2}, "pan", later)}));
  for (std::int64_t seq = 2; seq <= 10; ++seq)
    Handle(Queries(kAlice, seq, {Query{seq, QueryType::kClock, ""}}));
  // Its acknowledgement was lost: the client sends it again before it runs.
  auto again = Handle(Package(kAlice, 1, {Cmd(1, CommandType::kJointSetPoint, {0.2}, "pan", later)}));
  EXPECT_EQ(last_.batch.ack_sequence, 1);
  EXPECT_EQ(again.count(1), 0u) << "still queued: its reply comes when it ends";
  clock_.Set(later);
  Run();
  ASSERT_EQ(fake_->calls.size(), 1u);
  EXPECT_EQ(Replies(kAlice).at(1).signal, Signal::kSuccess);
}

TEST_F(SessionMemoryTest, FinishedPlaybacksAreFreedAndLateFramesAnswered) {
  CommandId id = 1;
  std::int64_t seq = 1;
  constexpr int kFrames = 10;
  for (std::int64_t playback = 1000; playback < 1200; ++playback) {
    for (int f = 0; f < kFrames; ++f) {
      Request frame = Playback(kAlice, seq++, playback, kFrames, milliseconds(10) * (kFrames - 1),
                               {Cmd(id++, CommandType::kJointSetPoint, {0.01 * f}, "pan",
                                    StartTime::After(milliseconds(10) * f))});
      frame.max_late = kMaxLateNever;  // the clock jumps 0.3 s at a time: frames run late (no deadline)
      Handle(frame);
    }
    clock_.Advance(milliseconds(300));
    Run();
  }
  const RobotSessions::SessionMemory m = sessions_->memory(kAlice);
  EXPECT_EQ(m.unfinished_playbacks, 0u) << "every sequence had all its frames queued";
  EXPECT_LE(m.playbacks, Session::kMaxEnded * 16) << "only the bounded list of ended ids";
  EXPECT_EQ(m.waiting, 0u);
  EXPECT_EQ(fake_->calls.size(), 200u * kFrames);
  // A late copy-free frame of a finished sequence starts nothing new.
  auto late =
      Handle(Playback(kAlice, seq++, 1199, kFrames, milliseconds(90),
                      {Cmd(id, CommandType::kJointSetPoint, {0.0}, "pan", StartTime::After(Duration(0)))}));
  EXPECT_EQ(late.at(id).signal, Signal::kError);
  EXPECT_THAT(late.at(id).message, HasSubstr("received already"));
  EXPECT_EQ(sessions_->memory(kAlice).unfinished_playbacks, 0u);
}

TEST_F(SessionMemoryTest, APlaybackWithARefusedFrameStillFinishesAndIsFreed) {
  constexpr int kFrames = 10;
  for (int f = 0; f < kFrames; ++f) {
    const std::string joint = f == 3 ? "no_such_joint" : "pan";
    auto r = Handle(Playback(
        kAlice, f + 1, 77, kFrames, milliseconds(10) * (kFrames - 1),
        {Cmd(f + 1, CommandType::kJointSetPoint, {0.01}, joint, StartTime::After(milliseconds(10) * f))}));
    if (f == 3) {
      EXPECT_EQ(r.at(4).signal, Signal::kError);
    }
  }
  EXPECT_EQ(sessions_->memory(kAlice).unfinished_playbacks, 0u) << "the refused frame was answered";
}

TEST_F(SessionMemoryTest, UnfinishedPlaybacksAreBoundedPerSessionAndTheRefusalAnswersTheDelayToo) {
  const SessionOptions defaults;
  CommandId id = 1;
  std::map<CommandId, Reply> last;
  for (std::int64_t playback = 1; playback <= static_cast<std::int64_t>(defaults.max_playbacks) + 1;
       ++playback) {
    last = Handle(
        Playback(kAlice, playback, 5000 + playback, 20, seconds(2),
                 {Cmd(id++, CommandType::kJointSetPoint, {0.1}, "pan", StartTime::After(Duration(0)))}));
  }
  EXPECT_EQ(sessions_->memory(kAlice).unfinished_playbacks, defaults.max_playbacks);
  ASSERT_EQ(last.size(), 2u) << "the frame and the delay reply";
  const std::int64_t refused = 5000 + static_cast<std::int64_t>(defaults.max_playbacks) + 1;
  EXPECT_EQ(last.at(refused).signal, Signal::kError);
  EXPECT_THAT(last.at(refused).message,
              HasSubstr("playback sequences unfinished on robot 'bot'; the limit is " +
                        std::to_string(defaults.max_playbacks)));
}

TEST_F(SessionMemoryTest, APanicFreesTheTimedServoEntriesOfTheCommandsItFlushed) {
  const TimePoint later = clock_.Now() + seconds(10);
  std::vector<Command> commands;
  for (CommandId id = 1; id <= 50; ++id) {
    commands.push_back(Cmd(id, CommandType::kJointSetPoint, {0.1}, "pan", later + milliseconds(id)));
  }
  Handle(Package(kAlice, 1, commands));
  EXPECT_EQ(sessions_->memory(kAlice).timed_servos, 50u);
  Handle(Package(kBob, 1, {}, /*panic=*/true));
  Collect();
  EXPECT_EQ(Replies(kAlice).at(7).signal, Signal::kInterrupted);
  EXPECT_EQ(sessions_->memory(kAlice).timed_servos, 0u);
}

// The third reproducer at a small scale: 256 sessions × 10,000
// queued commands took 914 MB and locked legitimate clients out.
class FloodedQueuesTest : public SessionMemoryTest {
 protected:
  FloodedQueuesTest()
      : SessionMemoryTest(
            SessionOptions{.max_queue = 1000, .max_sessions_per_robot = 8, .max_robot_queue = 64}) {}
  // Sends `n` future commands in one package; returns how many were refused.
  std::size_t Flood(std::int64_t client, std::int64_t seq, int n) {
    std::vector<Command> commands;
    for (int i = 0; i < n; ++i) {
      commands.push_back(Cmd(seq * 1000 + i, CommandType::kStop, {}, "", clock_.Now() + seconds(60)));
    }
    std::size_t refused = 0;
    for (const auto& [id, reply] : Handle(Package(client, seq, commands))) {
      refused += reply.signal == Signal::kError;
      last_refusal_ = reply.message;
    }
    return refused;
  }
  std::string last_refusal_;
};

TEST_F(FloodedQueuesTest, AFloodingClientHitsItsBoundAndEveryOtherClientKeepsItsShare) {
  // share = 64 / (2 × 8) = 4 per client; the shared half (32) goes first come.
  EXPECT_EQ(Flood(0x100, 1, 100), 100u - 32u);
  EXPECT_EQ(daemon_->queued(0x100), 32u);
  EXPECT_THAT(last_refusal_, HasSubstr("client 0000000000000100 has 32 commands queued on robot 'bot'; "
                                       "the limit is 4 while the robot's queues are full"));
  for (std::int64_t flooder = 0x101; flooder < 0x107; ++flooder) {
    EXPECT_EQ(Flood(flooder, 1, 100), 96u) << "past the full shared half: its share of 4";
  }
  // The eighth client, legitimate, still gets its share.
  EXPECT_EQ(Flood(kAlice, 1, 4), 0u);
  EXPECT_EQ(daemon_->queued(kAlice), 4u);
  EXPECT_LE(daemon_->queued_total(), 64u) << "the robot's bound";
  EXPECT_EQ(sessions_->memory(kAlice).waiting_bytes, 4 * QueuedItemBytes());
}

TEST_F(FloodedQueuesTest, AClientAloneMayUseTheSharedHalfUpToItsOwnLimit) {
  EXPECT_EQ(Flood(kAlice, 1, 40), 8u);
  EXPECT_EQ(daemon_->queued(kAlice), 32u);
  // The robot ran some: room again.
  clock_.Advance(seconds(61));
  Run();
  EXPECT_EQ(daemon_->queued(kAlice), 0u);
  EXPECT_EQ(Flood(kAlice, 2, 10), 0u);
}

// The documented arithmetic (docs/protocol.md, Bounds): at every default
// bound the stores of the whole server fit in 512 MiB.
TEST(ServerMemoryBound, TheDefaultBoundsKeepTheWholeServerUnder512MiB) {
  const ServerOptions server;
  const SessionOptions session;
  // Per session: its reply cache, its unfinished playbacks (their buffered
  // frames are queued items), the sequence window (at most kMaxUnseen gaps,
  // a vector of pairs: twice that while it grows).
  const std::size_t playback = sizeof(PlaybackSequence) + 64 + 32 * sizeof(Duration);
  const std::size_t window = 2 * SequenceWindow::kMaxUnseen * sizeof(std::pair<std::int64_t, std::int64_t>);
  // The session table's own part of a session (session_table.h): the entry
  // (sizeof(Session): keyed mode's keys, hello and answer included) in its
  // map node, its live-index, nonce-index and key-binding nodes, its `who`
  // string; and, once per server, the nonces of the last kRememberedNonces
  // closed sessions (a set node and a deque slot each).
  constexpr std::size_t kNode = 4 * sizeof(void*);
  const std::size_t table = kNode + sizeof(std::int64_t) + sizeof(Session) +        // sessions_
                            kNode + 2 * sizeof(std::int64_t) +                      // the live index
                            kNode + sizeof(Nonce) + sizeof(std::int64_t) +          // the nonce index
                            kNode + 2 * sizeof(std::int64_t) + sizeof(PublicKey) +  // the key binding
                            128;                                                    // `who`
  const std::size_t remembered = SessionTable::kRememberedNonces * (kNode + 2 * sizeof(Nonce));
  const std::size_t per_session =
      session.replies.max_bytes + session.max_playbacks * playback + window + Session::kMaxEnded * 16 + table;
  const std::size_t queued = server.max_queued_total * QueuedItemBytes();
  const std::size_t total = server.max_sessions * per_session + remembered + queued;
  std::printf(
      "a session at most %zu B (%zu KiB; an unfinished playback %zu B; the table's part %zu B); %zu sessions "
      "%zu MiB; remembered nonces %zu KiB; a waiting item %zu B, queued %zu MiB; total %zu MiB\n",
      per_session, per_session / 1024, playback, table, server.max_sessions,
      server.max_sessions * per_session >> 20, remembered >> 10, QueuedItemBytes(), queued >> 20,
      total >> 20);
  EXPECT_LT(per_session, 1u << 20);
  EXPECT_LT(total, 512u << 20) << "sessions " << server.max_sessions * per_session << " + queued " << queued;
  EXPECT_EQ(SessionTableOptions{}.max_sessions, server.max_sessions) << "one default";
}

}  // namespace
}  // namespace robotalk
