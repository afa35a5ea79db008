// End to end: a Server with the kinematic driver and RobotClients in one
// process, over real LCM multicast on the loopback of a private network
// namespace (this binary runs under tests/netns_run.sh).
#include "kinematic_driver.h"
#include "robotalk/robot_client.h"
#include "robotalk/server.h"
#include "robotalk/urdf_import.h"
#include "test_paths.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <map>
#include <mutex>
#include <thread>

namespace robotalk {
namespace {

using ::testing::HasSubstr;
using std::chrono::milliseconds;
using std::chrono::seconds;

constexpr const char* kUrl = "udpm://239.255.76.67:7711?ttl=0";

// Records every set-point the driver executes, to prove exactly-once delivery.
struct ExecutionLog {
  std::mutex mutex;
  std::map<double, int> setpoints;  // pan value -> times executed
};

class CountingDriver final : public Driver {
 public:
  CountingDriver(std::unique_ptr<Driver> inner, std::shared_ptr<ExecutionLog> log)
      : inner_(std::move(inner)), log_(std::move(log)) {}
  const RobotModel& model() const override { return inner_->model(); }
  Duration period() const override { return inner_->period(); }
  DriverResult Execute(const DriverCommand& c, TimePoint now, std::vector<Completion>& done) override {
    if (c.type == CommandType::kJointSetPoint) {
      std::lock_guard lock(log_->mutex);
      ++log_->setpoints[c.values[0]];
    }
    return inner_->Execute(c, now, done);
  }
  void Update(TimePoint now, std::vector<Completion>& done) override { inner_->Update(now, done); }
  void ReadState(RobotState& s) const override { inner_->ReadState(s); }
  void Halt(std::vector<Completion>& done) override { inner_->Halt(done); }
  void Resume() override { inner_->Resume(); }

 private:
  std::unique_ptr<Driver> inner_;
  std::shared_ptr<ExecutionLog> log_;
};

class ServerClientTest : public ::testing::Test {
 protected:
  void StartServer(ServerOptions options = {}) {
    RegisterKinematicDriver(registry_);
    registry_.Register("counting", [log = log_, this](const DriverConfig& config) {
      return std::make_unique<CountingDriver>(registry_.Create("kinematic", config), log);
    });
    options.lcm_url = kUrl;
    RobotSpec spec{"pioneer", "counting", testing::ProjectModel("pioneer2dx_pantilt.urdf"), {}};
    server_ = std::make_unique<Server>(options, std::vector<RobotSpec>{spec}, registry_, clock_);
    server_->Start();
  }
  std::unique_ptr<RobotClient> Connect(ClientOptions options = {}) {
    options.lcm_url = kUrl;
    auto client = std::make_unique<RobotClient>(options);
    client->Connect("pioneer");
    return client;
  }
  void TearDown() override {
    if (server_) server_->Stop();
  }

  SteadyClock clock_;
  DriverRegistry registry_;
  std::shared_ptr<ExecutionLog> log_ = std::make_shared<ExecutionLog>();
  std::unique_ptr<Server> server_;
};

TEST_F(ServerClientTest, ConnectsLoadsTheConfigurationAndSynchronisesClocks) {
  StartServer();
  auto client = Connect();
  const RobotModel local =
      LoadUrdfFile(testing::ProjectModel("pioneer2dx_pantilt.urdf")).model;
  EXPECT_EQ(client->model().num_dofs(), local.num_dofs());
  EXPECT_EQ(client->model().links().size(), local.links().size());
  // Same machine, same steady clock: the estimated offset is within the round trip.
  EXPECT_LE(std::chrono::abs(client->clock_offset()), client->clock_round_trip() + milliseconds(1));
  EXPECT_GT(client->clock_round_trip(), Duration(0));
}

TEST_F(ServerClientTest, DrivesTheRobotInDirectMode) {
  StartServer();
  auto client = Connect();
  Reply r = client->Goto(0.3, 0.0, 0.0);
  ASSERT_EQ(r.signal, Signal::kSuccess) << r.message;
  Reply pose = client->BasePose();
  ASSERT_EQ(pose.signal, Signal::kSuccess);
  EXPECT_NEAR(pose.values[0], 0.3, 0.02);
  EXPECT_NEAR(pose.values[1], 0.0, 0.02);

  Reply bad = client->SetJoint("no_such_joint", {0.1});
  EXPECT_EQ(bad.signal, Signal::kError);
  EXPECT_THAT(bad.message, HasSubstr("no_such_joint"));

  Command far{0, CommandType::kStop, client->ServerNow() + std::chrono::hours(3), "", {}};
  EXPECT_EQ(client->Execute(far).signal, Signal::kError);
}

TEST_F(ServerClientTest, ExecutesEachCommandExactlyOnceDespiteLossAndDuplication) {
  ServerOptions server_options;
  server_options.reply_drop_probability = 0.3;
  server_options.reply_duplicate_probability = 0.3;
  server_options.fault_seed = 7;
  StartServer(server_options);
  ClientOptions client_options;
  client_options.drop_probability = 0.3;
  client_options.duplicate_probability = 0.3;
  client_options.fault_seed = 11;
  client_options.retransmit_interval = milliseconds(20);
  client_options.give_up_after = seconds(20);
  client_options.connect_timeout = seconds(20);
  client_options.timeout = seconds(20);
  auto client = Connect(client_options);
  const std::string pan = "pan";
  ASSERT_TRUE(client->model().FindJoint(pan)) << "the demo robot's pan joint";
  ASSERT_EQ(client->model().joint(client->model().JointIndex(pan)).dofs.size(), 1u);

  constexpr int kCommands = 120;
  std::vector<PendingReply> pending;
  for (int i = 0; i < kCommands; ++i) {
    pending.push_back(client->Send(Command{0, CommandType::kJointSetPoint, std::nullopt, pan, {0.001 * (i + 1)}}));
  }
  for (PendingReply& p : pending) {
    const Reply r = p.Wait(seconds(30));
    EXPECT_TRUE(Succeeded(r.signal)) << r.message;
  }
  std::lock_guard lock(log_->mutex);
  ASSERT_EQ(log_->setpoints.size(), static_cast<size_t>(kCommands)) << "every command executed";
  for (const auto& [value, times] : log_->setpoints) EXPECT_EQ(times, 1) << "set-point " << value;
  EXPECT_GT(client->stats().retransmissions, 0u) << "the faults were exercised";
}

TEST_F(ServerClientTest, PanicFromOneClientRefusesEveryClientUntilReset) {
  StartServer();
  auto streamer = Connect();
  auto operator_ = Connect();
  ASSERT_EQ(streamer->SetSpeed(0.2, 0.1).signal, Signal::kSuccess);
  operator_->Panic();
  Reply refused = streamer->SetSpeed(0.2, 0.1);
  EXPECT_EQ(refused.signal, Signal::kPanic);
  Reply pose = operator_->BasePose();  // queries still work in panic
  ASSERT_EQ(pose.signal, Signal::kSuccess);
  EXPECT_EQ(pose.values[3], 0.0) << "halted: no forward speed";
  EXPECT_EQ(streamer->ResetPanic().signal, Signal::kSuccess);
  EXPECT_EQ(streamer->SetSpeed(0.1, 0.0).signal, Signal::kSuccess);
  EXPECT_EQ(streamer->Stop().signal, Signal::kSuccess);
}

TEST_F(ServerClientTest, StopsTheRobotWhenItsClientVanishes) {
  ServerOptions options;
  options.session_timeout = milliseconds(500);
  StartServer(options);
  auto watcher = Connect();
  {
    auto driver = Connect();
    ASSERT_EQ(driver->SetSpeed(0.3, 0.0).signal, Signal::kSuccess);
    std::this_thread::sleep_for(milliseconds(200));
    ASSERT_GT(watcher->BasePose().values[3], 0.1) << "moving";
  }  // the driving client disappears without a word
  const TimePoint deadline = clock_.Now() + seconds(5);
  double v = 1;
  while (clock_.Now() < deadline && v != 0.0) {
    std::this_thread::sleep_for(milliseconds(100));
    v = watcher->BasePose().values[3];
  }
  EXPECT_EQ(v, 0.0) << "the watchdog stopped the robot";
}

TEST_F(ServerClientTest, TimesOutConnectingToARobotNobodyServes) {
  StartServer();
  ClientOptions options;
  options.lcm_url = kUrl;
  options.connect_timeout = milliseconds(500);
  RobotClient client(options);
  EXPECT_THROW(client.Connect("nobody"), TimeoutError);
}

}  // namespace
}  // namespace robotalk
