// A driver that throws from any call, not only Execute (docs/drivers.md): the
// throw is contained, the robot halted and held in panic until PANIC_RESET,
// the fault names the driver, the call and the message, and no Execute runs
// until the reset. And an Execute that overruns the driver-call bound: its
// command answers ERROR as soon as the bound passes; its late result is dropped.
#include "daemon_fixture.h"
#include "fake_driver.h"
#include "queued_items.h"
#include "robot_daemon.h"
#include "support/test_clients.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

namespace robotalk {
namespace {

using std::chrono::milliseconds;
using testing::FakeDriver;
using ::testing::HasSubstr;
using testing::JointStateQuery;
using testing::Motion;
using testing::PanRobot;

using testing::kAlice;

// A FakeDriver that throws from the one call named `throw_in` while armed.
class ThrowingDriver : public FakeDriver {
 public:
  using FakeDriver::FakeDriver;
  void Update(TimePoint now, std::vector<Completion>& done) override {
    MaybeThrow("Update");
    FakeDriver::Update(now, done);
  }
  void ReadState(RobotState& s) const override {
    MaybeThrow("ReadState");
    FakeDriver::ReadState(s);
  }
  void Stop(TimePoint now, std::vector<Completion>& done) override {
    MaybeThrow("Stop");
    FakeDriver::Stop(now, done);
  }
  void Halt(std::vector<Completion>& done) override {
    ++halts;
    MaybeThrow("Halt");
    FakeDriver::Halt(done);
  }
  void Resume() override {
    ++resumes;
    FakeDriver::Resume();  // a driver may fail part-way, after it let the robot go
    MaybeThrow("Resume");
  }

  std::string throw_in;  // "" = never
  bool armed = false;
  int halts = 0, resumes = 0;

 private:
  void MaybeThrow(const std::string& call) const {
    if (armed && call == throw_in) throw std::runtime_error("bus error on " + call);
  }
};

class DriverFaultTest
    : public testing::DaemonOnManualClock<ThrowingDriver, ::testing::TestWithParam<const char*>> {
 protected:
  DriverFaultTest() : DaemonOnManualClock(RobotDaemonOptions{.driver_call_bound = milliseconds(200)}) {
    fake_->throw_in = GetParam();
  }
  std::vector<DaemonOutput::Answer> Run() {
    clock_.Advance(milliseconds(10));  // one driver period: Update runs each time
    std::vector<DaemonOutput::Answer> replies = DaemonOnManualClock::Run();
    for (auto& line : out_.log) log_ += line + "\n";
    return replies;
  }
  // Makes the robot reach the call under test, which throws.
  std::vector<DaemonOutput::Answer> TriggerTheCall() {
    const std::string call = GetParam();
    fake_->armed = true;
    if (call == "Update") return Run();
    if (call == "ReadState") {
      daemon_->Submit(JointStateQuery(5));
      return Run();
    }
    if (call == "Stop") {
      daemon_->Submit(Motion(5, CommandType::kStop, {}));
      return Run();
    }
    if (call == "Halt") {  // a client's panic halts the robot
      std::vector<QueuedItem> flushed;
      daemon_->Panic(flushed);
      return Run();
    }
    // Resume: a panic, then its reset resumes the driver.
    fake_->armed = false;
    std::vector<QueuedItem> flushed;
    daemon_->Panic(flushed);
    Run();
    EXPECT_TRUE(fake_->halted);
    EXPECT_TRUE(daemon_->ResetPanic());
    fake_->armed = true;
    return Run();
  }

  std::string log_;
};

TEST_P(DriverFaultTest, AThrowIsContainedTheRobotHeldInPanicUntilResetAndTheFaultNamesTheCall) {
  const std::string call = GetParam();
  // The robot runs a GOTO when the driver fails.
  daemon_->Submit(Motion(1, CommandType::kGoto, {1.0, 0.0, 0.0}));
  fake_->goto_updates = 1000;
  Run();
  ASSERT_TRUE(fake_->goto_id.has_value());
  const auto executes = [&] {
    return std::count_if(fake_->calls.begin(), fake_->calls.end(),
                         [](const FakeDriver::Call& c) { return c.type != CommandType::kStop; });
  };
  const auto executes_before = executes();

  const auto replies = TriggerTheCall();
  // The driver works again (a Halt that throws keeps throwing): the panic must still hold.
  fake_->armed = call == "Halt";
  const std::string fault = "driver 'fake' threw in " + call + ": bus error on " + call;
  EXPECT_TRUE(daemon_->in_panic()) << call;
  EXPECT_THAT(daemon_->fault(), HasSubstr(fault));
  EXPECT_THAT(log_, HasSubstr("DRIVER FAULT: " + fault));
  if (call == "ReadState" || call == "Stop") {  // the command that met the throw answers ERROR naming it
    const auto it =
        std::find_if(replies.begin(), replies.end(), [](const auto& a) { return a.reply.id == 5; });
    ASSERT_NE(it, replies.end());
    EXPECT_EQ(it->reply.signal, Signal::kError);
    EXPECT_THAT(it->reply.message, HasSubstr(fault));
  }
  // Halted: the GOTO ended (a Halt that threw is followed by a STOP), and
  // the server counts the robot as halted even when Halt itself threw (a
  // reset resumes it, so it was never left "un-halted").
  EXPECT_FALSE(fake_->goto_id.has_value()) << "the GOTO was stopped";
  if (call != "Resume") {  // (there the panic before the reset ended it)
    const auto goto_answer =
        std::find_if(replies.begin(), replies.end(), [](const auto& a) { return a.reply.id == 1; });
    ASSERT_NE(goto_answer, replies.end()) << "the GOTO is answered";
    EXPECT_EQ(goto_answer->reply.signal, Signal::kInterrupted);
  }
  if (call != "Halt") {
    EXPECT_TRUE(fake_->halted) << "the driver is halted after a throw in " << call;
  }

  // No Execute until PANIC_RESET, however long it waits.
  for (int i = 0; i < 3; ++i) {
    daemon_->Submit(Motion(10 + i, CommandType::kJointSetPoint, {0.2}, 0));
    const auto refused = Run();
    ASSERT_FALSE(refused.empty());
    EXPECT_EQ(refused.back().reply.signal, Signal::kInterrupted);
  }
  EXPECT_EQ(executes(), executes_before) << "an Execute ran in panic";
  EXPECT_TRUE(daemon_->in_panic());

  // A query says why.
  daemon_->Submit(JointStateQuery(20));
  const auto answer = Run();
  ASSERT_EQ(answer.size(), 1u);
  EXPECT_THAT(answer[0].reply.message, HasSubstr(fault));

  // PANIC_RESET resumes the halted driver; the robot serves again.
  fake_->armed = false;
  const int resumes_before = fake_->resumes;
  EXPECT_TRUE(daemon_->ResetPanic());
  Run();
  EXPECT_EQ(fake_->resumes, resumes_before + 1) << "the server still saw the robot halted, and resumed it";
  EXPECT_FALSE(fake_->halted);
  daemon_->Submit(Motion(30, CommandType::kJointSetPoint, {0.2}, 0));
  const auto after = Run();
  ASSERT_EQ(after.size(), 1u);
  EXPECT_EQ(after[0].reply.signal, Signal::kSuccess) << after[0].reply.message;
  EXPECT_DOUBLE_EQ(fake_->position, 0.2);
}

INSTANTIATE_TEST_SUITE_P(EveryDriverCall, DriverFaultTest,
                         ::testing::Values("Update", "ReadState", "Stop", "Halt", "Resume"),
                         [](const auto& info) { return std::string(info.param); });

// An Execute that blocks until released, to overrun the call bound.
class SlowExecuteDriver : public FakeDriver {
 public:
  using FakeDriver::FakeDriver;
  DriverResult Execute(const DriverCommand& c, TimePoint now, std::vector<Completion>& done) override {
    entered = true;
    while (!release) std::this_thread::sleep_for(milliseconds(1));
    return FakeDriver::Execute(c, now, done);
  }
  std::atomic<bool> entered{false}, release{false};
};

TEST(DriverCallBound, AnExecutePastTheBoundAnswersErrorAtOnceAndItsLateResultIsDropped) {
  ManualClock clock;
  auto driver = std::make_unique<SlowExecuteDriver>(PanRobot());
  SlowExecuteDriver* slow = driver.get();
  RobotDaemon daemon("bot", "slow", std::move(driver), clock,
                     RobotDaemonOptions{.driver_call_bound = milliseconds(200)});
  DaemonOutput out;
  daemon.Preallocate(out);
  daemon.Submit(Motion(7, CommandType::kGoto, {1.0, 0.0, 0.0}));
  std::thread robot_daemon([&] { daemon.RunOnce(clock.Now()); });
  while (!slow->entered) std::this_thread::sleep_for(milliseconds(1));

  clock.Advance(milliseconds(150));
  EXPECT_FALSE(daemon.CheckOverrun(clock.Now())) << "within the bound";
  daemon.TakeOutput(out);
  EXPECT_TRUE(out.replies.empty()) << "nothing answered before the bound";
  clock.Advance(milliseconds(100));
  EXPECT_TRUE(daemon.CheckOverrun(clock.Now()));
  // Answered while Execute is still running.
  daemon.TakeOutput(out);
  ASSERT_EQ(out.replies.size(), 1u);
  EXPECT_EQ(out.replies[0].client_id, kAlice);
  EXPECT_EQ(out.replies[0].reply.id, 7);
  EXPECT_EQ(out.replies[0].reply.signal, Signal::kError);
  EXPECT_THAT(out.replies[0].reply.message,
              HasSubstr("driver 'slow' Execute has run for 0.25 s (the bound is 0.2 s)"));
  EXPECT_TRUE(daemon.in_panic());

  // The late result (an accepted GOTO) is dropped: no second answer, no ownership.
  slow->release = true;
  robot_daemon.join();
  for (int i = 0; i < 50; ++i) {
    clock.Advance(milliseconds(10));
    daemon.RunOnce(clock.Now());
    daemon.TakeOutput(out);
    EXPECT_TRUE(out.replies.empty()) << "a second answer to the overrun command: "
                                     << out.replies[0].reply.message;
    EXPECT_TRUE(out.executed.empty()) << "the overrun command counted as executed (ownership)";
  }
  EXPECT_TRUE(slow->halted) << "halted after the late return";
  EXPECT_FALSE(slow->goto_id.has_value()) << "the late GOTO was halted, not left running";
}

}  // namespace
}  // namespace robotalk

namespace robotalk {
namespace {

// Gates for a driver call that hangs until released; shared with the driver,
// so a thread given up on may still use them after the test.
struct Gates {
  std::mutex mutex;
  std::condition_variable changed;
  std::atomic<bool> hang_update{false};
  bool update_released = false;
  bool stop_entered = false;
  bool stop_released = false;

  void Wait(bool& released) {
    std::unique_lock lock(mutex);
    changed.wait_for(lock, std::chrono::seconds(20), [&] { return released; });
  }
  void Set(bool& flag) {
    {
      std::lock_guard lock(mutex);
      flag = true;
    }
    changed.notify_all();
  }
  bool WaitFor(bool& flag) {
    std::unique_lock lock(mutex);
    return changed.wait_for(lock, std::chrono::seconds(5), [&] { return flag; });
  }
};

// Its next Update, once armed, hangs until released; its Stop waits for its
// own release.
class GatedDriver final : public FakeDriver {
 public:
  GatedDriver(RobotModel model, std::shared_ptr<Gates> gates) : FakeDriver(std::move(model)), gates_(gates) {}
  void Update(TimePoint now, std::vector<Completion>& done) override {
    if (gates_->hang_update.exchange(false)) gates_->Wait(gates_->update_released);
    FakeDriver::Update(now, done);
  }
  void Stop(TimePoint now, std::vector<Completion>& done) override {
    gates_->Set(gates_->stop_entered);
    gates_->Wait(gates_->stop_released);
    FakeDriver::Stop(now, done);
  }

 private:
  std::shared_ptr<Gates> gates_;
};

// The shutdown gives up on a driver call that has run twice the call bound
// (robotalk::Server measures it, then calls Abandon). A call that returns
// just then, its robot's thread already in the shutdown STOP, is not given
// up on: the robot is being stopped (before: Abandon gave up on whatever call
// ran, the STOP just begun; the server named the robot NOT STOPPED and
// robotalk-server exited during its STOP).
TEST(DriverCallBound, TheShutdownDoesNotGiveUpOnARobotWhoseHungCallReturnedAndWhoseStopRuns) {
  static const SteadyClock clock;  // a thread given up on may read it later
  auto gates = std::make_shared<Gates>();
  // Never deleted when given up on: its thread may still use it.
  auto* robot = new RobotDaemon("bot", "gated", std::make_unique<GatedDriver>(PanRobot(), gates), clock,
                                RobotDaemonOptions{.driver_call_bound = milliseconds(100)});
  gates->hang_update = true;
  robot->Start();
  // The Update hangs past twice the bound: measured as the shutdown does.
  TimePoint measured = clock.Now();
  for (int i = 0; i < 500 && robot->CallRunning(measured) <= milliseconds(200); ++i) {
    std::this_thread::sleep_for(milliseconds(10));
    measured = clock.Now();
  }
  ASSERT_GT(robot->CallRunning(measured), milliseconds(200));
  robot->EndSoon();
  // The hung call returns; the thread goes on to its shutdown STOP.
  gates->Set(gates->update_released);
  ASSERT_TRUE(gates->WaitFor(gates->stop_entered)) << "the shutdown STOP never began";
  const bool abandoned = robot->Abandon(measured);
  gates->Set(gates->stop_released);
  EXPECT_FALSE(abandoned) << "gave up on a robot whose hung call had returned, its STOP running";
  if (!abandoned) {
    EXPECT_TRUE(robot->WaitEnded(std::chrono::seconds(5)));
    robot->Shutdown();
    delete robot;
  }
}

}  // namespace
}  // namespace robotalk
