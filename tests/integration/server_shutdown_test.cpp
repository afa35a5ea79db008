// The server's shutdown (Server::Stop, what robotalk-server runs on SIGINT or
// SIGTERM): every robot gets a STOP, the last command its driver gets, and
// nothing that waited runs after it (docs/server.md). A Server with a
// kinematic and an ode robot, RobotClients over real LCM multicast on the
// loopback of a private network namespace (tests/netns_run.sh).
#include "kinematic_driver.h"
#include "ode_driver.h"
#include "robotalk/robot_client.h"
#include "robotalk/server.h"
#include "test_paths.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <atomic>
#include <condition_variable>
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

}  // namespace
}  // namespace robotalk
