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

#include <algorithm>
#include <atomic>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <future>
#include <mutex>
#include <optional>
#include <regex>
#include <thread>
#include <vector>

namespace robotalk {
namespace {

using std::chrono::seconds;
using ::testing::HasSubstr;
namespace fs = std::filesystem;

const std::string kRobot = "pioneer";

// The steady clock of a server instance that ran before its host rebooted
// (an hour more uptime than the live instance's): its announcements are
// stamped in the live instance's future.
class AheadClock final : public Clock {
 public:
  TimePoint Now() const override { return inner_.Now() + std::chrono::hours(1); }

 private:
  SteadyClock inner_;
};

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
  void StartServer(bool keyed, bool allow_duplicate_robots = false, const Clock* clock = nullptr) {
    ServerOptions o;
    o.precise_timing = false;
    o.allow_duplicate_robots = allow_duplicate_robots;
    if (keyed) {
      o.key_file = (dir_ / "server").string();
      o.clients_file = (dir_ / "clients").string();
    }
    const RobotSpec spec{
        kRobot, "kinematic", std::string(ROBOTALK_MODELS_DIR) + "/pioneer2dx_pantilt.urdf", {}};
    server_ = std::make_unique<Server>(server_end_, o, std::vector<RobotSpec>{spec}, registry_,
                                       clock != nullptr ? *clock : clock_);
    server_->Start();
  }
  std::unique_ptr<RobotClient> Client(const std::string& key = "", Duration heartbeat = {}) {
    ClientOptions o;
    if (heartbeat.count() > 0) o.heartbeat_interval = heartbeat;
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

  // The running server's first ANNOUNCE (signed in keyed mode), or empty
  // when none came within 5 s.
  std::vector<std::uint8_t> RecordAnnounce() {
    MemoryTransport recorder(bus_);
    std::mutex mu;
    std::vector<std::uint8_t> heard;
    auto sub = recorder.Subscribe(kAnnounceChannel, [&](const std::string&, std::span<const std::uint8_t> b) {
      std::lock_guard lock(mu);
      if (heard.empty()) heard.assign(b.begin(), b.end());
    });
    for (int i = 0; i < 100; ++i) {
      recorder.HandleFor(std::chrono::milliseconds(50));
      std::lock_guard lock(mu);
      if (!heard.empty()) break;
    }
    sub.reset();
    std::lock_guard lock(mu);
    return heard;
  }

  // Keyed instance A, its first ANNOUNCE recorded (empty when none came
  // within 5 s), then instance B, live. In its start-up window the replay
  // would make B give the robot up (a Known gap of its own, docs/safety.md):
  // not what is measured here. `old_clock`: instance A's (default: the test's).
  std::vector<std::uint8_t> RestartKeyedKeepingAnAnnounce(const Clock* old_clock = nullptr) {
    MakeKeys();
    StartServer(/*keyed=*/true, /*allow_duplicate_robots=*/false, old_clock);
    std::vector<std::uint8_t> announce = RecordAnnounce();
    server_.reset();
    StartServer(/*keyed=*/true, /*allow_duplicate_robots=*/true);
    return announce;
  }

  // client.Panic() while `replayer` publishes `announce` every `every`
  // (10 s at most): "" when taken, else what it threw.
  static std::string PanicWhileReplaying(RobotClient& client, MemoryTransport& replayer,
                                         const std::vector<std::uint8_t>& announce, Duration every) {
    std::atomic<bool> stop{false};
    std::thread replay([&] {
      const auto end = std::chrono::steady_clock::now() + seconds(10);  // bounded
      while (!stop && std::chrono::steady_clock::now() < end) {
        replayer.Publish(kAnnounceChannel, announce);
        std::this_thread::sleep_for(every);
      }
    });
    std::string error;
    try {
      client.Panic();
    } catch (const std::exception& e) {
      error = e.what();
    }
    stop = true;
    replay.join();
    return error;
  }

  // gaps14's measure (the tests below): a keyed client on a bus of its own
  // behind a relay that holds every panic package 600 ms panics while
  // instance A's (clock `old_clock`) recorded ANNOUNCE is replayed every
  // 1 ms; the panic is taken and the live session never ends.
  void ExpectAReplayedOldAnnounceNeverEndsTheSessionOfAPanicAnsweredLate(const Clock* old_clock) {
    const std::vector<std::uint8_t> old_announce = RestartKeyedKeepingAnAnnounce(old_clock);
    ASSERT_FALSE(old_announce.empty()) << "instance A announced nothing within 5 s";

    // The relay: what the client says goes to the server's bus (a panic 600 ms
    // late), everything else comes back.
    auto client_bus = std::make_shared<MemoryBus>();
    MemoryTransport near(client_bus), far(bus_), client_side(client_bus), replayer(client_bus);
    const std::string from_client = "ROBOTALK/" + kRobot + "/(REQUEST|HELLO)";
    std::mutex held_mu;
    std::vector<
        std::pair<std::chrono::steady_clock::time_point, std::pair<std::string, std::vector<std::uint8_t>>>>
        held;  // GUARDED_BY(held_mu)
    auto up = near.Subscribe(from_client, [&](const std::string& channel, std::span<const std::uint8_t> b) {
      bool panic = false;
      if (channel == RequestChannel(kRobot)) {
        try {
          panic = DecodeRequest(b).panic;
        } catch (const std::exception&) {
        }
      }
      if (!panic) {
        far.Publish(channel, b);
        return;
      }
      std::lock_guard lock(held_mu);
      held.push_back({std::chrono::steady_clock::now() + std::chrono::milliseconds(600),
                      {channel, std::vector<std::uint8_t>(b.begin(), b.end())}});
    });
    const std::regex client_channels(from_client);
    auto down = far.Subscribe(".*", [&](const std::string& channel, std::span<const std::uint8_t> b) {
      if (!std::regex_match(channel, client_channels)) near.Publish(channel, b);
    });
    std::atomic<bool> stop{false};
    std::thread relay([&] {
      const auto end = std::chrono::steady_clock::now() + seconds(30);  // bounded
      while (!stop && std::chrono::steady_clock::now() < end) {
        near.HandleFor(std::chrono::milliseconds(1));
        far.HandleFor(std::chrono::milliseconds(1));
        std::lock_guard lock(held_mu);
        const auto now = std::chrono::steady_clock::now();
        for (auto it = held.begin(); it != held.end();) {
          if (it->first > now) {
            ++it;
            continue;
          }
          far.Publish(it->second.first, it->second.second);
          it = held.erase(it);
        }
      }
    });
    ClientOptions o;
    o.transport = &client_side;
    o.timeout = seconds(5);
    o.connect_timeout = seconds(5);
    o.key_file = (dir_ / "monitor").string();
    o.known_servers_file = (dir_ / "known_servers").string();
    auto monitor = std::make_unique<RobotClient>(o);
    monitor->Connect(kRobot);
    const std::string error =
        PanicWhileReplaying(*monitor, replayer, old_announce, std::chrono::milliseconds(1));
    const std::uint64_t lost = monitor->stats().sessions_lost;
    stop = true;
    monitor.reset();
    relay.join();
    EXPECT_EQ(error, "") << "a panic the live server took was reported otherwise";
    EXPECT_EQ(lost, 0u) << "a replayed announcement of an older instance ended the live session";
    auto alice = Client("alice");
    EXPECT_EQ(alice->SetJoint("pan", {0.2}).signal, Signal::kPanic) << "the robot is not halted";
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

// Review 12's known gap, measured (gaps13): a forger floods a keyed server
// with packages naming made-up sessions, with and without the panic flag,
// 20 times each of the signed answers' budgets (1,000 SESSION_UNKNOWN
// answers a second, and as many panic refusals), from before the server
// restarts, and a keyed client whose session the new instance does not know
// calls Panic(). The promise: a panic is never lost, a forged flood cannot
// disable a robot. Before: the client learnt of the restart only when one
// of its retransmissions fell within a budget (a chance of 1 in 20 each).
TEST_F(ClientPanicTest, AKeyedPanicAfterARestartIsTakenDuringAFloodOfPackagesNamingMadeUpSessions) {
  MakeKeys();
  StartServer(/*keyed=*/true);
  // Its heartbeats (every 250 ms by default) would also learn of the restart
  // when one falls within the budget: the panic alone is measured here.
  auto monitor = Client("monitor", seconds(30));
  MemoryTransport forger(bus_);
  std::atomic<bool> stop{false};
  std::atomic<std::int64_t> forged{0};
  std::thread flood([&] {
    // One panic and one other package every 50 us, 40,000 a second, spread
    // evenly (a burst once a millisecond would leave the server idle between
    // bursts, its next token for whichever package comes first).
    constexpr auto kStep = std::chrono::microseconds(50);
    auto next = std::chrono::steady_clock::now();
    for (std::int64_t i = 0; !stop; i += 2) {
      for (std::int64_t k = i; k < i + 2; ++k) {
        forger.Publish(RequestChannel(kRobot), EncodeRequest(Request{.client_id = 0x5000'0000 + k,
                                                                     .session_id = 1'000'000 + k,
                                                                     .sequence = 1,
                                                                     .panic = k % 2 == 0}));
      }
      forged += 2;
      next = std::max(next + kStep, std::chrono::steady_clock::now() - 20 * kStep);  // a bounded rate
      std::this_thread::sleep_until(next);
    }
  });
  server_.reset();
  StartServer(/*keyed=*/true);  // the monitor's session is unknown to the new instance
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  ASSERT_EQ(monitor->stats().sessions_lost, 0u) << "the client learnt of the restart before its panic";
  const std::int64_t forged_before = forged;
  const auto start = std::chrono::steady_clock::now();
  std::string error;
  try {
    monitor->Panic();
  } catch (const std::exception& e) {
    error = e.what();
  }
  const auto end = std::chrono::steady_clock::now();
  const double rate = (forged - forged_before) / std::max(1e-3, ToSeconds(end - start));
  stop = true;
  flood.join();
  std::printf(
      "[ measured ] keyed Panic() after a restart, %.0f forged packages/s naming made-up sessions (half "
      "panics; %zu dropped by the server's full queue): %s after %.3f s (%llu retransmissions)\n",
      rate, server_end_.dropped(), error.empty() ? "taken" : error.c_str(), ToSeconds(end - start),
      static_cast<unsigned long long>(monitor->stats().retransmissions));
  EXPECT_EQ(error, "") << "the panic was lost to the flood";
  auto alice = Client("alice");
  EXPECT_EQ(alice->SetJoint("pan", {0.2}).signal, Signal::kPanic) << "the robot is not halted";
}

// final13: while a panic waits, the keyed client believes a signed ANNOUNCE
// of its robot from another server instance (gaps13, above). A replay of a
// real ANNOUNCE recorded before an earlier restart passes that check: it
// ended the live session, the panic was answered "session unknown" twice and
// Panic() threw "refused the panic (the robot is NOT in panic because of
// it)" while the live server had taken both (3 of 5 runs, replayed every
// 20 us). A panic the live server answers is never reported refused.
TEST_F(ClientPanicTest, AReplayedOldAnnounceNeverMakesATakenPanicLookRefused) {
  const std::vector<std::uint8_t> old_announce = RestartKeyedKeepingAnAnnounce();
  ASSERT_FALSE(old_announce.empty()) << "instance A announced nothing within 5 s";
  auto monitor = Client("monitor");
  MemoryTransport replayer(bus_);
  const std::string error =
      PanicWhileReplaying(*monitor, replayer, old_announce, std::chrono::microseconds(20));
  EXPECT_EQ(error, "") << "a panic the live server took was reported otherwise";
  auto alice = Client("alice");
  EXPECT_EQ(alice->SetJoint("pan", {0.2}).signal, Signal::kPanic) << "the robot is not halted";
}

// gaps14 (review 14's gap): the replay above never reaches a panic the
// live server answers at once; one it answers later than the retransmission
// timeout (its panic-latch fsync on slow storage) did: the replayed
// ANNOUNCE of the earlier instance, signed and in the client's robot, ended
// the live session, and whatever it had outstanding became an unknown
// outcome. Here the client is on a bus of its own behind a relay that holds
// every panic package 600 ms. An announcement of an instance older than the
// session (signed before its hello was answered) never ends it.
TEST_F(ClientPanicTest, AReplayedOldAnnounceNeverEndsTheSessionOfAPanicAnsweredLate) {
  ExpectAReplayedOldAnnounceNeverEndsTheSessionOfAPanicAnsweredLate(nullptr);
}

// final14b: the check above took an announcement stamped in the client's
// future as made now, so one of an instance whose steady clock was ahead
// (its host rebooted since, or up longer) passed it and ended the session
// (3 sessions lost in one Panic()). One stamped further ahead than an
// announcement's life is never believed.
TEST_F(ClientPanicTest, AReplayedAnnounceOfAnInstanceWhoseClockWasAheadNeverEndsTheSession) {
  AheadClock ahead;
  ExpectAReplayedOldAnnounceNeverEndsTheSessionOfAPanicAnsweredLate(&ahead);
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
    AnswerWhile([&](const Request&) { return answer; }, call);
  }
  // The same with an answer made for each package.
  void AnswerWhile(const std::function<ReplyBatch(const Request&)>& answer,
                   const std::function<void()>& call) {
    auto sub = server_end_.Subscribe(
        RequestChannel(kRobot), [&](const std::string&, std::span<const std::uint8_t> bytes) {
          const Request r = DecodeRequest(bytes);
          ReplyBatch b = answer(r);
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

// Review 14: a server's text (a reply's message) embedded in the exception
// of a call that failed, as the panic's refusal and the hello's are: escaped
// (no control character reaches whoever prints e.what(), a terminal or a
// log), and a CONFIG answer that is no hash is a RoboTalk error naming it,
// not std::stoull's std::invalid_argument.
class HandAnsweredTextTest : public HandAnsweredPanicTest {
 protected:
  // Every query answered `signal` with `message`.
  void AnswerQueriesWhile(Signal signal, const std::string& message, const std::function<void()>& call) {
    AnswerWhile(
        [&](const Request& r) {
          ReplyBatch b;
          for (const robotalk::Query& q : r.queries)
            b.replies.push_back(Reply{.id = q.id, .signal = signal, .message = message});
          return b;
        },
        call);
  }
  static void ExpectNoControlCharacter(const std::string& text) {
    for (const char c : text) {
      const auto u = static_cast<unsigned char>(c);
      EXPECT_FALSE(u < 0x20 || u == 0x7f) << "control character " << static_cast<int>(u) << " in: " << text;
    }
    EXPECT_EQ(text.find("\xc2\x9b"), std::string::npos) << "C1 CSI in: " << text;
  }
};

const std::string kHostile =
    "bad\x1b[31m red\a\n  robotalk: a forged line\r\xc2\x9b"
    "2J";

TEST_F(HandAnsweredTextTest, AServersMessageInAFailedCallsExceptionIsEscaped) {
  StartServer(/*keyed=*/false);
  auto client = Client();
  server_.reset();
  std::vector<std::string> texts;
  AnswerQueriesWhile(Signal::kError, kHostile, [&] {
    try {
      client->StartStateStream(std::chrono::milliseconds(100), [](const StateSample&) {});
      ADD_FAILURE() << "StartStateStream took an ERROR";
    } catch (const ClientError& e) {
      texts.push_back(e.what());
    }
    try {
      client->ReloadModel();
      ADD_FAILURE() << "ReloadModel took an ERROR";
    } catch (const ClientError& e) {
      texts.push_back(e.what());
    }
  });
  ASSERT_EQ(texts.size(), 2u);
  for (const std::string& text : texts) {
    EXPECT_THAT(text, HasSubstr("bad\\x1b[31m red\\x07\\x0a  robotalk: a forged line\\x0d\\xc2\\x9b2J"));
    ExpectNoControlCharacter(text);
  }
}

TEST_F(HandAnsweredTextTest, AConfigAnswerThatIsNoHashIsARobotalkErrorNamingIt) {
  StartServer(/*keyed=*/false);
  auto client = Client();
  server_.reset();
  AnswerQueriesWhile(Signal::kSuccess, "not a hash\x1b[2J", [&] {
    try {
      client->ReloadModel();
      ADD_FAILURE() << "ReloadModel took a CONFIG answer that is no hash";
    } catch (const Error& e) {
      EXPECT_THAT(e.what(), HasSubstr("not a hash\\x1b[2J"));
      ExpectNoControlCharacter(e.what());
    } catch (const std::exception& e) {
      ADD_FAILURE() << "not a RoboTalk error: " << e.what();
    }
  });
}

}  // namespace
}  // namespace robotalk
