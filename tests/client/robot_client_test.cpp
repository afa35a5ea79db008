// RobotClient against FakeServer on one in-process MemoryTransport: acks,
// duplicates, dropped packages, reordering, scheduling, panic, timeouts.
#include "robotalk/robot_client.h"
#include "fake_server.h"
#include "robotalk/channels.h"
#include "robotalk/config_codec.h"
#include "robotalk/memory_transport.h"
#include "robotalk/protocol_codec.h"
#include "robotalk/urdf_import.h"

#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <mutex>
#include <thread>

namespace robotalk {
namespace {

using std::chrono::milliseconds;
using testing::FakeServer;
using testing::FakeServerOptions;

RobotModel Pioneer() {
  return LoadUrdfFile(std::string(ROBOTALK_MODELS_DIR) + "/pioneer2dx_pantilt.urdf").model;
}

class RobotClientTest : public ::testing::Test {
 protected:
  ClientOptions Options() {
    ClientOptions o;
    o.transport = &transport_;
    o.timeout = std::chrono::seconds(5);
    o.connect_timeout = std::chrono::seconds(5);
    return o;
  }
  void StartServer(FakeServerOptions options = {}) {
    server_ = std::make_unique<FakeServer>(transport_, model_, options);
  }
  std::unique_ptr<RobotClient> Connected(ClientOptions o) {
    auto c = std::make_unique<RobotClient>(o);
    c->Connect(model_.name());
    return c;
  }

  // Client and FakeServer share one endpoint of an in-process bus: the
  // client's ReadDaemon dispatches both (no sockets).
  MemoryTransport transport_{std::make_shared<MemoryBus>()};
  RobotModel model_ = Pioneer();
  std::unique_ptr<FakeServer> server_;
};

TEST_F(RobotClientTest, ConnectSynchronisesTheClockAndLoadsTheModel) {
  StartServer();
  auto client = Connected(Options());
  EXPECT_TRUE(client->connected());
  EXPECT_EQ(client->model(), model_);
  // The fake server's clock runs 1000 s ahead; in-process round trips are short.
  EXPECT_NEAR(ToSeconds(client->clock_offset()), 1000.0, 0.01);
  EXPECT_LT(client->clock_round_trip(), milliseconds(50));
  const double skew =
      ToSeconds(client->ServerNow().time_since_epoch()) * 1e6 - static_cast<double>(server_->ServerNowUs());
  EXPECT_LT(std::abs(skew), 20000.0);
}

TEST_F(RobotClientTest, ExecuteReturnsTheFinalReplyAndTheServerExecutesOnce) {
  StartServer();
  auto client = Connected(Options());
  Reply r = client->Goto(1.0, 0.0, 0.0);
  EXPECT_EQ(r.signal, Signal::kSuccess);
  EXPECT_EQ(r.message, "cmd " + std::to_string(r.id));
  EXPECT_EQ(server_->executions(r.id), 1);
  Reply js = client->JointState();
  EXPECT_EQ(js.values.size(), 3u * static_cast<size_t>(model_.num_dofs()));
}

// Issue 9: after a server restart three commands were never executed and the
// CLI named only the first; the client ignored the new instance.
TEST_F(RobotClientTest, AServerRestartAnswersOutstandingCommandsAsUnknownOutcomesAndTheClientGoesOn) {
  StartServer();
  auto client = Connected(Options());
  std::vector<PendingReply> pending;
  for (int i = 0; i < 3; ++i) {
    pending.push_back(
        client->Send(Command{.type = CommandType::kJointSetPoint,
                             .start_time = StartTime::At(client->ServerNow() + std::chrono::seconds(30)),
                             .target = "pan",
                             .values = {0.1 * i}}));
  }
  server_->Restart();
  for (auto& p : pending) {
    try {
      p.Wait(std::chrono::seconds(5));
      ADD_FAILURE() << "id " << p.id() << " answered";
    } catch (const UnknownOutcomeError& e) {
      EXPECT_NE(std::string(e.what()).find("may or may not have run"), std::string::npos) << e.what();
    }
  }
  EXPECT_EQ(client->stats().sessions_lost, 1u);
  Reply r = client->Stop();  // a new session with the new instance
  EXPECT_EQ(r.signal, Signal::kSuccess);
  EXPECT_EQ(server_->hellos(), 2);
  EXPECT_EQ(client->stats().sessions_opened, 2u);
}

TEST_F(RobotClientTest, CommandIdsIncrease) {
  StartServer();
  auto client = Connected(Options());
  const CommandId a = client->Stop().id;
  const CommandId b = client->Stop().id;
  EXPECT_GT(b, a);
}

TEST_F(RobotClientTest, SurvivesDroppedAndDuplicatedPackagesEachCommandOnce) {
  StartServer({.reply_drop_probability = 0.3, .duplicate_replies = true, .seed = 5});
  ClientOptions o = Options();
  o.drop_probability = 0.3;
  o.duplicate_probability = 0.3;
  o.fault_seed = 11;
  o.retransmit_interval = milliseconds(20);
  o.retransmit_max_interval = milliseconds(100);
  auto client = Connected(o);
  std::vector<PendingReply> pending;
  for (int i = 0; i < 40; ++i)
    pending.push_back(client->Send(Command{.type = CommandType::kSetSpeed, .values = {0.1, 0.0}}));
  for (auto& p : pending) {
    Reply r = p.Wait(std::chrono::seconds(10));
    EXPECT_EQ(r.signal, Signal::kSuccess);
    EXPECT_EQ(r.id, p.id());
    EXPECT_EQ(server_->executions(p.id()), 1) << "id " << p.id();
  }
  const ClientStats s = client->stats();
  EXPECT_GT(s.retransmissions, 0u);
  EXPECT_GT(s.replies_ignored, 0u);  // duplicated reply packages
  EXPECT_GT(server_->repeated_packages(), 0);
  EXPECT_EQ(server_->total_executions(), 40);
}

TEST_F(RobotClientTest, BatchRepliesInReverseOrderReachTheirOwnCallers) {
  StartServer({.reverse_batches = true});
  auto client = Connected(Options());
  std::vector<Command> batch;
  for (int i = 0; i < 5; ++i)
    batch.push_back(Command{.type = CommandType::kJointSetPoint, .target = "pan", .values = {0.1 * i}});
  auto pending = client->SendBatch(batch);
  ASSERT_EQ(pending.size(), 5u);
  for (auto& p : pending) {
    Reply r = p.Wait(std::chrono::seconds(2));
    EXPECT_EQ(r.id, p.id());
    EXPECT_EQ(r.message, "cmd " + std::to_string(p.id()));
  }
  EXPECT_EQ(server_->packages_received() - server_->heartbeats(), 8 + 1 + 1);  // clock rounds, config, batch
}

TEST_F(RobotClientTest, ScheduledCommandIsAnsweredAfterItsStartEvenIfTheReplyIsLost) {
  StartServer({.drop_first_delayed_reply = true});
  ClientOptions o = Options();
  o.retransmit_interval = milliseconds(50);
  auto client = Connected(o);
  const auto start = std::chrono::steady_clock::now();
  Reply r = client->Goto(1.0, 2.0, 0.0, client->ServerNow() + milliseconds(300));
  const auto waited = std::chrono::steady_clock::now() - start;
  EXPECT_EQ(r.signal, Signal::kSuccess);
  EXPECT_GE(waited, milliseconds(290));
  EXPECT_LT(waited, std::chrono::seconds(2));
  EXPECT_EQ(server_->executions(r.id), 1);
  EXPECT_GE(server_->repeated_packages(), 1);  // the resend after the start recovered the reply
}

TEST_F(RobotClientTest, BlockingCallTimesOutWhenTheServerFallsSilent) {
  StartServer();
  ClientOptions o = Options();
  o.timeout = milliseconds(300);
  auto client = Connected(o);
  server_->SetMute(true);
  const auto start = std::chrono::steady_clock::now();
  EXPECT_THROW(client->Stop(), TimeoutError);
  EXPECT_GE(std::chrono::steady_clock::now() - start, milliseconds(290));
  EXPECT_GT(client->stats().retransmissions, 0u);
}

TEST_F(RobotClientTest, GivingUpFailsPendingRepliesWithATimeout) {
  StartServer();
  ClientOptions o = Options();
  o.give_up_after = milliseconds(200);
  auto client = Connected(o);
  server_->SetMute(true);
  PendingReply p = client->Send(Command{.type = CommandType::kStop});
  const auto start = std::chrono::steady_clock::now();
  try {
    p.Wait(std::chrono::seconds(5));
    FAIL() << "expected TimeoutError";
  } catch (const TimeoutError& e) {
    EXPECT_NE(std::string(e.what()).find("gave up"), std::string::npos) << e.what();
  }
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(2));
  EXPECT_EQ(client->stats().gave_up, 1u);
}

TEST_F(RobotClientTest, PanicIsAcknowledgedAndResetLiftsIt) {
  StartServer();
  auto client = Connected(Options());
  client->Panic();
  EXPECT_TRUE(server_->panic());
  EXPECT_EQ(client->Goto(1, 0, 0).signal, Signal::kPanic);
  EXPECT_EQ(client->JointState().signal, Signal::kSuccess);  // queries still answered
  EXPECT_EQ(client->ResetPanic().signal, Signal::kSuccess);
  EXPECT_EQ(client->Goto(1, 0, 0).signal, Signal::kSuccess);
}

TEST_F(RobotClientTest, PanicTimesOutWithoutAck) {
  StartServer();
  ClientOptions o = Options();
  o.timeout = milliseconds(200);
  auto client = Connected(o);
  server_->SetMute(true);
  EXPECT_THROW(client->Panic(), TimeoutError);
}

// On a ManualClock: one heartbeat per idle interval the clock moves, none
// while it stands still (no sleeping for the interval to pass).
TEST_F(RobotClientTest, IdleClientSendsAHeartbeatPerIdleIntervalOfItsClock) {
  StartServer();
  ManualClock clock;
  ClientOptions o = Options();
  o.clock = &clock;
  o.heartbeat_interval = milliseconds(50);
  o.max_idle_wait = milliseconds(1);  // re-read the manual clock often
  auto client = Connected(o);
  const int before = server_->heartbeats();
  for (int k = 1; k <= 4; ++k) {
    clock.Advance(milliseconds(50));
    // Bounded real-time wait for the ReadDaemon to notice the clock moved.
    for (int i = 0; i < 2000 && server_->heartbeats() < before + k; ++i) {
      std::this_thread::sleep_for(milliseconds(1));
    }
    ASSERT_EQ(server_->heartbeats(), before + k) << "after advancing " << k << " intervals";
  }
  clock.Advance(milliseconds(49));  // not yet an interval: nothing more is sent
  // ~20 daemon wake-ups (max_idle_wait 1 ms) in which a wrong heartbeat would go.
  std::this_thread::sleep_for(milliseconds(20));
  EXPECT_EQ(client->stats().heartbeats, 4u);
  EXPECT_EQ(server_->heartbeats(), before + 4);
}

TEST_F(RobotClientTest, StateStreamDeliversValidatedSamplesAndDropsBadOnes) {
  StartServer();
  auto client = Connected(Options());
  std::mutex mu;
  std::vector<StateSample> got;
  EXPECT_EQ(client->StartStateStream(milliseconds(50),
                                     [&](const StateSample& s) {
                                       std::lock_guard lock(mu);
                                       got.push_back(s);
                                     }),
            milliseconds(50));
  const auto dofs = static_cast<std::size_t>(model_.num_dofs());
  StateSample good;
  good.robot = model_.name();
  good.server_time = TimePoint(std::chrono::seconds(1000));
  good.period = milliseconds(50);
  good.sample = 1;
  good.positions.assign(dofs, 0.25);
  good.velocities.assign(dofs, 0.0);
  good.efforts.assign(dofs, 0.0);
  good.base = {1, 2, 0.5, 0.1, 0};
  robotalk_msgs::robot_state_t nan = ToWire(good);
  nan.sample = 2;
  nan.position[0] = std::nan("");
  StateSample extra_dof = good;
  extra_dof.sample = 3;
  for (auto* v : {&extra_dof.positions, &extra_dof.velocities, &extra_dof.efforts}) v->push_back(0);
  StateSample last = good;
  last.sample = 4;
  // The server's side of the bus (published from this thread; the client's
  // ReadDaemon dispatches).
  Publish(transport_, StateChannel(model_.name()), ToWire(good));
  Publish(transport_, StateChannel(model_.name()), nan);
  Publish(transport_, StateChannel(model_.name()), ToWire(extra_dof));
  Publish(transport_, StateChannel(model_.name()), ToWire(last));
  for (int i = 0; i < 2000; ++i) {
    {
      std::lock_guard lock(mu);
      if (got.size() >= 2 && client->stats().malformed_packages >= 2) break;
    }
    std::this_thread::sleep_for(milliseconds(1));
  }
  std::lock_guard lock(mu);
  ASSERT_EQ(got.size(), 2u);
  EXPECT_EQ(got[0], good);
  EXPECT_EQ(got[1].sample, 4);
  EXPECT_EQ(client->stats().malformed_packages, 2u);  // NaN, and a dof count the model does not have
}

TEST_F(RobotClientTest, ConnectTimesOutWithoutServer) {
  ClientOptions o = Options();
  o.connect_timeout = milliseconds(300);
  RobotClient client(o);
  EXPECT_THROW(client.Connect("nobody"), TimeoutError);
}

TEST_F(RobotClientTest, CallsBeforeConnectThrowClientError) {
  RobotClient client(Options());
  EXPECT_THROW(client.Stop(), ClientError);
  EXPECT_THROW(client.model(), ClientError);
  EXPECT_THROW(client.Connect("bad name"), ClientError);
}

TEST_F(RobotClientTest, ManyThreadsShareOneClient) {
  StartServer();
  auto client = Connected(Options());
  std::atomic<int> ok{0};
  std::vector<std::thread> threads;
  for (int t = 0; t < 4; ++t) {
    threads.emplace_back([&] {
      for (int i = 0; i < 25; ++i) {
        if (client->SetSpeed(0.1, 0.0).signal == Signal::kSuccess) ++ok;
      }
    });
  }
  for (auto& t : threads) t.join();
  EXPECT_EQ(ok.load(), 100);
}

TEST_F(RobotClientTest, PendingReplyOutlivingTheClientFailsCleanly) {
  StartServer({.mute = false});
  auto client = Connected(Options());
  server_->SetMute(true);
  PendingReply p = client->Send(Command{.type = CommandType::kStop});
  client.reset();
  EXPECT_THROW(p.Wait(milliseconds(100)), ClientError);
}

TEST_F(RobotClientTest, ListRobotsDedupesAnnouncements) {
  StartServer();
  std::atomic<bool> stop{false};
  std::thread announcer([&] {
    while (!stop) {
      server_->Announce(1);
      server_->Announce(2);
      std::this_thread::sleep_for(milliseconds(10));
    }
  });
  auto robots = ListRobots(Options(), milliseconds(200));
  stop = true;
  announcer.join();
  ASSERT_EQ(robots.size(), 2u);  // one robot, two servers
  EXPECT_EQ(robots[0].name, model_.name());
  EXPECT_EQ(robots[0].config_hash, ConfigHash(model_));
  EXPECT_NE(robots[0].server_id, robots[1].server_id);
}

}  // namespace
}  // namespace robotalk
