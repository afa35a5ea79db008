// The server's shutdown (Server::Stop, what robotalk-server runs on SIGINT or
// SIGTERM): every robot gets a STOP, the last command its driver gets, and
// nothing that waited runs after it (docs/server.md). A Server with a
// kinematic and an ode robot, RobotClients over real LCM multicast on the
// loopback of a private network namespace (tests/netns_run.sh).
#include "kinematic_driver.h"
#include "ode_driver.h"
#include "robotalk/robot_client.h"
#include "robotalk/server.h"
#include "support/observed_driver.h"
#include "test_paths.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <atomic>
#include <condition_variable>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <map>
#include <mutex>
#include <thread>

namespace robotalk {
namespace {

using std::chrono::milliseconds;
using std::chrono::seconds;
using ::testing::HasSubstr;

constexpr const char* kUrl = "udpm://239.255.76.67:7713?ttl=0";

// What each robot's driver was asked, in order ("Execute SETSPEED", "Stop", ...).
struct CallLog {
  void Add(const std::string& robot, std::string what) {
    {
      std::lock_guard lock(mutex);
      calls[robot].push_back(std::move(what));
    }
    changed.notify_all();
  }
  std::vector<std::string> Of(const std::string& robot) {
    std::lock_guard lock(mutex);
    return calls[robot];
  }
  std::size_t Count(const std::string& robot) {
    std::lock_guard lock(mutex);
    return calls[robot].size();
  }
  // Waits until `robot` has more than `n` calls, or `timeout`.
  void WaitForMoreThan(const std::string& robot, std::size_t n, Duration timeout) {
    std::unique_lock lock(mutex);
    changed.wait_for(lock, timeout, [&] { return calls[robot].size() > n; });
  }
  std::mutex mutex;
  std::condition_variable changed;
  std::map<std::string, std::vector<std::string>> calls;
};

// Forwards to a real driver and records the motion calls. When `slow_stop`
// is set, Stop() first waits (at most 2.5 s) for another robot to get a call:
// a driver whose STOP takes time, during which the server must not let any
// other robot start something.
class RecordingDriver final : public Driver {
 public:
  struct SlowStop {
    std::atomic<bool> armed{false};
    std::string other;  // the robot whose next call it waits for
  };
  RecordingDriver(std::string robot, std::unique_ptr<Driver> inner, std::shared_ptr<CallLog> log,
                  std::shared_ptr<SlowStop> slow_stop)
      : robot_(std::move(robot)),
        inner_(std::move(inner)),
        log_(std::move(log)),
        slow_stop_(std::move(slow_stop)) {}
  const RobotModel& model() const override { return inner_->model(); }
  Duration period() const override { return inner_->period(); }
  DriverResult Execute(const DriverCommand& c, TimePoint now, std::vector<Completion>& done) override {
    log_->Add(robot_, std::string("Execute ") + ToString(c.type));
    return inner_->Execute(c, now, done);
  }
  void Update(TimePoint now, std::vector<Completion>& done) override { inner_->Update(now, done); }
  void ReadState(RobotState& s) const override { inner_->ReadState(s); }
  void Stop(TimePoint now, std::vector<Completion>& done) override {
    if (slow_stop_ && slow_stop_->armed.exchange(false)) {
      log_->WaitForMoreThan(slow_stop_->other, log_->Count(slow_stop_->other), milliseconds(2500));
    }
    log_->Add(robot_, "Stop");
    inner_->Stop(now, done);
  }
  void StopOnly(const StopScope& scope, TimePoint now, std::vector<Completion>& done) override {
    log_->Add(robot_, "StopOnly");
    inner_->StopOnly(scope, now, done);
  }
  void Halt(std::vector<Completion>& done) override {
    log_->Add(robot_, "Halt");
    inner_->Halt(done);
  }
  void Resume() override {
    log_->Add(robot_, "Resume");
    inner_->Resume();
  }
  std::string_view Fault() const override { return inner_->Fault(); }

 private:
  std::string robot_;
  std::unique_ptr<Driver> inner_;
  std::shared_ptr<CallLog> log_;
  std::shared_ptr<SlowStop> slow_stop_;
};

class ServerShutdownTest : public ::testing::Test {
 protected:
  ServerShutdownTest() {
    RegisterKinematicDriver(registry_);
    RegisterOdeDriver(registry_);
    for (const std::string inner : {"kinematic", "ode"}) {
      registry_.Register("recorded-" + inner, [this, inner](const DriverConfig& config) {
        return std::make_unique<RecordingDriver>(config.robot_name, registry_.Create(inner, config), log_,
                                                 config.robot_name == "pioneer" ? slow_stop_ : nullptr);
      });
    }
    ServerOptions options;
    options.lcm_url = kUrl;
    const std::string urdf = testing::ProjectModel("pioneer2dx_pantilt.urdf");
    server_ = std::make_unique<Server>(options,
                                       std::vector<RobotSpec>{{"pioneer", "recorded-kinematic", urdf, {}},
                                                              {"rover", "recorded-ode", urdf, {}}},
                                       registry_, clock_);
    server_->Start();
  }
  ~ServerShutdownTest() override { server_->Stop(); }
  std::unique_ptr<RobotClient> Connect(const std::string& robot) {
    ClientOptions options;
    options.lcm_url = kUrl;
    auto client = std::make_unique<RobotClient>(options);
    client->Connect(robot);
    return client;
  }
  // The calls `robot`'s driver got from index `from` on.
  std::vector<std::string> CallsFrom(const std::string& robot, std::size_t from) {
    const auto all = log_->Of(robot);
    return {all.begin() + static_cast<std::ptrdiff_t>(std::min(from, all.size())), all.end()};
  }

  SteadyClock clock_;
  DriverRegistry registry_;
  std::shared_ptr<CallLog> log_ = std::make_shared<CallLog>();
  std::shared_ptr<RecordingDriver::SlowStop> slow_stop_ = std::make_shared<RecordingDriver::SlowStop>();
  std::unique_ptr<Server> server_;
};

TEST_F(ServerShutdownTest, StopsEveryMovingRobotAndInterruptsItsGotoBeforeItReturns) {
  auto pioneer = Connect("pioneer");
  auto rover = Connect("rover");
  ASSERT_EQ(pioneer->SetSpeed(0.3, 0.1).signal, Signal::kSuccess);
  PendingReply drive = rover->Send(Command{.type = CommandType::kGoto, .values = {5.0, 0.0, 0.0}});
  log_->WaitForMoreThan("rover", 0, seconds(5));
  ASSERT_EQ(log_->Of("rover"), std::vector<std::string>{"Execute GOTO"});

  server_->Stop();
  for (const std::string robot : {"pioneer", "rover"}) {
    const auto calls = log_->Of(robot);
    ASSERT_FALSE(calls.empty());
    EXPECT_EQ(calls.back(), "Stop") << robot << ": the shutdown's STOP is the last call its driver got";
  }
  const Reply goto_reply = drive.Wait(seconds(5));
  EXPECT_EQ(goto_reply.signal, Signal::kInterrupted) << goto_reply.message;
  EXPECT_THAT(goto_reply.message, HasSubstr("STOP"));
}

// A robot whose STOP takes time must not let another robot start something
// that was waiting: nothing runs once the shutdown has begun.
TEST_F(ServerShutdownTest, NothingThatWaitedRunsOnAnyRobotOnceTheShutdownHasBegun) {
  auto pioneer = Connect("pioneer");
  auto rover = Connect("rover");
  ASSERT_EQ(pioneer->SetSpeed(0.3, 0.0).signal, Signal::kSuccess);
  // Due 1 s from now on the rover, queued on the server.
  PendingReply later = rover->Send(Command{.type = CommandType::kSetSpeed,
                                           .start_time = StartTime::At(rover->ServerNow() + seconds(1)),
                                           .values = {0.4, 0.0}});
  // Until the server has it: a query behind it in the same session is answered after it was queued.
  EXPECT_EQ(rover->Query(QueryType::kBasePose).signal, Signal::kSuccess);
  const std::size_t rover_before = log_->Count("rover");
  slow_stop_->other = "rover";
  slow_stop_->armed = true;  // the pioneer's STOP waits for a rover call (2.5 s at most)

  server_->Stop();
  EXPECT_EQ(CallsFrom("rover", rover_before), std::vector<std::string>{"Stop"})
      << "after the shutdown began the rover got only its STOP";
  EXPECT_EQ(log_->Of("pioneer").back(), "Stop");
  std::this_thread::sleep_for(milliseconds(200));  // time for a reply, were there one
  EXPECT_FALSE(later.Poll().has_value()) << "it never ran, and nobody says it did";
}

// Once armed, the next Execute of the driver it observes hangs (at most
// 20 s, or until released): a driver call that never returns while the
// server shuts down.
struct Hang final : testing::DriverObserver {
  void Executed(const DriverCommand&, TimePoint) override {
    if (!armed.exchange(false)) return;
    std::unique_lock lock(mutex);
    hung = true;
    changed.notify_all();
    changed.wait_for(lock, seconds(20), [&] { return released; });
    returned = true;
  }
  // Waits until a call hangs, at most `timeout`.
  bool WaitHung(Duration timeout) {
    std::unique_lock lock(mutex);
    return changed.wait_for(lock, timeout, [&] { return hung; });
  }
  void Release() {
    {
      std::lock_guard lock(mutex);
      released = true;
    }
    changed.notify_all();
  }
  bool Hanging() {
    std::lock_guard lock(mutex);
    return hung && !returned;
  }
  std::atomic<bool> armed{false};
  std::mutex mutex;
  std::condition_variable changed;
  bool hung = false;
  bool released = false;
  bool returned = false;
};

// A driver call that hangs while the server shuts down (the ServerDaemon
// that watched the call bound has stopped): the other robot still gets its
// STOP at once, the call is still a fault (its command answered ERROR, the
// robot latched in panic) and the shutdown ends; it once waited for the call
// however long it hung, every robot after it in the list left moving.
TEST(HungDriverShutdown, AHungCallKeepsNoOtherRobotFromItsStopIsAFaultAndTheShutdownEnds) {
  static const SteadyClock clock;  // the thread the shutdown gave up on may read it later
  DriverRegistry registry;
  RegisterKinematicDriver(registry);
  auto log = std::make_shared<CallLog>();
  auto hang = std::make_shared<Hang>();
  registry.Register("hanging-kinematic", [&](const DriverConfig& config) {
    return std::make_unique<RecordingDriver>(
        config.robot_name,
        std::make_unique<testing::ObservedDriver>(registry.Create("kinematic", config), hang), log, nullptr);
  });
  registry.Register("recorded-kinematic", [&](const DriverConfig& config) {
    return std::make_unique<RecordingDriver>(config.robot_name, registry.Create("kinematic", config), log,
                                             nullptr);
  });
  const std::string latch = ::testing::TempDir() + "/hung_driver_shutdown_latch";
  std::remove(latch.c_str());
  ServerOptions options;
  options.lcm_url = kUrl;
  options.driver_call_bound = milliseconds(1500);
  options.panic_latch_path = latch;
  const std::string urdf = testing::ProjectModel("pioneer2dx_pantilt.urdf");
  // The hanging robot first: the shutdown once took the robots in this order.
  Server server(options,
                std::vector<RobotSpec>{{"rover", "hanging-kinematic", urdf, {}},
                                       {"pioneer", "recorded-kinematic", urdf, {}}},
                registry, clock);
  server.Start();
  ClientOptions client_options;
  client_options.lcm_url = kUrl;
  RobotClient pioneer(client_options);
  pioneer.Connect("pioneer");
  RobotClient rover(client_options);
  rover.Connect("rover");
  ASSERT_EQ(pioneer.SetSpeed(0.3, 0.1).signal, Signal::kSuccess);
  hang->armed = true;
  PendingReply drive = rover.Send(Command{.type = CommandType::kGoto, .values = {5.0, 0.0, 0.0}});
  ASSERT_TRUE(hang->WaitHung(seconds(5))) << "the rover's Execute never started";

  const auto begin = std::chrono::steady_clock::now();
  server.Stop();
  const double took = std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count();
  std::printf("Server::Stop returned after %.2f s with the rover's Execute hung (bound 1.5 s)\n", took);
  EXPECT_TRUE(hang->Hanging()) << "the shutdown waited for the hung call (" << took << " s)";
  EXPECT_EQ(server.not_stopped(), std::vector<std::string>{"rover"});
  const auto pioneer_calls = log->Of("pioneer");
  ASSERT_FALSE(pioneer_calls.empty());
  EXPECT_EQ(pioneer_calls.back(), "Stop") << "the other robot got its STOP while the rover's call hung";
  const Reply goto_reply = drive.Wait(seconds(5));
  EXPECT_EQ(goto_reply.signal, Signal::kError) << goto_reply.message;
  EXPECT_THAT(goto_reply.message, HasSubstr("has run for"));
  std::ifstream latched(latch);
  const std::string latch_text((std::istreambuf_iterator<char>(latched)), std::istreambuf_iterator<char>());
  EXPECT_THAT(latch_text, HasSubstr("rover")) << "the fault is on the panic latch";

  // Should the call ever return, the rover's own thread still STOPs it.
  hang->Release();
  const auto until = std::chrono::steady_clock::now() + seconds(5);
  auto rover_calls = log->Of("rover");
  while ((rover_calls.empty() || rover_calls.back() != "Stop") && std::chrono::steady_clock::now() < until) {
    log->WaitForMoreThan("rover", rover_calls.size(), milliseconds(100));
    rover_calls = log->Of("rover");
  }
  ASSERT_FALSE(rover_calls.empty());
  EXPECT_EQ(rover_calls.back(), "Stop");
}

}  // namespace
}  // namespace robotalk
