// Issue 19 item 2: a panic the server refused was reported as acknowledged.
// RobotClient::Panic() against the real server core (robotalk::Server,
// kinematic driver) on an in-process bus, open and keyed mode, and against a
// hand-made answer for what no correct server sends: the client believes only
// the reply package's explicit panic answer, in every mode. And item 6: a
// keyed client keeps its id across a server restart, whoever says hello first.
#include "kinematic_driver.h"
#include "robotalk/channels.h"
#include "robotalk/client_errors.h"
#include "robotalk/keys.h"
#include "robotalk/memory_transport.h"
#include "robotalk/request.h"
#include "robotalk/robot_client.h"
#include "robotalk/server.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <stdlib.h>

#include <atomic>
#include <filesystem>
#include <fstream>
#include <future>
#include <optional>
#include <thread>

namespace robotalk {
namespace {

using std::chrono::seconds;
using ::testing::HasSubstr;
namespace fs = std::filesystem;

const std::string kRobot = "pioneer";

class ClientPanicTest : public ::testing::Test {
 protected:
  ClientPanicTest() {
    RegisterKinematicDriver(registry_);
    char pattern[] = "/tmp/robotalk_client_panic_XXXXXX";
    dir_ = mkdtemp(pattern);
  }
  ~ClientPanicTest() override {
    server_.reset();
    fs::remove_all(dir_);
  }

  // Keyed mode: a server key and three clients (all rights, query and
  // panic, query only), as robotalk-keygen and an operator would write them.
  void MakeKeys() {
    for (const char* who : {"server", "alice", "monitor", "viewer"}) {
      WriteKeyFiles(dir_ / who, KeyPair::Generate(), who);
    }
    std::ofstream list(dir_ / "clients");
    list << ReadPublicKeyFile(dir_ / "alice.pub").key.ToString() << " alice *=all\n"
         << ReadPublicKeyFile(dir_ / "monitor.pub").key.ToString() << " monitor *=query,panic\n"
         << ReadPublicKeyFile(dir_ / "viewer.pub").key.ToString() << " viewer *=query\n";
  }
  void StartServer(bool keyed) {
    ServerOptions o;
    o.precise_timing = false;
    if (keyed) {
      o.key_file = (dir_ / "server").string();
      o.clients_file = (dir_ / "clients").string();
    }
    const RobotSpec spec{
        kRobot, "kinematic", std::string(ROBOTALK_MODELS_DIR) + "/pioneer2dx_pantilt.urdf", {}};
    server_ = std::make_unique<Server>(server_end_, o, std::vector<RobotSpec>{spec}, registry_, clock_);
    server_->Start();
  }
  std::unique_ptr<RobotClient> Client(const std::string& key = "") {
    ClientOptions o;
    o.transport = &client_end_;
    o.timeout = seconds(5);
    o.connect_timeout = seconds(5);
    if (!key.empty()) o.key_file = (dir_ / key).string();
    // Its own pins: the default file is the user's, shared with every other
    // test run on the machine (a key pinned there by another run is "CHANGED").
    o.known_servers_file = (dir_ / "known_servers").string();
    auto c = std::make_unique<RobotClient>(o);
    c->Connect(kRobot);
    return c;
  }

  fs::path dir_;
  std::shared_ptr<MemoryBus> bus_ = std::make_shared<MemoryBus>();
  MemoryTransport server_end_{bus_};
  MemoryTransport client_end_{bus_};
  SteadyClock clock_;
  DriverRegistry registry_;
  std::unique_ptr<Server> server_;  // last: stopped before the transports go
};

TEST_F(ClientPanicTest, AKeyedPanicRefusedForRightsThrowsWithTheServersReasonAndTheRobotGoesOn) {
  MakeKeys();
  StartServer(/*keyed=*/true);
  auto viewer = Client("viewer");
  try {
    viewer->Panic();
    ADD_FAILURE() << "a refused panic was reported as taken";
  } catch (const PanicRefusedError& e) {
    EXPECT_THAT(e.what(), HasSubstr("may not panic robot 'pioneer'"));
    EXPECT_THAT(e.what(), HasSubstr("NOT in panic"));
  }
  auto alice = Client("alice");
  const Reply moved = alice->SetJoint("pan", {0.2});
  EXPECT_EQ(moved.signal, Signal::kSuccess) << "the robot is not in panic: " << moved.message;
}

TEST_F(ClientPanicTest, AKeyedPanicWithThePanicRightIsTaken) {
  MakeKeys();
  StartServer(/*keyed=*/true);
  auto monitor = Client("monitor");
  EXPECT_NO_THROW(monitor->Panic());
  auto alice = Client("alice");
  EXPECT_EQ(alice->SetJoint("pan", {0.2}).signal, Signal::kPanic);
}

TEST_F(ClientPanicTest, AKeyedPanicAfterAServerRestartIsSentAgainInANewSessionAndTaken) {
  MakeKeys();
  StartServer(/*keyed=*/true);
  auto monitor = Client("monitor");
  server_.reset();
  StartServer(/*keyed=*/true);  // the client's session is unknown to the new instance
  EXPECT_NO_THROW(monitor->Panic());
  auto alice = Client("alice");
  EXPECT_EQ(alice->SetJoint("pan", {0.2}).signal, Signal::kPanic);
}

TEST_F(ClientPanicTest, AnOpenModePanicOutsideAnySessionIsTakenByTheServersExplicitAnswer) {
  StartServer(/*keyed=*/false);
  auto client = Client();
  server_.reset();
  StartServer(/*keyed=*/false);  // a new instance: the client's session is unknown there
  EXPECT_NO_THROW(client->Panic());
  EXPECT_EQ(Client()->SetJoint("pan", {0.2}).signal, Signal::kPanic);
}

TEST_F(ClientPanicTest, AfterARestartAnotherKeyCannotTakeAKeyedClientsIdAndTheClientGoesOn) {
  MakeKeys();
  StartServer(/*keyed=*/true);
  auto alice = Client("alice");
  ASSERT_EQ(alice->Stop().signal, Signal::kSuccess);
  server_.reset();
  StartServer(/*keyed=*/true);
  // Another listed key says hello first under alice's id (a process that
  // does not use the library: the library refuses such an id itself).
  MemoryTransport attacker(bus_);
  std::optional<HelloAnswer> answer;
  auto sub = attacker.Subscribe(
      HelloAnswerChannel(kRobot, alice->client_id()),
      [&](const std::string&, std::span<const std::uint8_t> b) { answer = DecodeHelloAnswer(b); });
  const ClientHandshake hello(ReadSecretKeyFile(dir_ / "monitor"), alice->client_id());
  attacker.Publish(HelloChannel(kRobot), EncodeHello(Hello{.keyed = true, .body = hello.hello()}));
  for (int i = 0; i < 400 && !answer; ++i) attacker.HandleFor(std::chrono::milliseconds(5));
  ASSERT_TRUE(answer);
  EXPECT_EQ(answer->session_id, 0) << "another key took alice's client id";
  EXPECT_THAT(answer->refusal, HasSubstr("is not one of this key's"));
  try {
    alice->Stop();  // its session died with the old instance: an unknown outcome, once
  } catch (const UnknownOutcomeError&) {
  }
  EXPECT_EQ(alice->Stop().signal, Signal::kSuccess) << "the same client object goes on";
  EXPECT_THROW(
      {
        ClientOptions o;
        o.transport = &client_end_;
        o.key_file = (dir_ / "monitor").string();
        o.known_servers_file = (dir_ / "known_servers").string();
        o.client_id = alice->client_id();
        RobotClient impostor(o);
      },
      ClientError);
}

// What no correct server sends, answered by hand once the real server is
// gone: the client must not infer "taken" from anything but PANIC_TAKEN.
class HandAnsweredPanicTest : public ClientPanicTest {
 protected:
  // Answers every REQUEST package with `answer` (client, session and
  // sequence filled in) while `call` runs on another thread.
  void AnswerWhile(ReplyBatch answer, const std::function<void()>& call) {
    auto sub = server_end_.Subscribe(
        RequestChannel(kRobot), [&](const std::string&, std::span<const std::uint8_t> bytes) {
          const Request r = DecodeRequest(bytes);
          ReplyBatch b = answer;
          b.client_id = r.client_id;
          b.session_id = r.session_id;
          b.ack_sequence = r.sequence;
          if (!r.panic) b.panic = PanicStatus::kNone;
          server_end_.Publish(ReplyChannel(kRobot, r.client_id), EncodeReplyBatch(b));
        });
    auto done = std::async(std::launch::async, call);
    while (done.wait_for(std::chrono::milliseconds(1)) != std::future_status::ready) {
      server_end_.HandleFor(std::chrono::milliseconds(5));
    }
    done.get();
  }
};

TEST_F(HandAnsweredPanicTest, AnOpenModeSessionUnknownAnswerIsNoLongerTakenForAnAcknowledgement) {
  StartServer(/*keyed=*/false);
  auto client = Client();
  server_.reset();
  ReplyBatch unknown;  // the old special case: SESSION_UNKNOWN counted as the panic's acknowledgement
  unknown.session_status = SessionStatus::kUnknown;
  AnswerWhile(unknown, [&] { EXPECT_THROW(client->Panic(), PanicRefusedError); });
}

TEST_F(HandAnsweredPanicTest, AnOpenModePanicAnsweredRefusedThrowsWithTheReason) {
  StartServer(/*keyed=*/false);
  auto client = Client();
  server_.reset();
  ReplyBatch refused;
  refused.panic = PanicStatus::kRefused;
  refused.panic_refusal = "the reason the server gave";
  AnswerWhile(refused, [&] {
    try {
      client->Panic();
      ADD_FAILURE() << "a refused panic was reported as taken";
    } catch (const PanicRefusedError& e) {
      EXPECT_THAT(e.what(), HasSubstr("the reason the server gave"));
    }
  });
}

}  // namespace
}  // namespace robotalk
