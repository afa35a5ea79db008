// The ServerDaemon on the in-memory transport: bytes in, bytes out, with the
// real codec, sessions and RobotDaemon, on a manual clock and no sockets.
#include "server_daemon.h"

#include "fake_driver.h"
#include "robotalk/channels.h"
#include "robotalk/forwarding_transport.h"
#include "robotalk/memory_transport.h"
#include "robotalk/request.h"
#include "robotalk/server.h"
#include "session_test_util.h"
#include "support/test_clients.h"
#include "two_robot_server.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>

#include <cstdio>
#include <fstream>
#include <iterator>

namespace robotalk {
namespace {

using std::chrono::milliseconds;
using testing::FakeDriver;
using ::testing::HasSubstr;
using testing::PanRobot;
using testing::SayHello;

using testing::kAlice;

class ServerDaemonTest : public testing::TwoRobotServerTest {
 protected:
  ServerDaemonTest() {
    reply_sub_ =
        client_.Subscribe("ROBOTALK/.*", [this](const std::string& channel, std::span<const std::uint8_t> b) {
          channels_.push_back(channel);
          if (auto parts = ParseReplyChannel(channel)) {
            for (Reply& r : DecodeReplyBatch(b).replies) replies_[parts->robot][r.id] = r;
          }
        });
  }

  // Sends in the client's session on that robot (said hello to first).
  void Send(const std::string& robot, Request r) {
    std::int64_t& session = sessions_[{robot, r.client_id}];
    if (session == 0) session = SayHello(client_, robot, r.client_id, [this] { Step(); }).session_id;
    r.session_id = session;
    client_.Publish(RequestChannel(robot), EncodeRequest(r));
  }
  std::unique_ptr<Subscription> reply_sub_;
  std::vector<std::string> channels_;
  std::map<std::string, std::map<CommandId, Reply>> replies_;
  std::map<std::pair<std::string, std::int64_t>, std::int64_t> sessions_;
};

// A transport whose subscriptions cannot be made (LCM could not start a lane).
class RefusingTransport final : public Transport {
 public:
  void Publish(const std::string&, std::span<const std::uint8_t>) override {}
  std::unique_ptr<Subscription> Subscribe(const std::string& regex, Handler) override {
    throw TransportError("cannot listen on '" + regex + "'");
  }
  int HandleFor(Duration) override { return 0; }
  int fileno() const override { return -1; }
  std::string url() const override { return "refusing://"; }
};

// The signed SESSION_UNKNOWN answers' budget: a burst of `per_second`, then
// one more each 1/per_second, never more than a burst however long the pause.
TEST(AnswerBudget, AllowsABurstThenRefillsAtItsRateUpToOneBurst) {
  const TimePoint t0 = TimePoint(std::chrono::seconds(100));
  AnswerBudget budget;
  int taken = 0;
  for (int i = 0; i < 10; ++i) taken += budget.Take(t0, 4);
  EXPECT_EQ(taken, 4);
  EXPECT_FALSE(budget.Take(t0 + milliseconds(240), 4));
  EXPECT_TRUE(budget.Take(t0 + milliseconds(250), 4)) << "one token a quarter second";
  EXPECT_FALSE(budget.Take(t0 + milliseconds(260), 4));
  taken = 0;
  for (int i = 0; i < 10; ++i) taken += budget.Take(t0 + std::chrono::hours(1), 4);
  EXPECT_EQ(taken, 4) << "an hour's pause buys one burst, not 14,400 answers";
  EXPECT_FALSE(budget.Take(t0 - std::chrono::seconds(5), 4)) << "a clock stepped back refills nothing";
  EXPECT_FALSE(AnswerBudget{}.Take(t0, 0)) << "a budget of 0 answers none";
}

// Every way a robot is served goes through AddRobot: a name LCM's channels
// cannot carry is refused there, naming the rule (before: "serving robot",
// then every hello answer failed to publish).
TEST(ServerDaemon, RefusesARobotWhoseNameNoChannelCanCarry) {
  ManualClock clock;
  MemoryTransport transport(std::make_shared<MemoryBus>());
  ServerDaemon server(transport, clock);
  RobotDaemon robot(std::string(40, 'a'), "fake", std::make_unique<FakeDriver>(PanRobot()), clock);
  try {
    server.AddRobot(robot, SessionOptions{});
    ADD_FAILURE() << "a 40-character robot name was served";
  } catch (const Error& e) {
    EXPECT_THAT(e.what(), HasSubstr("at most 31"));
  }
}

// server.h (installed) cannot name channels.h's kAnnouncePeriod, which the
// clients' waits are counted in: the two defaults must stay one value.
TEST(ServerDaemon, AnnouncesEveryKAnnouncePeriodByDefault) {
  EXPECT_EQ(ServerOptions{}.announce_period, kAnnouncePeriod);
  EXPECT_EQ(ServerDaemonOptions{}.announce_period, kAnnouncePeriod);
}

TEST(ServerDaemon, ASubscriptionErrorReachesItsCreatorWithOrWithoutTheFifoSubscribingThread) {
  // With fifo_priority the subscriptions are made on a short-lived thread (so
  // LCM's receive threads inherit the priority); its error must still be the
  // constructor's.
  RefusingTransport transport;
  ManualClock clock;
  for (int priority : {0, 5}) {
    EXPECT_THROW(ServerDaemon(transport, clock, ServerDaemonOptions{.fifo_priority = priority}),
                 TransportError)
        << "fifo_priority " << priority;
  }
}

TEST_F(ServerDaemonTest, RoutesAPackageToItsRobotAndAnswersOnTheClientsReplyChannel) {
  Request r{.client_id = kAlice, .sequence = 1};
  r.commands.push_back(Command{1, CommandType::kJointSetPoint, std::nullopt, "pan", {0.5}});
  Send("arm", r);
  Step();
  ASSERT_EQ(replies_["arm"].count(1), 1u);
  EXPECT_EQ(replies_["arm"][1].signal, Signal::kSuccess);
  EXPECT_EQ(fakes_["arm"]->calls.size(), 1u);
  EXPECT_TRUE(fakes_["bot"]->calls.empty()) << "the other robot saw nothing";
  EXPECT_THAT(channels_, ::testing::Contains(ReplyChannel("arm", kAlice)));
  EXPECT_THAT(channels_, ::testing::Contains(std::string(kAnnounceChannel)));
}

// Issue 11: a query whose answer the RobotDaemon's last iteration already
// knows is answered without it, in the acknowledgement's own package.
TEST_F(ServerDaemonTest, AnswersAStateQueryInTheAcknowledgementPackage) {
  Request first{.client_id = kAlice, .sequence = 1};
  first.queries.push_back(Query{1, QueryType::kJointState, ""});
  Send("bot", first);
  Step();
  ASSERT_EQ(replies_["bot"].count(1), 1u);
  clock_.Advance(milliseconds(1));
  Request second{.client_id = kAlice, .sequence = 2};
  second.queries.push_back(Query{2, QueryType::kJointState, ""});
  Send("bot", second);
  const auto reply_packages = [this] {
    return std::count(channels_.begin(), channels_.end(), ReplyChannel("bot", kAlice));
  };
  const auto before = reply_packages();
  server_->RunOnce(Duration(0));  // no RobotDaemon iteration
  client_.HandleFor(Duration(0));
  ASSERT_EQ(replies_["bot"].count(2), 1u);
  EXPECT_EQ(replies_["bot"][2].signal, Signal::kSuccess);
  EXPECT_EQ(replies_["bot"][2].values.size(), 3u);  // position, velocity, effort of the pan joint
  EXPECT_EQ(reply_packages() - before, 1) << "the acknowledgement and the answer in one package";
}

TEST_F(ServerDaemonTest, CountsUndecodableBytesAndKeepsServing) {
  const std::vector<std::uint8_t> garbage(40, 0xAB);
  client_.Publish(RequestChannel("bot"), garbage);
  Step();
  EXPECT_EQ(server_->malformed(), 1u);
  Request r{.client_id = kAlice, .sequence = 1};
  r.queries.push_back(Query{5, QueryType::kClock, ""});
  Send("bot", r);
  Step();
  EXPECT_EQ(replies_["bot"].at(5).signal, Signal::kSuccess);
}

TEST_F(ServerDaemonTest, KeepsServingOtherRobotsWhenOnesDriverThrows) {
  fakes_["bot"]->throw_on_execute = "serial port write failed";
  Request r{.client_id = kAlice, .sequence = 1};
  r.commands.push_back(Command{1, CommandType::kJointSetPoint, std::nullopt, "pan", {0.5}});
  Send("bot", r);
  Send("arm", r);
  Step();
  EXPECT_EQ(replies_["bot"].at(1).signal, Signal::kError);
  EXPECT_THAT(replies_["bot"].at(1).message,
              HasSubstr("driver 'fake' threw in Execute: serial port write failed"));
  EXPECT_EQ(replies_["arm"].at(1).signal, Signal::kSuccess);
  // The faulted robot refuses motion (PANIC) until reset, naming the fault.
  Request again{.client_id = kAlice, .sequence = 2};
  again.commands.push_back(Command{2, CommandType::kJointSetPoint, std::nullopt, "pan", {0.1}});
  Send("bot", again);
  Step();
  EXPECT_EQ(replies_["bot"].at(2).signal, Signal::kPanic);
  EXPECT_THAT(replies_["bot"].at(2).message, HasSubstr("serial port write failed"));
}

TEST_F(ServerDaemonTest, PublishesTheConfigurationWhenAskedAndStateWhenStreamed) {
  Request r{.client_id = kAlice, .sequence = 1};
  r.queries.push_back(Query{1, QueryType::kConfig, ""});
  r.queries.push_back(Query{2, QueryType::kStateStream, "", milliseconds(10)});
  Send("bot", r);
  Step();
  EXPECT_THAT(channels_, ::testing::Contains(ConfigChannel("bot")));
  EXPECT_THAT(channels_, ::testing::Contains(StateChannel("bot")));
}

}  // namespace
}  // namespace robotalk

namespace robotalk {
namespace {

// A latch file of its own (removed before and after), a clock, a bus and a client.
class ServerDaemonPanicLatch : public ::testing::Test {
 protected:
  ServerDaemonPanicLatch() { std::remove(latch.c_str()); }
  ~ServerDaemonPanicLatch() override { std::remove(latch.c_str()); }

  const std::string latch = ::testing::TempDir() + "/panic_latch_" +
                            ::testing::UnitTest::GetInstance()->current_test_info()->name() + ".txt";
  ManualClock clock;
  std::shared_ptr<MemoryBus> bus = std::make_shared<MemoryBus>();
  MemoryTransport client{bus};

  // Says hello to `server` and sends a set-point of 'pan' (id 1) that it
  // admits; returns the session.
  std::int64_t SendMove(ServerDaemon& server) {
    const std::int64_t session =
        SayHello(client, "bot", kAlice, [&] { server.RunOnce(Duration(0)); }).session_id;
    Request move{.client_id = kAlice, .session_id = session, .sequence = 1};
    move.commands.push_back(Command{1, CommandType::kJointSetPoint, std::nullopt, "pan", {0.5}});
    client.Publish(RequestChannel("bot"), EncodeRequest(move));
    server.RunOnce(Duration(0));
    return session;
  }
};

// Issue 9: after kill -9 and a restart, a latched PANIC was gone.
TEST_F(ServerDaemonPanicLatch, APanicSurvivesARestartUntilReset) {
  std::map<CommandId, Reply> replies;
  auto sub =
      client.Subscribe("ROBOTALK/bot/REPLY/.*", [&](const std::string&, std::span<const std::uint8_t> b) {
        for (Reply& r : DecodeReplyBatch(b).replies) replies[r.id] = r;
      });
  {
    MemoryTransport transport(bus);
    RobotDaemon robot("bot", "fake", std::make_unique<FakeDriver>(PanRobot()), clock);
    ServerDaemon server(transport, clock, ServerDaemonOptions{.panic_latch_path = latch});
    server.AddRobot(robot, SessionOptions{});
    Request panic{.client_id = kAlice, .sequence = 1, .panic = true};
    client.Publish(RequestChannel("bot"), EncodeRequest(panic));
    server.RunOnce(Duration(0));
    std::ifstream file(latch);
    std::string text((std::istreambuf_iterator<char>(file)), {});
    EXPECT_THAT(text, HasSubstr("bot\t")) << "written before the panic was acknowledged";
  }  // the server goes away (a crash keeps the same file)
  MemoryTransport transport(bus);
  auto driver = std::make_unique<FakeDriver>(PanRobot());
  FakeDriver* fake = driver.get();
  RobotDaemon robot("bot", "fake", std::move(driver), clock);
  ServerDaemon server(transport, clock, ServerDaemonOptions{.panic_latch_path = latch});
  server.AddRobot(robot, SessionOptions{});
  EXPECT_TRUE(robot.in_panic()) << "the restarted server starts in panic";
  EXPECT_THAT(robot.fault(), HasSubstr("latched before this server started"));
  const std::int64_t session = SendMove(server);
  robot.RunOnce(clock.Now());
  client.HandleFor(Duration(0));
  EXPECT_EQ(replies.at(1).signal, Signal::kPanic);
  EXPECT_TRUE(fake->calls.empty());
  Request reset{.client_id = kAlice, .session_id = session, .sequence = 2};
  reset.commands.push_back(Command{2, CommandType::kPanicReset, std::nullopt, "", {}});
  client.Publish(RequestChannel("bot"), EncodeRequest(reset));
  server.RunOnce(Duration(0));
  EXPECT_FALSE(robot.in_panic());
  std::ifstream file(latch);
  std::string text((std::istreambuf_iterator<char>(file)), {});
  EXPECT_THAT(text, ::testing::Not(HasSubstr("bot\t"))) << "the reset is on disk too";
}

// Reads the latch file whenever the server publishes a reply that answers
// ERROR: what was on disk at the moment it left.
class LatchAtErrorTransport final : public ForwardingTransport {
 public:
  // The base keeps a reference to bus_transport_, constructed after it (it is
  // not used before).
  LatchAtErrorTransport(std::shared_ptr<MemoryBus> bus, std::string latch)
      : ForwardingTransport(bus_transport_), bus_transport_(std::move(bus)), latch_(std::move(latch)) {}
  void Publish(const std::string& channel, std::span<const std::uint8_t> bytes) override {
    if (ParseReplyChannel(channel)) {
      for (const Reply& r : DecodeReplyBatch(bytes).replies) {
        if (r.signal != Signal::kError) continue;
        std::ifstream file(latch_);
        on_disk_at_error.assign(std::istreambuf_iterator<char>(file), {});
      }
    }
    ForwardingTransport::Publish(channel, bytes);
  }

  std::string on_disk_at_error;

 private:
  MemoryTransport bus_transport_;
  std::string latch_;
};

// Issue 20: the latch is written in one place (ServerDaemon::Drain), for a
// panic the RobotDaemon latched itself (a driver fault) as for a client's,
// before the fault's ERROR leaves.
TEST_F(ServerDaemonPanicLatch, ADriverFaultIsOnDiskBeforeItsErrorIsSent) {
  LatchAtErrorTransport transport(bus, latch);
  auto driver = std::make_unique<FakeDriver>(PanRobot());
  driver->throw_on_execute = "serial port write failed";
  RobotDaemon robot("bot", "fake", std::move(driver), clock);
  ServerDaemon server(transport, clock, ServerDaemonOptions{.panic_latch_path = latch});
  server.AddRobot(robot, SessionOptions{});
  SendMove(server);
  robot.RunOnce(clock.Now());  // the driver throws: a fault, panic
  server.RunOnce(Duration(0));
  EXPECT_THAT(transport.on_disk_at_error,
              HasSubstr("bot\tdriver 'fake' threw in Execute: serial port write failed"));
}

}  // namespace
}  // namespace robotalk

namespace robotalk {
namespace {

// Issue 9: two servers serving the same robot name both executed every command.
TEST(ServerDaemonOneRobotOneServer, TheServerThatStartedLaterRefusesTheRobotAndNamesTheOther) {
  ManualClock clock;
  auto bus = std::make_shared<MemoryBus>();
  MemoryTransport first_transport(bus), second_transport(bus), client(bus);
  auto first_driver = std::make_unique<FakeDriver>(PanRobot());
  auto second_driver = std::make_unique<FakeDriver>(PanRobot());
  FakeDriver* first_fake = first_driver.get();
  FakeDriver* second_fake = second_driver.get();
  RobotDaemon first_robot("bot", "fake", std::move(first_driver), clock);
  RobotDaemon second_robot("bot", "fake", std::move(second_driver), clock);
  ServerDaemon first(first_transport, clock, ServerDaemonOptions{.server_id = 7});
  first.AddRobot(first_robot, SessionOptions{});
  first.RunOnce(Duration(0));  // serving, announcing
  clock.Advance(std::chrono::seconds(5));
  ServerDaemon second(second_transport, clock, ServerDaemonOptions{.server_id = 3});  // smaller id, later
  second.AddRobot(second_robot, SessionOptions{});
  second.RunOnce(Duration(0));  // starts, announces
  clock.Advance(std::chrono::seconds(1));
  for (int i = 0; i < 3; ++i) {  // both hear each other's ANNOUNCE
    first.RunOnce(Duration(0));
    second.RunOnce(Duration(0));
  }
  EXPECT_EQ(first.refused("bot"), "") << "the first server keeps serving";
  EXPECT_THAT(second.refused("bot"), HasSubstr("is served by server 0000000000000007"));

  std::map<CommandId, Reply> replies;
  auto sub =
      client.Subscribe("ROBOTALK/bot/REPLY/.*", [&](const std::string&, std::span<const std::uint8_t> b) {
        for (Reply& r : DecodeReplyBatch(b).replies) replies[r.id] = r;
      });
  const std::int64_t session = SayHello(client, "bot", kAlice, [&] {
                                 first.RunOnce(Duration(0));
                                 second.RunOnce(Duration(0));
                               }).session_id;
  Request move{.client_id = kAlice, .session_id = session, .sequence = 1};
  move.commands.push_back(Command{1, CommandType::kJointSetPoint, std::nullopt, "pan", {0.5}});
  client.Publish(RequestChannel("bot"), EncodeRequest(move));
  for (int i = 0; i < 2; ++i) {
    first.RunOnce(Duration(0));
    second.RunOnce(Duration(0));
    first_robot.RunOnce(clock.Now());
    second_robot.RunOnce(clock.Now());
  }
  client.HandleFor(Duration(0));
  EXPECT_EQ(replies.at(1).signal, Signal::kSuccess);
  EXPECT_EQ(first_fake->calls.size(), 1u);
  EXPECT_TRUE(second_fake->calls.empty()) << "executed once, by one server";
}

}  // namespace
}  // namespace robotalk
