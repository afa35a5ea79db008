#include "robot_daemon.h"

#include "daemon_fixture.h"
#include "fake_driver.h"
#include "queued_items.h"
#include "support/test_clients.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cstdlib>
#include <new>
#include <thread>

// Counts heap allocations (operator new) while `g_counting` is set, to show
// that the RobotDaemon's steady state does not allocate.
namespace {
std::atomic<bool> g_counting{false};
std::atomic<long> g_allocations{0};
}  // namespace

// GCC cannot see that malloc pairs with free through the replaced operators.
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
void* operator new(std::size_t n) {
  if (g_counting) ++g_allocations;
  if (void* p = std::malloc(n ? n : 1)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }

namespace robotalk {
namespace {

using std::chrono::milliseconds;
using std::chrono::seconds;
using testing::FakeDriver;
using ::testing::HasSubstr;
using testing::JointStateQuery;
using testing::Motion;
using testing::PanRobot;

using testing::kAlice;

class RobotDaemonTest : public testing::DaemonOnManualClock<> {
 protected:
  RobotDaemonTest() : DaemonOnManualClock(RobotDaemonOptions{.driver_call_bound = milliseconds(200)}) {}
  // What RobotSessions does with a state query due now: answered on receipt
  // from the snapshot the RobotDaemon published (appended to `direct`), else queued.
  void Ask(QueuedItem query, std::vector<DaemonOutput::Answer>& direct) {
    if (Reply r; daemon_->snapshot().Answer(query, r)) {
      direct.push_back({query.client_id, std::move(r)});
      return;
    }
    daemon_->Submit(std::move(query));
  }
};

TEST_F(RobotDaemonTest, ContainsADriverThatThrowsAnswersErrorNamingItAndHoldsTheRobotInPanic) {
  fake_->throw_on_execute = "serial port write failed";
  daemon_->Submit(Motion(7, CommandType::kJointSetPoint, {0.5}, 0));
  const auto replies = Run();
  ASSERT_EQ(replies.size(), 1u);
  EXPECT_EQ(replies[0].client_id, kAlice);
  EXPECT_EQ(replies[0].reply.id, 7);
  EXPECT_EQ(replies[0].reply.signal, Signal::kError);
  EXPECT_THAT(replies[0].reply.message,
              HasSubstr("driver 'fake' threw in Execute: serial port write failed"));
  EXPECT_TRUE(daemon_->in_panic());
  EXPECT_TRUE(fake_->halted) << "the robot is halted";
  EXPECT_THAT(daemon_->fault(), HasSubstr("serial port write failed"));
  ASSERT_FALSE(out_.log.empty());
  EXPECT_THAT(out_.log[0], HasSubstr("DRIVER FAULT"));

  // Nothing reaches the driver until the panic is reset.
  fake_->throw_on_execute.reset();
  daemon_->Submit(Motion(8, CommandType::kJointSetPoint, {0.2}, 0));
  auto later = Run();
  ASSERT_EQ(later.size(), 1u);
  EXPECT_EQ(later[0].reply.signal, Signal::kInterrupted);
  EXPECT_EQ(fake_->calls.size(), 1u);

  EXPECT_TRUE(daemon_->ResetPanic());
  Run();
  EXPECT_FALSE(fake_->halted);
  daemon_->Submit(Motion(9, CommandType::kJointSetPoint, {0.2}, 0));
  auto after = Run();
  ASSERT_EQ(after.size(), 1u);
  EXPECT_EQ(after[0].reply.signal, Signal::kSuccess);
  EXPECT_DOUBLE_EQ(fake_->position, 0.2);
}

// A driver whose Update blocks until told, to overrun the call bound.
class BlockingDriver : public FakeDriver {
 public:
  using FakeDriver::FakeDriver;
  void Update(TimePoint, std::vector<Completion>&) override {
    entered = true;
    while (!release) std::this_thread::sleep_for(milliseconds(1));
  }
  std::atomic<bool> entered{false}, release{false};
};

TEST(RobotDaemonOverrun, HoldsTheRobotInPanicWhenADriverCallOverrunsItsBound) {
  ManualClock clock;
  auto driver = std::make_unique<BlockingDriver>(PanRobot());
  BlockingDriver* blocking = driver.get();
  RobotDaemon daemon("bot", "slow", std::move(driver), clock,
                     RobotDaemonOptions{.driver_call_bound = milliseconds(200)});
  std::thread robot_daemon([&] { daemon.RunOnce(clock.Now()); });
  while (!blocking->entered) std::this_thread::sleep_for(milliseconds(1));
  clock.Advance(milliseconds(100));
  EXPECT_FALSE(daemon.CheckOverrun(clock.Now())) << "within the bound";
  clock.Advance(milliseconds(150));
  EXPECT_TRUE(daemon.CheckOverrun(clock.Now()));
  EXPECT_FALSE(daemon.CheckOverrun(clock.Now())) << "reported once";
  EXPECT_TRUE(daemon.in_panic());
  EXPECT_THAT(daemon.fault(), HasSubstr("driver 'slow' Update has run for 0.25 s (the bound is 0.2 s)"));
  blocking->release = true;
  robot_daemon.join();
  daemon.RunOnce(clock.Now());  // halts the driver after the late return
  EXPECT_TRUE(blocking->halted);
  // Review of issue 20: a query is not answered from the snapshot while the
  // panic has a reason (an overrun, the latch): the RobotDaemon's answer names it.
  const QueuedItem query = JointStateQuery(1);
  Reply reply;
  daemon.snapshot().Answer(query, reply);  // asks for snapshots
  daemon.RunOnce(clock.Now());
  EXPECT_FALSE(daemon.snapshot().Answer(query, reply)) << "answered without the panic's reason";
}

TEST_F(RobotDaemonTest, DoesNotAllocateInItsSteadyStateOfDriverUpdatesAndStateSamples) {
  daemon_->SetStream(kAlice, milliseconds(1));
  // Warm up: the first iterations size the buffers.
  for (int i = 0; i < 20; ++i) {
    clock_.Advance(milliseconds(1));
    Run();
  }
  g_allocations = 0;
  g_counting = true;
  for (int i = 0; i < 1000; ++i) {
    clock_.Advance(milliseconds(1));
    daemon_->RunOnce(clock_.Now());
    if (i % 10 == 9) {
      g_counting = false;  // the ServerDaemon's side may allocate; it is not the real-time path
      daemon_->TakeOutput(out_);
      g_counting = true;
    }
  }
  g_counting = false;
  EXPECT_EQ(g_allocations.load(), 0) << "allocations on the RobotDaemon's path in 1000 iterations";
  EXPECT_GE(fake_->updates, 100) << "one Update per 10 ms driver period";
}

TEST_F(RobotDaemonTest, RunsTheWatchdogsStopOnlyWhenTheRobotIsMoving) {
  daemon_->QueueStop(/*only_if_moving=*/true);
  Run();
  EXPECT_TRUE(fake_->calls.empty()) << "at rest: no STOP needed";
  fake_->moving = true;
  daemon_->QueueStop(/*only_if_moving=*/true);
  Run();
  ASSERT_EQ(fake_->calls.size(), 1u);
  EXPECT_EQ(fake_->calls[0].type, CommandType::kStop);
  EXPECT_TRUE(out_.replies.empty()) << "the server's own STOP has nobody to answer";
}

// Issue 11: a query crossed the RobotDaemon's thread (its lock, a wake-up,
// the outbox, an eventfd) even when the state it reads had not changed.
TEST_F(RobotDaemonTest, AnswersAQueryOnReceiptFromTheStateOfItsLastIteration) {
  daemon_->Submit(Motion(1, CommandType::kJointSetPoint, {0.5}, 0));
  std::vector<DaemonOutput::Answer> direct;
  Ask(JointStateQuery(2), direct);
  EXPECT_TRUE(direct.empty()) << "no snapshot yet: queued behind the set-point";
  auto replies = Run();
  ASSERT_EQ(replies.size(), 2u);
  EXPECT_EQ(replies[1].reply.values.at(0), 0.5) << "the query ran after the set-point";

  clock_.Advance(milliseconds(1));
  Ask(JointStateQuery(3), direct);
  ASSERT_EQ(direct.size(), 1u) << "answered on receipt, without the RobotDaemon's thread";
  EXPECT_EQ(direct[0].client_id, kAlice);
  EXPECT_EQ(direct[0].reply.id, 3);
  EXPECT_EQ(direct[0].reply.signal, Signal::kSuccess);
  EXPECT_EQ(direct[0].reply.values.at(0), 0.5);
  EXPECT_EQ(direct[0].reply.exec_time, clock_.Now());
  EXPECT_EQ(daemon_->snapshot().answered(), 1u);
}

TEST_F(RobotDaemonTest, AQueryWaitsForACommandDueBeforeItAndForAStaleSnapshot) {
  std::vector<DaemonOutput::Answer> direct;
  Ask(JointStateQuery(1), direct);
  Run();  // snapshots from now on
  daemon_->Submit(Motion(2, CommandType::kJointSetPoint, {0.25}, 0));
  Ask(JointStateQuery(3), direct);
  EXPECT_TRUE(direct.empty()) << "the set-point has not run yet";
  auto replies = Run();
  ASSERT_EQ(replies.size(), 2u);
  EXPECT_EQ(replies[1].reply.values.at(0), 0.25);

  clock_.Advance(milliseconds(11));  // over the driver period (10 ms): Update is due
  Ask(JointStateQuery(4), direct);
  EXPECT_TRUE(direct.empty()) << "older than a driver period: queued";
  EXPECT_EQ(Run().size(), 1u);

  clock_.Advance(milliseconds(1));
  std::vector<QueuedItem> flushed;
  daemon_->Panic(flushed);
  Ask(JointStateQuery(5), direct);
  EXPECT_TRUE(direct.empty()) << "panic raised, the driver not halted yet: queued behind the halt";
  Run();
  clock_.Advance(milliseconds(1));
  Ask(JointStateQuery(6), direct);
  EXPECT_EQ(direct.size(), 1u) << "halted, as the snapshot says";
}

// Issue 13: a driver that finds its robot in a state that must stop it (a
// humanoid that fell) says so through Driver::Fault(); the server halts it and
// holds it in panic like a throwing driver, and names the condition.
TEST_F(RobotDaemonTest, HaltsAndHoldsInPanicARobotWhoseDriverReportsAFault) {
  daemon_->Submit(Motion(1, CommandType::kGoto, {1.0, 0.0, 0.0}));
  Run();
  ASSERT_TRUE(fake_->goto_id.has_value());
  fake_->fault = "the robot has fallen (torso tilt 0.71 rad)";
  clock_.Advance(milliseconds(20));
  const auto replies = Run();
  EXPECT_TRUE(daemon_->in_panic());
  EXPECT_TRUE(fake_->halted);
  EXPECT_THAT(daemon_->fault(), HasSubstr("driver 'fake' reports: the robot has fallen"));
  ASSERT_EQ(replies.size(), 1u);
  EXPECT_EQ(replies[0].reply.signal, Signal::kInterrupted) << "the running GOTO";
  // A query says why the robot is in panic (queued, not answered on receipt).
  std::vector<DaemonOutput::Answer> direct;
  Ask(JointStateQuery(2), direct);
  EXPECT_TRUE(direct.empty());
  const auto answers = Run();
  ASSERT_EQ(answers.size(), 1u);
  EXPECT_EQ(answers[0].reply.signal, Signal::kSuccess);
  EXPECT_THAT(answers[0].reply.message,
              HasSubstr("is in panic: driver 'fake' reports: the robot has fallen"));
  // The same condition after PANIC_RESET does not halt again; a new one does.
  EXPECT_TRUE(daemon_->ResetPanic());
  clock_.Advance(milliseconds(20));
  Run();
  EXPECT_FALSE(daemon_->in_panic());
  fake_->fault = "";
  clock_.Advance(milliseconds(20));
  Run();
  fake_->fault = "the robot has fallen (torso tilt 0.80 rad)";
  clock_.Advance(milliseconds(20));
  Run();
  EXPECT_TRUE(daemon_->in_panic());
}

// A server clock need not be the steady clock (an offset, a simulated one):
// the thread must sleep for the distance to a start time on *its* clock.
TEST(RobotDaemonThread, RunsATimedCommandAtItsTimeOnAClockAheadOfTheSteadyClock) {
  SteadyClock steady;
  OffsetClock clock(steady, seconds(1000));
  for (const bool precise : {true, false}) {
    auto driver = std::make_unique<FakeDriver>(PanRobot());
    FakeDriver* fake = driver.get();
    RobotDaemon daemon("bot", "fake", std::move(driver), clock,
                       RobotDaemonOptions{.precise_timing = precise});
    daemon.Start();
    QueuedItem item = Motion(1, CommandType::kJointSetPoint, {0.2}, 0);
    item.has_start_time = true;
    item.start = clock.Now() + milliseconds(50);
    const TimePoint start = item.start;
    daemon.Submit(std::move(item));
    // Bounded real-time wait (the thread sleeps on the steady clock); before
    // the fix it slept until the steady clock read the start: 1000 s.
    bool answered = false;
    DaemonOutput out;
    for (int i = 0; i < 400 && !answered; ++i) {
      std::this_thread::sleep_for(milliseconds(5));
      daemon.TakeOutput(out);
      for (const auto& a : out.replies) answered = answered || a.reply.id == 1;
    }
    daemon.Stop();
    EXPECT_TRUE(answered) << "precise " << precise;
    ASSERT_EQ(fake->calls.size(), 1u) << "precise " << precise;
    EXPECT_GE(fake->calls[0].at, start);
    EXPECT_LT(fake->calls[0].at, start + milliseconds(500));
  }
}

// Issue 11 item 4: the timing option, applied on the RobotDaemon's thread.
TEST(RobotDaemonTiming, SaysWhichTimingItsThreadRunsWith) {
  ManualClock clock;
  for (const bool precise : {true, false}) {
    RobotDaemon daemon("bot", "fake", std::make_unique<FakeDriver>(PanRobot()), clock,
                       RobotDaemonOptions{.precise_timing = precise});
    EXPECT_EQ(daemon.timing(), "");
    daemon.Start();
    for (int i = 0; i < 200 && daemon.timing().empty(); ++i) std::this_thread::sleep_for(milliseconds(5));
    daemon.Stop();
    if (precise && std::getenv("ROBOTALK_PRECISE_TIMING") == nullptr) {
      EXPECT_THAT(daemon.timing(), HasSubstr("final spin 50 us"));
      EXPECT_THAT(daemon.timing(), ::testing::AnyOf(HasSubstr("SCHED_FIFO priority 10"),
                                                    HasSubstr("SCHED_FIFO not permitted")));
    } else if (!precise) {
      EXPECT_THAT(daemon.timing(), HasSubstr("precise_timing off"));
    }
    DaemonOutput out;
    daemon.TakeOutput(out);
    EXPECT_THAT(out.log, ::testing::Contains(HasSubstr("RobotDaemon timing: " + daemon.timing())));
  }
}

}  // namespace
}  // namespace robotalk

namespace robotalk {
namespace {

// Issue 23, eleventh session: with LogLateStarts (the server's --log-playback)
// a command begun more than 1 ms after its start time is logged with what the
// thread did before it, and a timed item handed over after its start too; one
// begun within 1 ms is not.
TEST_F(RobotDaemonTest, WithLateStartsLoggedACommandBegunMoreThanAMillisecondLateIsExplained) {
  daemon_->LogLateStarts(true);
  QueuedItem on_time = Motion(7, CommandType::kJointSetPoint, {0.1}, 0);
  on_time.has_start_time = true;
  on_time.start = clock_.Now() + milliseconds(5);
  QueuedItem late = Motion(8, CommandType::kJointSetPoint, {0.2}, 0);
  late.has_start_time = true;
  late.start = clock_.Now() + milliseconds(20);
  daemon_->Submit(std::move(on_time));
  daemon_->Submit(std::move(late));
  clock_.Advance(milliseconds(5) + std::chrono::microseconds(900));  // 0.9 ms after command 7's start
  Run();
  clock_.Advance(milliseconds(14) + std::chrono::microseconds(100) + milliseconds(2) +
                 std::chrono::microseconds(500));
  Run();  // 2.5 ms after command 8's start
  std::vector<std::string> late_lines;
  for (const std::string& line : out_.log)
    if (line.find("late start") != std::string::npos) late_lines.push_back(line);
  ASSERT_EQ(late_lines.size(), 1u);
  EXPECT_THAT(late_lines[0], HasSubstr("command 8 ran 2.500 ms after its start"));
  EXPECT_THAT(late_lines[0], HasSubstr("this one began at 2.500"));
  // Handed over after its start.
  QueuedItem handed_late = Motion(9, CommandType::kJointSetPoint, {0.3}, 0);
  handed_late.has_start_time = true;
  handed_late.start = clock_.Now() - milliseconds(3);
  daemon_->Submit(std::move(handed_late));
  Run();
  EXPECT_THAT(out_.log, ::testing::Contains(HasSubstr("command 9 handed over 3.000 ms after its start")));
}

}  // namespace
}  // namespace robotalk
