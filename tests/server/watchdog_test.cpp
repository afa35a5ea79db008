// The watchdog's stop of a vanished client (issue 19, items 1 and 10): it
// goes through the RobotDaemon's STOP path as a StopOnly() of what that
// session owns, which a driver cannot refuse; only commands the driver
// accepted are ownership. The fake driver answers SETSPEED with BUSY while a
// GOTO runs, as both shipped drivers do.
#include "robot_daemon.h"
#include "robot_sessions.h"
#include "sessions_fixture.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

namespace robotalk {
namespace {

using std::chrono::milliseconds;
using std::chrono::seconds;
using ::testing::AllOf;
using testing::Cmd, testing::Package, testing::Queries;
using ::testing::Contains;
using testing::FakeDriver;
using ::testing::HasSubstr;
using ::testing::IsEmpty;
using testing::kAlice, testing::kBob;
using ::testing::Not;
using testing::PanRobot;

class WatchdogTest : public testing::RobotSessionsTest {
 protected:
  WatchdogTest() { fake_->goto_updates = 100000; }  // a GOTO that runs until stopped

  // `total` time in 100 ms steps, the watchdog and the RobotDaemon run at
  // each; `alive` (if not 0) sends a heartbeat at each.
  void Pass(Duration total, std::int64_t alive = 0) {
    for (Duration t{0}; t < total; t += milliseconds(100)) {
      clock_.Advance(milliseconds(100));
      if (alive != 0) Handle(Queries(alive, ++heartbeat_seq_[alive], {}));
      sessions_->Expire(clock_.Now());
      Run();
      for (auto& line : sessions_->TakeLog()) log_.push_back(std::move(line));
    }
  }
  std::int64_t Send(std::int64_t client, Command c) {
    Handle(Package(client, ++heartbeat_seq_[client], {std::move(c)}));
    return heartbeat_seq_[client];
  }

  std::map<std::int64_t, std::int64_t> heartbeat_seq_;
  std::vector<std::string> log_;
};

// Issue 19 item 1: `robotalk send pioneer goto 6 0 0`, then kill -9 of that
// CLI: the watchdog's hold was a SETSPEED 0, answered BUSY while the GOTO
// ran and ignored, and the robot drove on to x = 6.
TEST_F(WatchdogTest, InterruptsAVanishedClientsGotoAlthoughTheDriverRefusesSetSpeedDuringIt) {
  Send(kAlice, Cmd(1, CommandType::kGoto, {6, 0, 0}));
  Run();
  fake_->moving = true;
  ASSERT_TRUE(fake_->goto_id.has_value());
  Pass(seconds(3));  // Alice's CLI was killed: no heartbeat
  EXPECT_FALSE(fake_->goto_id.has_value()) << "the GOTO still runs for a client that is gone";
  ASSERT_EQ(fake_->partial_stops.size(), 1u);
  EXPECT_TRUE(fake_->partial_stops[0].base);
  EXPECT_THAT(fake_->partial_stops[0].joints, IsEmpty());
  for (const auto& call : fake_->calls) EXPECT_NE(call.type, CommandType::kSetSpeed) << "no SETSPEED 0 hold";
  EXPECT_THAT(log_, Contains(AllOf(HasSubstr("client 00000000000a11ce vanished"), HasSubstr("the base"))));
}

TEST_F(WatchdogTest, StopsOnlyWhatTheVanishedClientOwnedAndLetsAnotherClientsMotionRunOn) {
  Send(kBob, Cmd(1, CommandType::kJointSetPoint, {0.5}, "pan"));
  Send(kAlice, Cmd(1, CommandType::kGoto, {6, 0, 0}));
  Run();
  fake_->moving = true;
  Pass(seconds(3), kBob);  // Alice vanishes, Bob stays
  ASSERT_EQ(fake_->partial_stops.size(), 1u);
  EXPECT_TRUE(fake_->partial_stops[0].base) << "Alice's GOTO stops";
  EXPECT_THAT(fake_->partial_stops[0].joints, IsEmpty()) << "Bob's pan runs on";
  for (const auto& call : fake_->calls)
    EXPECT_NE(call.type, CommandType::kStop) << "not a STOP of everything";
  EXPECT_EQ(sessions_->joint_owner(0), kBob);

  Send(kAlice, Cmd(2, CommandType::kGoto, {1, 0, 0}));  // Alice comes back with a new session
  Run();
  Pass(seconds(3), kAlice);  // now Bob vanishes
  ASSERT_EQ(fake_->partial_stops.size(), 2u);
  EXPECT_FALSE(fake_->partial_stops[1].base) << "Alice's new GOTO runs on";
  EXPECT_EQ(fake_->partial_stops[1].joints, std::vector<int>{0});
  EXPECT_TRUE(fake_->goto_id.has_value());
}

// Issue 19 item 10: a command the driver refused (BUSY) was recorded as
// executed, so the watchdog named the client whose SETSPEED was refused and
// the GOTO's owner got no line (and its GOTO no stop).
TEST_F(WatchdogTest, ACommandTheDriverRefusedOwnsNothing) {
  Send(kAlice, Cmd(1, CommandType::kGoto, {6, 0, 0}));
  Run();
  fake_->moving = true;
  Send(kBob, Cmd(1, CommandType::kSetSpeed, {0.5, 0}));
  Run();
  EXPECT_EQ(Replies(kBob).at(1).signal, Signal::kBusy);
  EXPECT_EQ(sessions_->base_owner(), kAlice) << "the refused SETSPEED took the base";

  Pass(seconds(3), kAlice);  // Bob vanishes: he moved nothing
  EXPECT_THAT(fake_->partial_stops, IsEmpty());
  EXPECT_THAT(log_, Not(Contains(HasSubstr("client 0000000000000b0b vanished; stopping"))));
  EXPECT_TRUE(fake_->goto_id.has_value());

  Pass(seconds(3));  // then Alice
  ASSERT_EQ(fake_->partial_stops.size(), 1u);
  EXPECT_TRUE(fake_->partial_stops[0].base);
  EXPECT_FALSE(fake_->goto_id.has_value());
  EXPECT_THAT(log_, Contains(AllOf(HasSubstr("client 00000000000a11ce vanished"), HasSubstr("the base"))));
}

// A delay-mode command that became due just as its client's session
// expired: the RobotDaemon took it before the watchdog flushed the queue, so
// the watchdog's stop did not cover it. It is stopped as soon as it is filed.
TEST_F(WatchdogTest, StopsACommandThatRanJustAsItsClientExpired) {
  const TimePoint start = clock_.Now() + milliseconds(2500);
  Send(kAlice, Cmd(1, CommandType::kJointSetPoint, {0.5}, "pan", start));
  clock_.Advance(milliseconds(2500));
  daemon_->RunOnce(clock_.Now());  // runs the JOINT_SETPOINT; its record waits in the outbox
  ASSERT_EQ(sessions_->Expire(clock_.Now()).size(), 1u);
  EXPECT_THAT(fake_->partial_stops, IsEmpty()) << "Alice owned nothing yet";
  Collect();
  Run();
  ASSERT_EQ(fake_->partial_stops.size(), 1u) << "the set-point of a client that is gone runs on";
  EXPECT_EQ(fake_->partial_stops[0].joints, std::vector<int>{0});
  EXPECT_EQ(sessions_->joint_owner(0), 0);
}

TEST_F(WatchdogTest, AClientsStopStillStopsEverythingAndInterruptsTheGoto) {
  Send(kAlice, Cmd(1, CommandType::kGoto, {6, 0, 0}));
  Run();
  Send(kBob, Cmd(1, CommandType::kStop));
  Run();
  ASSERT_FALSE(fake_->calls.empty());
  EXPECT_EQ(fake_->calls.back().type, CommandType::kStop);
  EXPECT_THAT(fake_->partial_stops, IsEmpty());
  EXPECT_EQ(Replies(kAlice).at(1).signal, Signal::kInterrupted);
  EXPECT_EQ(sessions_->base_owner(), 0);
}

// A driver written before StopOnly() existed (or one that does not
// override it) stops everything: more than asked, never less.
TEST(DriverContract, StopOnlyStopsEverythingUnlessADriverOverridesIt) {
  FakeDriver driver(PanRobot());
  std::vector<Completion> done;
  ASSERT_TRUE(driver.Execute(DriverCommand{.id = 7, .type = CommandType::kGoto, .num_values = 3}, {}, done)
                  .in_progress);
  const int pan = 0;
  driver.Driver::StopOnly(StopScope{.joints = {&pan, 1}, .base = false}, {}, done);
  ASSERT_FALSE(driver.calls.empty());
  EXPECT_EQ(driver.calls.back().type, CommandType::kStop);
  ASSERT_EQ(done.size(), 1u);
  EXPECT_EQ(done[0].id, 7);
  EXPECT_EQ(done[0].signal, Signal::kInterrupted);
}

// Item 10 at the RobotDaemon: only SUCCESS, MODIFIED and in-progress answers
// are ownership ("executed"); the audit lines (--log-executions) say what the
// driver refused as refused.
TEST(RobotDaemonAudit, RecordsARefusedCommandAsRefusedAndNotAsExecuted) {
  ManualClock clock;
  auto driver = std::make_unique<FakeDriver>(PanRobot());
  RobotDaemon daemon("bot", "fake", std::move(driver), clock, RobotDaemonOptions{.log_executions = true});
  const auto motion = [](CommandId id, CommandType type, std::vector<double> v) {
    QueuedItem item;
    item.client_id = kAlice;
    item.command = DriverCommand{.id = id, .type = type, .num_values = static_cast<int>(v.size())};
    std::copy(v.begin(), v.end(), item.command.values.begin());
    return item;
  };
  daemon.Submit(motion(1, CommandType::kGoto, {6, 0, 0}));
  daemon.Submit(motion(2, CommandType::kSetSpeed, {0.5, 0}));
  daemon.RunOnce(clock.Now());
  DaemonOutput out;
  daemon.TakeOutput(out);
  ASSERT_EQ(out.executed.size(), 1u);
  EXPECT_EQ(out.executed[0].type, CommandType::kGoto);
  ASSERT_EQ(out.audit.size(), 2u);
  EXPECT_THAT(out.audit[0], HasSubstr("executed client 00000000000a11ce command 1 GOTO -> in progress"));
  EXPECT_THAT(out.audit[1], HasSubstr("refused client 00000000000a11ce command 2 SETSPEED -> BUSY"));
  EXPECT_THAT(out.audit[1], HasSubstr("GOTO in progress"));
}

}  // namespace
}  // namespace robotalk
