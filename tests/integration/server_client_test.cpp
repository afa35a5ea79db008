// End to end: a Server with the kinematic driver and RobotClients in one
// process, over real LCM multicast on the loopback of a private network
// namespace (this binary runs under tests/netns_run.sh).
#include "kinematic_driver.h"
#include "robotalk/robot_client.h"
#include "robotalk/server.h"
#include "robotalk/urdf_import.h"
#include "support/observed_driver.h"
#include "test_paths.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <map>
#include <mutex>
#include <thread>

namespace robotalk {
namespace {

using std::chrono::milliseconds;
using std::chrono::seconds;
using ::testing::HasSubstr;

constexpr const char* kUrl = "udpm://239.255.76.67:7711?ttl=0";

// Records every set-point the driver executes, to prove exactly-once delivery.
struct ExecutionLog final : testing::DriverObserver {
  void Executed(const DriverCommand& c, TimePoint now) override {
    if (c.type != CommandType::kJointSetPoint) return;
    std::lock_guard lock(mutex);
    ++setpoints[c.values[0]];
    setpoint_times[c.values[0]] = now;
  }
  std::mutex mutex;
  std::map<double, int> setpoints;             // pan value -> times executed
  std::map<double, TimePoint> setpoint_times;  // pan value -> when it executed
};

class ServerClientTest : public ::testing::Test {
 protected:
  void StartServer(ServerOptions options = {}) {
    if (!registered_) {
      RegisterKinematicDriver(registry_);
      registry_.Register("counting", [log = log_, this](const DriverConfig& config) {
        return std::make_unique<testing::ObservedDriver>(registry_.Create("kinematic", config), log);
      });
      registered_ = true;
    }
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
  bool registered_ = false;
};

// Issue 9: after a restart the client ignored the new instance; a panic must
// still stop the robot at once, before the client has a new session.
TEST_F(ServerClientTest, AfterAServerRestartAPanicStopsTheRobotAtOnceAndTheClientGoesOn) {
  StartServer();
  auto client = Connect();
  PendingReply later = client->Send(Command{.type = CommandType::kJointSetPoint,
                                            .start_time = StartTime::At(client->ServerNow() + seconds(30)),
                                            .target = "pan",
                                            .values = {0.4}});
  server_->Stop();
  server_.reset();
  StartServer();    // a new instance: none of the old sessions
  client->Panic();  // sent in the old session; the new server acts on it and says so
  EXPECT_THROW(later.Wait(seconds(5)), UnknownOutcomeError);
  const Reply moved = client->SetJoint("pan", {0.2});  // a new session
  EXPECT_EQ(moved.signal, Signal::kPanic) << "the panic reached the new instance: " << moved.message;
  EXPECT_EQ(client->ResetPanic().signal, Signal::kSuccess);
  EXPECT_EQ(client->SetJoint("pan", {0.2}).signal, Signal::kSuccess);
  EXPECT_GE(client->stats().sessions_lost, 1u);
}

TEST_F(ServerClientTest, ConnectsLoadsTheConfigurationAndSynchronisesClocks) {
  StartServer();
  auto client = Connect();
  const RobotModel local = LoadUrdfFile(testing::ProjectModel("pioneer2dx_pantilt.urdf")).model;
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
    pending.push_back(
        client->Send(Command{0, CommandType::kJointSetPoint, std::nullopt, pan, {0.001 * (i + 1)}}));
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

// Frames every 100 ms setting the pan joint to a distinct value each.
std::vector<TimedCommand> PanFrames(int n) {
  std::vector<TimedCommand> frames;
  for (int i = 0; i < n; ++i) {
    frames.push_back({milliseconds(100) * i,
                      Command{0, CommandType::kJointSetPoint, std::nullopt, "pan", {0.01 * (i + 1)}}});
  }
  return frames;
}

TEST_F(ServerClientTest, DelayModeRunsEveryCommandAtItsStartTimeDespiteCongestion) {
  ServerOptions options;
  options.congestion_max_pause = milliseconds(80);  // the paper's injector
  StartServer(options);
  auto client = Connect();
  const SequenceResult result =
      client->RunSequence(PanFrames(20), {.mode = CommandMode::kDelay, .delay = seconds(1)});
  ASSERT_TRUE(result.server_start);
  std::lock_guard lock(log_->mutex);
  for (int i = 0; i < 20; ++i) {
    EXPECT_EQ(result.replies[static_cast<size_t>(i)].signal, Signal::kSuccess);
    const TimePoint due = *result.server_start + milliseconds(100) * i;
    const Duration late = log_->setpoint_times.at(0.01 * (i + 1)) - due;
    // The start went on the wire in whole microseconds (truncated), so a
    // RobotDaemon that starts on time may start up to 1 us before `due`.
    EXPECT_GE(late, -std::chrono::microseconds(1)) << "frame " << i << " ran early";
    EXPECT_LT(late, milliseconds(30))
        << "frame " << i << " ran late (RobotDaemon wake-up on a shared machine)";
    // The reply says how late it ran (the wire carries microseconds).
    EXPECT_LE(std::chrono::abs(result.replies[static_cast<size_t>(i)].lateness - late),
              std::chrono::microseconds(1));
  }
}

// Congestion only: a frame lost and retransmitted arrives a retransmission
// timeout later, which no estimate of the arrival rate can foresee (its reply
// then reports the lateness); loss is covered by the exactly-once test.
TEST_F(ServerClientTest, PlaybackKeepsTheInterFrameTimingUnderCongestion) {
  ServerOptions options;
  options.congestion_max_pause = milliseconds(300);  // mean 150 ms per package: the backlog grows
  StartServer(options);
  ClientOptions client_options;
  client_options.timeout = seconds(20);
  client_options.give_up_after = seconds(20);
  auto client = Connect(client_options);
  constexpr int kFrames = 20;
  const SequenceResult result = client->RunSequence(PanFrames(kFrames), {.mode = CommandMode::kPlayback});
  ASSERT_TRUE(result.playback_delay) << "the client learns the delay";
  ASSERT_TRUE(result.server_start);
  EXPECT_GT(*result.playback_delay, milliseconds(100));
  std::lock_guard lock(log_->mutex);
  ASSERT_EQ(log_->setpoint_times.size(), static_cast<size_t>(kFrames));
  for (int i = 0; i < kFrames; ++i) {
    EXPECT_EQ(result.replies[static_cast<size_t>(i)].signal, Signal::kSuccess);
    const Duration late =
        log_->setpoint_times.at(0.01 * (i + 1)) - (*result.server_start + milliseconds(100) * i);
    EXPECT_GE(late, -std::chrono::microseconds(1)) << "frame " << i;
    EXPECT_LT(late, milliseconds(30)) << "frame " << i << ": the sequence ran dry";
  }
}

TEST_F(ServerClientTest, DirectModeWaitsForEachReplyBeforeTheNextFrame) {
  StartServer();
  auto client = Connect();
  const SequenceResult result = client->RunSequence(PanFrames(5), {.mode = CommandMode::kDirect});
  for (const Reply& r : result.replies) EXPECT_EQ(r.signal, Signal::kSuccess);
  EXPECT_FALSE(result.server_start) << "direct mode runs each frame on receipt";
}

TEST_F(ServerClientTest, BroadcastKeepsItsPeriodAndStopsOnCancel) {
  StartServer();
  auto client = Connect();
  auto watcher = Connect();
  std::mutex mu;
  std::vector<std::int64_t> times;
  const Duration period = client->StartStateStream(milliseconds(50), [&](const StateSample& s) {
    std::lock_guard lock(mu);
    times.push_back(ToWireMicros(s.server_time));
  });
  EXPECT_EQ(period, milliseconds(50));
  // Another subscriber sees the same stream without asking (as lcm-spy would).
  std::atomic<int> seen_by_watcher{0};
  watcher->StartStateStream(milliseconds(500), [&](const StateSample&) { ++seen_by_watcher; });
  std::this_thread::sleep_for(seconds(2));
  client->StopStateStream();
  watcher->StopStateStream();
  std::this_thread::sleep_for(milliseconds(300));
  std::lock_guard lock(mu);
  ASSERT_GE(times.size(), 35u);
  ASSERT_LE(times.size(), 42u);
  // Absolute deadlines: sample k is due at t0 + k x 50 ms. Measured from the
  // first sample (itself a little late), each is within a wake-up of its due
  // time (generous: the machine is shared), and the lateness does not grow.
  std::vector<std::int64_t> late_us;
  for (size_t k = 0; k < times.size(); ++k) {
    late_us.push_back(times[k] - times[0] - static_cast<std::int64_t>(k) * 50000);
    EXPECT_GE(late_us.back(), -2000) << "sample " << k << " early";
    EXPECT_LT(late_us.back(), 50000) << "sample " << k << " late";
  }
  std::vector<std::int64_t> last(late_us.end() - 10, late_us.end());
  std::nth_element(last.begin(), last.begin() + 5, last.end());
  EXPECT_LT(last[5], 10000) << "median lateness of the last 10 samples: the stream drifted";
  EXPECT_GT(seen_by_watcher.load(), 30) << "one shared stream at the shortest period";
  const size_t after_cancel = times.size();
  std::this_thread::sleep_for(milliseconds(300));
  EXPECT_EQ(times.size(), after_cancel) << "no samples after every client cancelled";
}

}  // namespace
}  // namespace robotalk
