// RobotClient against the real server core (robotalk::Server with the
// kinematic driver on models/pioneer2dx_pantilt.urdf) on one in-process
// MemoryBus, the network's faults made by FaultyTransport: lost, repeated,
// reordered and held packages, a server fallen silent, a server restarted,
// panic, heartbeats on a ManualClock, the state stream, timeouts.
//
// Real time: the server runs on its own threads on the steady clock; the
// client on a clock 1000 s behind it (or a ManualClock where a test says so).
// Where a test waits for those threads it polls with a bound, never sleeps
// for a result.
#include "robotalk/robot_client.h"
#include "client/faulty_transport.h"
#include "client/real_server_support.h"
#include "kinematic_driver.h"
#include "robotalk/channels.h"
#include "robotalk/command_status.h"
#include "robotalk/config_message.h"
#include "robotalk/memory_transport.h"
#include "robotalk/request.h"
#include "robotalk/server.h"
#include "robotalk/urdf_import.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <mutex>
#include <thread>

namespace robotalk {
namespace {

using std::chrono::milliseconds;
using std::chrono::seconds;
using namespace robotalk::testing;  // NOLINT: the helpers of real_server_support.h
using ::testing::HasSubstr;

const std::string kRobot = "pioneer";
const std::string kRequests = RequestChannel(kRobot);
const std::string kReplies = "ROBOTALK/" + kRobot + "/REPLY/.*";

class RobotClientTest : public ::testing::Test {
 protected:
  RobotClientTest() {
    RegisterKinematicDriver(registry_);
    registry_.Register("counting", [this](const DriverConfig& config) {
      return std::make_unique<ObservedDriver>(registry_.Create("kinematic", config), log_);
    });
  }

  static ServerOptions DefaultServerOptions() {
    ServerOptions o;
    o.precise_timing = false;  // no spinning or SCHED_FIFO on a shared test machine
    return o;
  }
  // Starts a new server instance on the same transport (a restart when one ran before).
  void StartServer(ServerOptions options = DefaultServerOptions()) {
    const RobotSpec spec{
        kRobot, "counting", std::string(ROBOTALK_MODELS_DIR) + "/pioneer2dx_pantilt.urdf", {}};
    server_ = std::make_unique<Server>(server_net_, options, std::vector<RobotSpec>{spec}, registry_,
                                       server_clock_);
    server_->Start();
  }
  ClientOptions Options() {
    ClientOptions o;
    o.transport = &client_net_;
    o.clock = &client_clock_;
    o.timeout = seconds(5);
    o.connect_timeout = seconds(5);
    return o;
  }
  std::unique_ptr<RobotClient> Connected(ClientOptions o) {
    auto c = std::make_unique<RobotClient>(o);
    c->Connect(kRobot);
    return c;
  }
  // The server's and the client's endpoints of one in-process bus, each
  // behind a FaultyTransport: faults on what the server sends or receives,
  // and on what the client sends.
  std::shared_ptr<MemoryBus> bus_ = std::make_shared<MemoryBus>();
  MemoryTransport server_end_{bus_};
  MemoryTransport client_end_{bus_};
  FaultyTransport server_net_{server_end_, {.seed = 5}};
  FaultyTransport client_net_{client_end_, {.seed = 11}};
  SteadyClock server_clock_;
  // 1000 s behind the server's, so that a measured clock offset cannot be
  // right by accident. (The server runs on the steady clock itself.)
  OffsetClock client_clock_{server_clock_, -seconds(1000)};
  std::shared_ptr<DriverLog> log_ = std::make_shared<DriverLog>();
  DriverRegistry registry_;
  RobotModel model_ =
      LoadUrdfFile(std::string(ROBOTALK_MODELS_DIR) + "/pioneer2dx_pantilt.urdf", {.robot_name = kRobot})
          .model;
  std::unique_ptr<Server> server_;  // last: stopped before the transports go
};

TEST_F(RobotClientTest, ConnectSynchronisesTheClockAndLoadsTheModel) {
  StartServer();
  auto client = Connected(Options());
  EXPECT_TRUE(client->connected());
  EXPECT_EQ(client->model(), model_);
  EXPECT_EQ(ConfigHash(client->model()), ConfigHash(model_));
  // The client's clock runs 1000 s behind the server's; in-process round trips are short.
  EXPECT_NEAR(ToSeconds(client->clock_offset()), 1000.0, 0.01);
  EXPECT_LT(client->clock_round_trip(), milliseconds(50));
  EXPECT_LT(std::chrono::abs(client->ServerNow() - server_clock_.Now()), milliseconds(20));
}

TEST_F(RobotClientTest, ExecuteReturnsTheFinalReplyAndTheServerExecutesOnce) {
  StartServer();
  auto client = Connected(Options());
  const Reply r = client->Goto(0.2, 0.0, 0.0);  // final when the robot arrived
  EXPECT_EQ(r.signal, Signal::kSuccess) << r.message;
  EXPECT_EQ(log_->executions(CommandType::kGoto, 0.2), 1);
  const Reply pose = client->BasePose();
  ASSERT_EQ(pose.signal, Signal::kSuccess);
  EXPECT_NEAR(pose.values[0], 0.2, 0.02);
  const Reply js = client->JointState();
  EXPECT_EQ(js.values.size(), 3u * static_cast<size_t>(model_.num_dofs()));
}

// Issue 9: after a server restart three commands were never executed and the
// CLI named only the first; the client ignored the new instance. A restart
// here: the server object is destroyed and a new one built on the same transport.
TEST_F(RobotClientTest, AServerRestartAnswersOutstandingCommandsAsUnknownOutcomesAndTheClientGoesOn) {
  StartServer();
  const auto hellos =
      server_net_.Add({.channel_regex = HelloChannel(kRobot), .direction = Direction::kIncoming});
  auto client = Connected(Options());
  std::vector<PendingReply> pending;
  for (int i = 0; i < 3; ++i) {
    pending.push_back(client->Send(Command{.type = CommandType::kJointSetPoint,
                                           .start_time = StartTime::At(client->ServerNow() + seconds(30)),
                                           .target = "pan",
                                           .values = {0.1 * i}}));
  }
  for (const auto& p : pending) {
    const Reply status = client->CommandStatus(p.id());
    ASSERT_EQ(status.signal, Signal::kBusy);  // queued there
    // What tells it from a command that ended BUSY (docs/protocol.md).
    EXPECT_EQ(CommandStatusOf(status, p.id()), CommandStatusKind::kNotEnded) << status.message;
  }
  server_.reset();
  StartServer();
  for (auto& p : pending) {
    try {
      p.Wait(seconds(5));
      ADD_FAILURE() << "id " << p.id() << " answered";
    } catch (const UnknownOutcomeError& e) {
      EXPECT_THAT(e.what(), HasSubstr("may or may not have run"));
    }
  }
  EXPECT_EQ(client->stats().sessions_lost, 1u);
  const Reply r = client->Stop();  // a new session with the new instance
  EXPECT_EQ(r.signal, Signal::kSuccess) << r.message;
  EXPECT_EQ(client->stats().sessions_opened, 2u);
  EXPECT_GE(server_net_.counts(hellos).matched, 2u);
  for (int i = 0; i < 3; ++i) {
    EXPECT_EQ(log_->executions(CommandType::kJointSetPoint, 0.1 * i), 0)
        << "never re-sent to the new instance";
  }
}

TEST_F(RobotClientTest, CommandIdsIncrease) {
  StartServer();
  auto client = Connected(Options());
  const CommandId a = client->Stop().id;
  const CommandId b = client->Stop().id;
  EXPECT_GT(b, a);
}

TEST_F(RobotClientTest, SurvivesDroppedAndDuplicatedPackagesEachCommandOnce) {
  StartServer();
  client_net_.Add({.channel_regex = kRequests, .drop_probability = 0.3, .duplicate_probability = 0.3});
  const auto replies =
      server_net_.Add({.channel_regex = kReplies, .drop_probability = 0.3, .duplicate_probability = 0.3});
  const auto repeats =
      server_net_.Add({.channel_regex = kRequests, .direction = Direction::kIncoming, .when = Repeated()});
  ClientOptions o = Options();
  o.retransmit_interval = milliseconds(20);
  o.retransmit_max_interval = milliseconds(100);
  auto client = Connected(o);
  std::vector<PendingReply> pending;
  const auto speed = [](int i) { return 0.01 * (i + 1); };  // tells the commands apart
  for (int i = 0; i < 40; ++i)
    pending.push_back(client->Send(Command{.type = CommandType::kSetSpeed, .values = {speed(i), 0.0}}));
  for (int i = 0; i < 40; ++i) {
    const Reply r = pending[static_cast<std::size_t>(i)].Wait(seconds(10));
    EXPECT_EQ(r.signal, Signal::kSuccess) << r.message;
    EXPECT_EQ(r.id, pending[static_cast<std::size_t>(i)].id());
    EXPECT_EQ(log_->executions(CommandType::kSetSpeed, speed(i)), 1) << "command " << i;
  }
  const ClientStats s = client->stats();
  EXPECT_GT(s.retransmissions, 0u);
  EXPECT_GT(s.replies_ignored, 0u);  // duplicated reply packages
  EXPECT_GT(server_net_.counts(replies).dropped, 0u);
  EXPECT_GT(server_net_.counts(repeats).matched, 0u);  // the server saw packages again
  EXPECT_EQ(log_->total(), 40);
}

// Five commands of one batch run 80 ms apart, so each final reply leaves in a
// package of its own; the network holds those packages and delivers them last
// first. Each reply still reaches its own caller.
TEST_F(RobotClientTest, BatchRepliesInReverseOrderReachTheirOwnCallers) {
  StartServer();
  ClientOptions o = Options();
  o.retransmit_interval = seconds(2);  // no resend while the network holds the replies
  auto client = Connected(o);
  const auto sent =
      server_net_.Add({.channel_regex = kRequests, .direction = Direction::kIncoming, .when = HasPayload});
  const auto reversed = server_net_.Add({.channel_regex = kReplies, .when = HasReplies, .reverse_batch = 5});
  const TimePoint first = client->ServerNow() + milliseconds(100);
  std::vector<Command> batch;
  for (int i = 0; i < 5; ++i) {  // beyond pan's upper limit 2.775 rad: each reply names its value
    batch.push_back(Command{.type = CommandType::kJointSetPoint,
                            .start_time = StartTime::At(first + i * milliseconds(80)),
                            .target = "pan",
                            .values = {3.0 + i}});
  }
  auto pending = client->SendBatch(batch);
  ASSERT_EQ(pending.size(), 5u);
  // The batch is released when its fifth package is held; should a busy
  // server thread have put two replies in one package, release the rest.
  WaitUntil([&] { return server_net_.counts(reversed).released >= 5; }, seconds(3));
  server_net_.ReleaseAll();
  std::vector<Reply> replies;
  for (std::size_t i = 0; i < pending.size(); ++i) {
    replies.push_back(pending[i].Wait(seconds(2)));
    const Reply& r = replies.back();
    EXPECT_EQ(r.id, pending[i].id());
    EXPECT_EQ(r.signal, Signal::kModified) << r.message;
    EXPECT_THAT(r.message, HasSubstr("dof 0: " + std::to_string(3 + i) + " rad clamped"));
    if (i > 0) {
      EXPECT_GT(r.exec_time, replies[i - 1].exec_time);  // it ran at its own start
    }
  }
  EXPECT_GE(server_net_.counts(reversed).held, 2u);
  EXPECT_EQ(server_net_.counts(reversed).released, server_net_.counts(reversed).held);
  EXPECT_EQ(server_net_.counts(sent).matched, 1u);  // the batch travelled as one package
}

TEST_F(RobotClientTest, ScheduledCommandIsAnsweredAfterItsStartEvenIfTheReplyIsLost) {
  StartServer();
  ClientOptions o = Options();
  o.retransmit_interval = milliseconds(50);
  auto client = Connected(o);
  // The first reply package that carries a reply (the acknowledgement does
  // not: the command starts later) is lost.
  const auto lost = server_net_.Add({.channel_regex = kReplies, .when = HasReplies, .drop_first = 1});
  const auto repeats =
      server_net_.Add({.channel_regex = kRequests, .direction = Direction::kIncoming, .when = Repeated()});
  const auto start = std::chrono::steady_clock::now();
  const Reply r = client->SetJoint("pan", {0.3}, client->ServerNow() + milliseconds(300));
  const auto waited = std::chrono::steady_clock::now() - start;
  EXPECT_EQ(r.signal, Signal::kSuccess) << r.message;
  EXPECT_GE(waited, milliseconds(290));
  EXPECT_LT(waited, seconds(2));
  EXPECT_EQ(log_->executions(CommandType::kJointSetPoint, 0.3), 1);
  EXPECT_EQ(server_net_.counts(lost).dropped, 1u);
  EXPECT_GE(server_net_.counts(repeats).matched, 1u);  // the resend after the start recovered the reply
}

// The network holds every reply until the test lets them go (a delay no clock
// reaches): the client resends meanwhile, the server answers each resend from
// its reply cache, the command runs once, and the late reply reaches its caller.
TEST_F(RobotClientTest, RepliesHeldByTheNetworkArriveLateAndTheCommandRunsOnce) {
  StartServer();
  ClientOptions o = Options();
  o.retransmit_interval = milliseconds(20);
  auto client = Connected(o);
  const auto held = server_net_.Add({.channel_regex = kReplies, .delay = std::chrono::hours(1)});
  const auto repeats =
      server_net_.Add({.channel_regex = kRequests, .direction = Direction::kIncoming, .when = Repeated()});
  PendingReply p =
      client->Send(Command{.type = CommandType::kJointSetPoint, .target = "pan", .values = {0.4}});
  ASSERT_TRUE(WaitUntil([&] { return server_net_.counts(repeats).matched >= 2; }));  // resent twice
  EXPECT_FALSE(p.Poll().has_value());
  EXPECT_GE(server_net_.held(), 3u);  // the first answer and one per resend
  server_net_.Remove(held);           // lets them go
  const Reply r = p.Wait(seconds(2));
  EXPECT_EQ(r.signal, Signal::kSuccess) << r.message;
  EXPECT_EQ(log_->executions(CommandType::kJointSetPoint, 0.4), 1);
  EXPECT_TRUE(WaitUntil([&] { return client->stats().replies_ignored > 0; }));  // the copies of the reply
}

TEST_F(RobotClientTest, BlockingCallTimesOutWhenTheServerFallsSilent) {
  StartServer();
  ClientOptions o = Options();
  o.timeout = milliseconds(300);
  auto client = Connected(o);
  server_net_.Add({.mute = true});  // everything the server sends
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
  server_net_.Add({.mute = true});
  PendingReply p = client->Send(Command{.type = CommandType::kStop});
  const auto start = std::chrono::steady_clock::now();
  try {
    p.Wait(seconds(5));
    FAIL() << "expected TimeoutError";
  } catch (const TimeoutError& e) {
    EXPECT_THAT(e.what(), HasSubstr("gave up"));
  }
  EXPECT_LT(std::chrono::steady_clock::now() - start, seconds(2));
  EXPECT_EQ(client->stats().gave_up, 1u);
}

TEST_F(RobotClientTest, PanicIsAcknowledgedAndResetLiftsIt) {
  StartServer();
  auto client = Connected(Options());
  client->Panic();
  // The server halts the driver just after its acknowledgement (architecture.md).
  EXPECT_TRUE(WaitUntil([&] { return log_->halted(); }));
  const Reply refused = client->Goto(1, 0, 0);
  EXPECT_EQ(refused.signal, Signal::kPanic) << refused.message;
  EXPECT_EQ(log_->executions(CommandType::kGoto, 1), 0);
  EXPECT_EQ(client->JointState().signal, Signal::kSuccess);  // queries still answered
  EXPECT_EQ(client->ResetPanic().signal, Signal::kSuccess);
  EXPECT_TRUE(WaitUntil([&] { return !log_->halted(); }));
  const Reply moved = client->SetJoint("pan", {0.2});
  EXPECT_EQ(moved.signal, Signal::kSuccess) << moved.message;
  EXPECT_EQ(log_->executions(CommandType::kJointSetPoint, 0.2), 1);
}

TEST_F(RobotClientTest, PanicTimesOutWithoutAck) {
  StartServer();
  ClientOptions o = Options();
  o.timeout = milliseconds(200);
  auto client = Connected(o);
  server_net_.Add({.mute = true});
  EXPECT_THROW(client->Panic(), TimeoutError);
}

// Follows real time until Freeze(), then moves only when told to: the real
// server takes time between a CLOCK query's receipt and its answer, so a
// client clock standing still through Connect() would see a negative round
// trip in every sample and never synchronise. (A thread setting a
// ManualClock every 100 us lagged behind under load and failed Connect.)
class FollowThenManualClock final : public Clock {
 public:
  TimePoint Now() const override {
    if (frozen_.load()) return TimePoint(Duration(manual_.load()));
    return start_ + std::chrono::duration_cast<Duration>(std::chrono::steady_clock::now() - real_start_);
  }
  // A reader between the two stores sees real time, below the frozen
  // value: the clock never goes back.
  void Freeze() {
    manual_.store((Now() + milliseconds(1)).time_since_epoch().count());
    frozen_.store(true);
  }
  void Advance(Duration d) { manual_.fetch_add(d.count()); }

 private:
  const TimePoint start_{seconds(1000)};
  const std::chrono::steady_clock::time_point real_start_ = std::chrono::steady_clock::now();
  std::atomic<bool> frozen_{false};
  std::atomic<Duration::rep> manual_{0};
};

// On a ManualClock: one heartbeat per idle interval the clock moves, none
// while it stands still (no sleeping for the interval to pass).
TEST_F(RobotClientTest, IdleClientSendsAHeartbeatPerIdleIntervalOfItsClock) {
  ServerOptions so = DefaultServerOptions();
  so.session_timeout = seconds(60);  // the server's clock runs on while the client's stands still
  StartServer(so);
  // New heartbeat packages the server receives (a resend is not a heartbeat).
  const auto heartbeats = server_net_.Add(
      {.channel_regex = kRequests,
       .direction = Direction::kIncoming,
       .when = [repeated = Repeated()](const std::string& channel, std::span<const std::uint8_t> bytes) {
         return !repeated(channel, bytes) && IsHeartbeat(channel, bytes);
       }});
  FollowThenManualClock clock;
  ClientOptions o = Options();
  o.clock = &clock;
  // An interval far longer than Connect() takes (below), and no resend or
  // giving up within the few intervals the test moves the clock.
  o.heartbeat_interval = seconds(10);
  o.clock_refresh_interval = std::chrono::hours(1);  // a CLOCK package would stand in for a heartbeat
  o.retransmit_interval = o.retransmit_max_interval = std::chrono::minutes(10);
  o.give_up_after = std::chrono::hours(1);
  o.max_idle_wait = milliseconds(1);  // re-read the manual clock often
  std::unique_ptr<RobotClient> client = Connected(o);
  clock.Freeze();  // from here on only the test moves it
  ASSERT_LT(clock.Now() - TimePoint(seconds(1000)), seconds(5)) << "Connect() took half an interval";
  const auto received = [&] { return server_net_.counts(heartbeats).matched; };
  EXPECT_EQ(received(), 0u);
  for (std::uint64_t k = 1; k <= 4; ++k) {
    clock.Advance(seconds(10));
    // Bounded real-time wait for the ReadDaemon to notice the clock moved.
    WaitUntil([&] { return received() >= k; });
    ASSERT_EQ(received(), k) << "after advancing " << k << " intervals";
  }
  clock.Advance(seconds(10) - milliseconds(1));  // not yet an interval: nothing more is sent
  // ~20 daemon wake-ups (max_idle_wait 1 ms) in which a wrong heartbeat would go.
  std::this_thread::sleep_for(milliseconds(20));
  EXPECT_EQ(client->stats().heartbeats, 4u);
  EXPECT_EQ(received(), 4u);
}

// Two hosts' clocks drift apart: a connected client takes a fresh clock
// sample every clock_refresh_interval of its clock, so its offset follows
// (ClockSync ages the best sample; ClockSync.FollowsAServerClockThatDrifts*).
// Before, the only samples were Connect's and a restart's.
TEST_F(RobotClientTest, AConnectedClientAsksTheServersClockEveryRefreshInterval) {
  ServerOptions so = DefaultServerOptions();
  so.session_timeout = seconds(60);
  StartServer(so);
  const auto clock_queries = server_net_.Add(
      {.channel_regex = kRequests,
       .direction = Direction::kIncoming,
       .when = [repeated = Repeated()](const std::string& channel, std::span<const std::uint8_t> bytes) {
         if (repeated(channel, bytes)) return false;
         try {
           const Request r = DecodeRequest(bytes);
           return std::any_of(r.queries.begin(), r.queries.end(),
                              [](const Query& q) { return q.type == QueryType::kClock; });
         } catch (const std::exception&) {
           return false;
         }
       }});
  FollowThenManualClock clock;
  ClientOptions o = Options();
  o.clock = &clock;
  o.clock_refresh_interval = seconds(10);  // the default, said here
  o.heartbeat_interval = std::chrono::minutes(10);
  o.retransmit_interval = o.retransmit_max_interval = std::chrono::minutes(10);
  o.give_up_after = std::chrono::hours(1);
  o.max_idle_wait = milliseconds(1);
  std::unique_ptr<RobotClient> client = Connected(o);
  clock.Freeze();
  ASSERT_LT(clock.Now() - TimePoint(seconds(1000)), seconds(5)) << "Connect() took half an interval";
  const auto received = [&] { return server_net_.counts(clock_queries).matched; };
  const std::uint64_t at_connect = received();
  EXPECT_GE(at_connect, 1u) << "Connect's own rounds";
  for (std::uint64_t k = 1; k <= 3; ++k) {
    clock.Advance(seconds(10));
    WaitUntil([&] { return received() >= at_connect + k; });
    ASSERT_EQ(received(), at_connect + k) << "after " << k << " refresh intervals";
  }
  clock.Advance(seconds(10) - milliseconds(1));  // not yet an interval: nothing more is asked
  std::this_thread::sleep_for(milliseconds(20));
  EXPECT_EQ(received(), at_connect + 3);
}

// On real clocks: each refresh's round trip is a sample the clock sync
// takes (not only a package the server sees), and its reply, which nobody
// collects, is not counted among the ignored (duplicates, unknown ids).
TEST_F(RobotClientTest, EachClockRefreshIsASampleAndItsReplyIsNotCountedIgnored) {
  StartServer();
  ClientOptions o = Options();
  o.clock_refresh_interval = milliseconds(50);
  std::unique_ptr<RobotClient> client = Connected(o);
  const std::uint64_t at_connect = client->stats().clock_samples;
  EXPECT_GE(at_connect, 1u) << "Connect's own rounds";
  EXPECT_TRUE(WaitUntil([&] { return client->stats().clock_samples >= at_connect + 5; }))
      << client->stats().clock_samples - at_connect << " samples after Connect";
  EXPECT_EQ(client->stats().replies_ignored, 0u);
  EXPECT_LT(std::chrono::abs(client->ServerTime(client_clock_.Now()) - server_clock_.Now()), milliseconds(50))
      << "the offset after the refreshes";
}

// The server's own samples arrive validated; samples forged on the bus by
// another endpoint are validated the same way: the bad ones are dropped and
// counted, the good ones delivered as sent.
TEST_F(RobotClientTest, StateStreamDeliversValidatedSamplesAndDropsBadOnes) {
  StartServer();
  auto client = Connected(Options());
  std::mutex mu;
  std::vector<StateSample> got;
  const auto received = [&] {
    std::lock_guard lock(mu);
    return got.size();
  };
  EXPECT_EQ(client->StartStateStream(milliseconds(50),
                                     [&](const StateSample& s) {
                                       std::lock_guard lock(mu);
                                       got.push_back(s);
                                     }),
            milliseconds(50));
  ASSERT_TRUE(WaitUntil([&] { return received() >= 2; }));  // the server's, every 50 ms
  const auto dofs = static_cast<std::size_t>(model_.num_dofs());
  StateSample good;
  good.robot = kRobot;
  good.server_time = TimePoint(seconds(1000));
  good.period = milliseconds(50);
  good.sample = 1000001;
  good.positions.assign(dofs, 0.25);
  good.velocities.assign(dofs, 0.0);
  good.efforts.assign(dofs, 0.0);
  good.base = {1, 2, 0.5, 0.1, 0};
  StateSample nan = good;
  nan.sample = 1000002;
  nan.positions[0] = std::nan("");
  StateSample extra_dof = good;
  extra_dof.sample = 1000003;
  for (auto* v : {&extra_dof.positions, &extra_dof.velocities, &extra_dof.efforts}) v->push_back(0);
  StateSample last = good;
  last.sample = 1000004;
  MemoryTransport forger(bus_);
  for (const StateSample& s : {good, nan, extra_dof, last})
    forger.Publish(StateChannel(kRobot), EncodeStateSample(s));
  const auto has = [&](std::int64_t sample) {
    std::lock_guard lock(mu);
    return std::any_of(got.begin(), got.end(), [&](const StateSample& s) { return s.sample == sample; });
  };
  ASSERT_TRUE(WaitUntil([&] { return has(1000004) && client->stats().malformed_packages >= 2; }));
  EXPECT_EQ(client->stats().malformed_packages, 2u);  // NaN, and a dof count the model does not have
  EXPECT_FALSE(has(1000002));
  EXPECT_FALSE(has(1000003));
  std::lock_guard lock(mu);
  int from_server = 0;
  for (const StateSample& s : got) {
    if (s.sample == good.sample) {
      EXPECT_EQ(s, good);
    }
    if (s.sample >= 1000000) continue;
    ++from_server;
    EXPECT_EQ(s.robot, kRobot);
    EXPECT_EQ(s.period, milliseconds(50));
    EXPECT_EQ(s.config_hash, ConfigHash(model_));
    EXPECT_EQ(s.positions.size(), dofs);
  }
  EXPECT_GE(from_server, 2);
}

TEST_F(RobotClientTest, ConnectTimesOutWithoutServer) {
  ClientOptions o = Options();
  o.connect_timeout = milliseconds(300);  // real time: Connect() times out on the steady clock
  RobotClient client(o);
  EXPECT_THROW(client.Connect("nobody"), TimeoutError);
}

// A client clock that stands still makes every CLOCK round trip negative:
// Connect() says so after a bounded number of answers instead of asking the
// server thousands of times a second until its timeout.
TEST_F(RobotClientTest, ConnectOnAClockThatStandsStillFailsNamingTheClockAfterFewQueries) {
  StartServer(DefaultServerOptions());
  const auto clock_queries = server_net_.Add({.channel_regex = kRequests, .direction = Direction::kIncoming});
  ManualClock frozen;
  ClientOptions o = Options();
  o.clock = &frozen;
  RobotClient client(o);
  try {
    client.Connect("pioneer");
    ADD_FAILURE() << "connected on a clock that stands still";
  } catch (const TimeoutError& e) {
    ADD_FAILURE() << "timed out instead: " << e.what();
  } catch (const ClientError& e) {
    EXPECT_THAT(e.what(), HasSubstr("does ClientOptions::clock move with real time?"));
  }
  // 4 x 8 rounds + 4 answers, the CONFIG query, and a heartbeat or two.
  EXPECT_LT(server_net_.counts(clock_queries).matched, 60u);
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
  EXPECT_EQ(log_->total(), 100);
}

TEST_F(RobotClientTest, PendingReplyOutlivingTheClientFailsCleanly) {
  StartServer();
  auto client = Connected(Options());
  server_net_.Add({.mute = true});
  PendingReply p = client->Send(Command{.type = CommandType::kStop});
  client.reset();
  EXPECT_THROW(p.Wait(milliseconds(100)), ClientError);
}

// Two real servers announce the same robot (allowed), each once a second: the
// list names each server once however often it was heard.
TEST_F(RobotClientTest, ListRobotsDedupesAnnouncements) {
  ServerOptions so = DefaultServerOptions();
  so.allow_duplicate_robots = true;
  StartServer(so);
  MemoryTransport second_end(bus_);
  const RobotSpec spec{
      kRobot, "kinematic", std::string(ROBOTALK_MODELS_DIR) + "/pioneer2dx_pantilt.urdf", {}};
  Server second(second_end, so, {spec}, registry_, server_clock_);
  second.Start();
  const auto heard = client_net_.Add({.channel_regex = kAnnounceChannel, .direction = Direction::kIncoming});
  // Real time: the server announces once a second (ServerOptions::announce_period
  // is not passed on to the ServerDaemon), so hearing each server twice takes 2 s.
  const auto robots = ListRobots(Options(), milliseconds(2100));
  second.Stop();
  EXPECT_GE(client_net_.counts(heard).matched, 3u);  // some server heard more than once
  ASSERT_EQ(robots.size(), 2u);                      // one robot, two servers
  for (const auto& robot : robots) {
    EXPECT_EQ(robot.name, kRobot);
    EXPECT_EQ(robot.config_hash, ConfigHash(model_));
  }
  EXPECT_NE(robots[0].server_id, robots[1].server_id);
}

// A forger floods ANNOUNCE with distinct names (1000 per datagram, the most a
// decoder takes is 1024): the list keeps at most kMaxListedRobots and counts
// the rest, instead of growing with the flood (and comparing every new name
// with every one kept).
TEST_F(RobotClientTest, AFloodOfAnnouncedNamesIsListedUpToTheBoundAndCounted) {
  MemoryTransport forger(bus_);
  std::atomic<bool> listed{false};
  std::atomic<int> sent_names{0};
  std::thread flood([&] {
    for (int round = 0; round < 30 && !listed; ++round) {
      Announcement a;
      a.server_id = 7000 + round;
      for (int i = 0; i < 1000; ++i)
        a.robots.push_back(
            {"forged-" + std::to_string(i), "kinematic", 1, 1, BaseType::kDifferential, false, 0});
      forger.Publish(kAnnounceChannel, EncodeAnnouncement(a));
      sent_names += 1000;
      std::this_thread::sleep_for(milliseconds(10));
    }
  });
  std::size_t unlisted = 0;
  const auto robots = ListRobots(Options(), milliseconds(1500), &unlisted);
  listed = true;
  flood.join();
  ASSERT_GT(sent_names.load(), static_cast<int>(kMaxListedRobots));  // the flood outgrew the list
  EXPECT_EQ(robots.size(), kMaxListedRobots);
  EXPECT_GT(unlisted, 0u);
  EXPECT_LE(robots.size() + unlisted, static_cast<std::size_t>(sent_names.load()));
}

// Issue 22: SETSPEED frames of a linear sequence ramp within the robot's own
// base acceleration limit (ServerOptions::robot_base_acceleration, the
// server's --max-base-acceleration NAME=LIN,ANG), end to end through a client.
TEST_F(RobotClientTest, ALinearSequencesSetSpeedFramesRampWithinTheRobotsOwnBaseLimit) {
  ServerOptions options = DefaultServerOptions();
  options.robot_base_acceleration[kRobot] = BaseAccelerationLimit{.linear = 1.0, .angular = 2.0};
  StartServer(options);
  auto client = Connected(Options());
  const auto speed = CommandType::kSetSpeed;
  const std::vector<TimedCommand> frames = {{milliseconds(0), {.type = speed, .values = {0.0, 0.0}}},
                                            {milliseconds(200), {.type = speed, .values = {0.5, 0.0}}},
                                            {milliseconds(1200), {.type = speed, .values = {0.0, 0.0}}}};
  const SequenceResult r =
      client->RunSequence(frames, {.delay = milliseconds(300), .interpolation = Interpolation::kLinear});
  ASSERT_EQ(r.replies.size(), 3u);
  EXPECT_EQ(r.replies[0].signal, Signal::kSuccess) << r.replies[0].message;
  EXPECT_EQ(r.replies[1].signal, Signal::kModified);
  EXPECT_THAT(r.replies[1].message,
              HasSubstr("the plan's linear acceleration 2.5 m/s² exceeds the base's limit 1 m/s²"));
  EXPECT_NE(r.replies[2].signal, Signal::kInterrupted) << r.replies[2].message;
  EXPECT_NE(r.replies[2].signal, Signal::kError) << r.replies[2].message;
}

TEST(ServerOptionsTest, ABaseLimitForARobotNotServedIsRefusedByName) {
  DriverRegistry registry;
  RegisterKinematicDriver(registry);
  auto bus = std::make_shared<MemoryBus>();
  MemoryTransport net(bus);
  ServerOptions options;
  options.precise_timing = false;
  options.robot_base_acceleration["rover"] = BaseAccelerationLimit{};
  const RobotSpec spec{
      kRobot, "kinematic", std::string(ROBOTALK_MODELS_DIR) + "/pioneer2dx_pantilt.urdf", {}};
  SteadyClock clock;
  try {
    Server server(net, options, std::vector<RobotSpec>{spec}, registry, clock);
    ADD_FAILURE() << "accepted";
  } catch (const Error& e) {
    EXPECT_THAT(e.what(), HasSubstr("--max-base-acceleration rover=...: no robot 'rover' is served"));
  }
}

}  // namespace
}  // namespace robotalk
