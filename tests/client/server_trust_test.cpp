// Issue 19 items 4 and 7: which server a keyed client trusts, and what it
// accepts from the multicast. A keyed client pins the server key on first use
// (like SSH's known_hosts) or takes it from --server-key; a server with
// another key is refused; STATE and CONFIG must carry the trusted server's
// signature; a CONFIG flood cannot grow the client's memory.
//
// The real server core (robotalk::Server, kinematic driver) and RobotClient
// on one in-process MemoryBus; a "forger" endpoint is anyone else on the LAN.
#include "client/real_server_support.h"
#include "config_codec.h"
#include "kinematic_driver.h"
#include "robotalk/broadcast_signature.h"
#include "robotalk/channels.h"
#include "robotalk/keys.h"
#include "robotalk/memory_transport.h"
#include "robotalk/request.h"
#include "robotalk/robot_client.h"
#include "robotalk/server.h"
#include "robotalk/urdf_import.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <thread>

namespace robotalk {
namespace {

namespace fs = std::filesystem;
using std::chrono::milliseconds;
using std::chrono::seconds;
using ::testing::HasSubstr;
using testing::WaitUntil;

const std::string kRobot = "pioneer";

class ServerTrustTest : public ::testing::Test {
 protected:
  ServerTrustTest() {
    RegisterKinematicDriver(registry_);
    dir_ = fs::temp_directory_path() / ("robotalk_server_trust_test_" + std::to_string(::getpid()) + "_" +
                                        std::to_string(std::mt19937_64(std::random_device{}())()));
    fs::create_directories(dir_);
    for (const char* name : {"server", "mallory", "alice"})
      WriteKeyFiles(dir_ / name, KeyPair::Generate(), name);
    std::ofstream(dir_ / "clients") << Slurp(dir_ / "alice.pub") << " *=all\n";
    ::chmod((dir_ / "clients").c_str(), 0600);
  }
  ~ServerTrustTest() override {
    server_.reset();
    fs::remove_all(dir_);
  }

  static std::string Slurp(const fs::path& p) {
    std::ifstream in(p);
    std::string line;
    std::getline(in, line);
    return line;
  }
  // A keyed server of kRobot with the secret key `key` ("server", or
  // "mallory": an impersonator who copied the access list, which is public).
  void StartServer(const std::string& key, bool allow_duplicate_robots = false) {
    server_.reset();
    server_ = KeyedServer(server_end_, key, allow_duplicate_robots);
  }
  // The same on its own endpoint `end`, started.
  std::unique_ptr<Server> KeyedServer(Transport& end, const std::string& key, bool allow_duplicate_robots) {
    ServerOptions o;
    o.precise_timing = false;
    o.key_file = (dir_ / key).string();
    o.clients_file = (dir_ / "clients").string();
    o.allow_duplicate_robots = allow_duplicate_robots;
    const RobotSpec spec{
        kRobot, "kinematic", std::string(ROBOTALK_MODELS_DIR) + "/pioneer2dx_pantilt.urdf", {}};
    auto server = std::make_unique<Server>(end, o, std::vector<RobotSpec>{spec}, registry_, clock_);
    server->Start();
    return server;
  }
  ClientOptions Options() {
    ClientOptions o;
    o.transport = &client_end_;
    o.key_file = (dir_ / "alice").string();
    o.known_servers_file = (dir_ / "home" / "known_servers").string();
    o.timeout = seconds(5);
    o.connect_timeout = seconds(2);
    return o;
  }
  std::string ConnectError(ClientOptions o) {
    RobotClient client(o);
    try {
      client.Connect(kRobot);
    } catch (const ClientError& e) {
      return e.what();
    }
    return "connected";
  }

  fs::path dir_;
  std::shared_ptr<MemoryBus> bus_ = std::make_shared<MemoryBus>();
  MemoryTransport server_end_{bus_};
  MemoryTransport client_end_{bus_};
  MemoryTransport forger_{bus_};
  SteadyClock clock_;
  DriverRegistry registry_;
  std::unique_ptr<Server> server_;
};

TEST_F(ServerTrustTest, AKeyedClientPinsTheServerKeyOnFirstUseAndSaysSo) {
  StartServer("server");
  const PublicKey server_key = ReadPublicKeyFile(dir_ / "server.pub").key;
  {
    RobotClient first(Options());
    first.Connect(kRobot);
    const TrustedServer trust = first.trusted_server();
    EXPECT_EQ(trust.source, TrustedServer::Source::kPinnedNow);
    EXPECT_EQ(trust.fingerprint, server_key.Fingerprint());
    EXPECT_EQ(trust.file, Options().known_servers_file);
  }
  EXPECT_EQ(Slurp(Options().known_servers_file), "pioneer memory:// " + server_key.ToString());
  RobotClient second(Options());
  second.Connect(kRobot);
  EXPECT_EQ(second.trusted_server().source, TrustedServer::Source::kPinned);
  EXPECT_EQ(second.Goto(0.1, 0, 0).signal, Signal::kSuccess);
}

// The reproducer: a fake server answered a keyed client's `goto 1 0 0` with
// SUCCESS and base_pose zeros; only --server-key refused it.
TEST_F(ServerTrustTest, AServerWithAnotherKeyThanThePinnedOneIsRefusedNamingBothKeys) {
  StartServer("server");
  RobotClient(Options()).Connect(kRobot);  // pins the real server
  StartServer("mallory");                  // the real one is gone; an impersonator answers
  const std::string error = ConnectError(Options());
  EXPECT_THAT(error, HasSubstr("the server's key has CHANGED"));
  EXPECT_THAT(error, HasSubstr(ReadPublicKeyFile(dir_ / "server.pub").key.Fingerprint()));
  EXPECT_THAT(error, HasSubstr(ReadPublicKeyFile(dir_ / "mallory.pub").key.Fingerprint()));
  EXPECT_THAT(error, HasSubstr("delete line 1 of " + Options().known_servers_file));
}

TEST_F(ServerTrustTest, AnExplicitServerKeyOverridesThePinAndLeavesTheFileAlone) {
  StartServer("server");
  RobotClient(Options()).Connect(kRobot);
  const std::string pins = Slurp(Options().known_servers_file);
  StartServer("mallory");  // say: the server really was given a new key
  ClientOptions o = Options();
  o.server_key_file = (dir_ / "mallory.pub").string();
  RobotClient client(o);
  client.Connect(kRobot);
  EXPECT_EQ(client.trusted_server().source, TrustedServer::Source::kExplicit);
  EXPECT_EQ(Slurp(Options().known_servers_file), pins);
  o.server_key_file = (dir_ / "server.pub").string();
  EXPECT_THAT(ConnectError(o), HasSubstr("given with --server-key; refused"));
}

// security.md ("Which server?"): a keyed client waits, up to its connect
// timeout, for an answer of the server it trusts, so a fake server that
// answers its hello first cannot keep it from its real one. Here the fake
// one answers every hello before the real one even runs.
TEST_F(ServerTrustTest, AFakeServerThatAnswersFirstCannotKeepAKeyedClientFromItsRealOne) {
  MemoryTransport mallory_end(bus_);
  const std::unique_ptr<Server> mallory = KeyedServer(mallory_end, "mallory", false);
  ClientOptions o = Options();
  o.server_key_file = (dir_ / "server.pub").string();
  o.connect_timeout = seconds(10);
  RobotClient client(o);
  std::string error = "Connect has not returned";
  std::thread connect([&] {
    try {
      client.Connect(kRobot);
      error.clear();
    } catch (const std::exception& e) {
      error = e.what();
    }
  });
  const bool refused = WaitUntil([&] { return client.stats().servers_refused >= 1; });
  const auto real_from = std::chrono::steady_clock::now();
  StartServer("server", /*allow_duplicate_robots=*/true);  // it starts second, beside the fake one
  connect.join();
  const double after = std::chrono::duration<double>(std::chrono::steady_clock::now() - real_from).count();
  std::printf(
      "connected %.2f s after the real server started; %llu answers of the fake server refused; %llu "
      "sessions "
      "lost\n",
      after, static_cast<unsigned long long>(client.stats().servers_refused),
      static_cast<unsigned long long>(client.stats().sessions_lost));
  ASSERT_TRUE(refused) << "the fake server answered first";
  ASSERT_EQ(error, "");
  EXPECT_EQ(client.trusted_server().fingerprint, ReadPublicKeyFile(dir_ / "server.pub").key.Fingerprint());
  EXPECT_EQ(client.Goto(0.1, 0, 0).signal, Signal::kSuccess);
  EXPECT_GE(client.stats().servers_refused, 1u);
}

// security.md, Binding: a keyed client's id is one of its key's; given
// another key's id (or a made-up one) it is refused at construction, naming
// the id and its key, before it sends anything.
using KeyedClientIdTest = ServerTrustTest;
TEST_F(KeyedClientIdTest, AKeyedClientGivenAnIdNotOfItsKeyIsRefusedAtConstruction) {
  const PublicKey alice = ReadPublicKeyFile(dir_ / "alice.pub").key;
  const PublicKey mallory = ReadPublicKeyFile(dir_ / "mallory.pub").key;
  const std::size_t published = bus_->published();
  for (const std::int64_t id : {KeyedClientId(mallory, 7), std::int64_t{0x1234}}) {
    ClientOptions o = Options();
    o.client_id = id;
    try {
      RobotClient client(o);
      ADD_FAILURE() << "client id " << id << " was taken by alice's key";
    } catch (const ClientError& e) {
      EXPECT_THAT(e.what(), HasSubstr("client id " + std::to_string(id) + " is not one of key " +
                                      alice.Fingerprint() + "'s"));
    }
  }
  EXPECT_EQ(bus_->published(), published) << "a refused client sends nothing";
  ClientOptions own = Options();
  own.client_id = KeyedClientId(alice, 7);
  EXPECT_EQ(RobotClient(own).client_id(), own.client_id);
  EXPECT_TRUE(ClientIdBelongsTo(RobotClient(Options()).client_id(), alice))
      << "id 0: one of the key's is made";
}

TEST_F(ServerTrustTest, ACorruptOrGroupWritableKnownServersFileIsAClearError) {
  StartServer("server");
  const fs::path pins = Options().known_servers_file;
  fs::create_directories(pins.parent_path());
  std::ofstream(pins) << "pioneer memory:// ed25519:not-a-key\n";
  ::chmod(pins.c_str(), 0600);
  EXPECT_THAT(ConnectError(Options()), HasSubstr(pins.string() + ":1: "));
  std::ofstream(pins) << "# nothing pinned yet\n";
  ::chmod(pins.c_str(), 0664);
  EXPECT_THAT(ConnectError(Options()), HasSubstr("mode 0664 lets group or others write it"));
}

StateSample Forged(std::int64_t sample, int dofs) {
  StateSample s;
  s.robot = kRobot;
  s.server_time = TimePoint(std::chrono::hours(10000));  // far ahead: newer than anything real
  s.sample = sample;
  s.base.x = 42;
  s.base.y = 42;
  s.positions.assign(static_cast<std::size_t>(dofs), 1.234);
  s.velocities.assign(static_cast<std::size_t>(dofs), 0.0);
  s.efforts.assign(static_cast<std::size_t>(dofs), 0.0);
  return s;
}

// The reproducer: 40 of 40 forged samples (base 42, 42; q 1.234) were
// printed by a keyed `robotalk watch`.
TEST_F(ServerTrustTest, AKeyedClientDropsAndCountsStateNotSignedByItsServer) {
  StartServer("server");
  RobotClient client(Options());
  client.Connect(kRobot);
  std::atomic<int> genuine{0}, forged{0};
  std::vector<std::uint8_t> recorded;  // an authentic sample, for a replay
  auto recorder =
      forger_.Subscribe(StateChannel(kRobot), [&](const std::string&, std::span<const std::uint8_t> b) {
        if (recorded.empty()) recorded.assign(b.begin(), b.end());
      });
  client.StartStateStream(milliseconds(10),
                          [&](const StateSample& s) { (s.base.x == 42 ? forged : genuine)++; });
  ASSERT_TRUE(WaitUntil([&] { return genuine >= 3; }));
  forger_.HandleFor(Duration(0));
  ASSERT_FALSE(recorded.empty());
  const KeyPair mallory = ReadSecretKeyFile(dir_ / "mallory");
  for (int i = 0; i < 40; ++i) {
    std::vector<std::uint8_t> bytes = EncodeStateSample(Forged(1000 + i, client.model().num_dofs()));
    forger_.Publish(StateChannel(kRobot), bytes);  // unsigned
    BroadcastSigner(mallory, Nonce{}).Sign(StateChannel(kRobot), bytes);
    forger_.Publish(StateChannel(kRobot), bytes);  // signed by another key
  }
  forger_.Publish(StateChannel(kRobot), recorded);  // an authentic sample, replayed
  EXPECT_TRUE(WaitUntil([&] { return client.stats().broadcasts_refused >= 81; }));
  const int before = genuine;
  EXPECT_TRUE(WaitUntil([&] { return genuine > before + 2; })) << "the real stream goes on";
  EXPECT_EQ(forged, 0);
  client.StopStateStream();
}

// `msg` encoded with its hash (docs/configuration_message.md: FNV-1a 64 of
// the encoding with the hash field zero).
std::vector<std::uint8_t> Encoded(robotalk_msgs::robot_config_t msg) {
  const auto encode = [&] {
    std::vector<std::uint8_t> bytes(static_cast<std::size_t>(msg.getEncodedSize()));
    msg.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
    return bytes;
  };
  msg.header.hash = 0;
  std::uint64_t h = 0xcbf29ce484222325ULL;
  for (std::uint8_t b : encode()) h = (h ^ b) * 0x100000001b3ULL;
  msg.header.hash = static_cast<std::int64_t>(h);
  return encode();
}

// The reproducer: 20,000 forged CONFIG messages grew a keyed `watch` from 6.9 to 99.9 MB.
TEST_F(ServerTrustTest, ACONFIGFloodDoesNotGrowTheClientsStoreInKeyedOrOpenMode) {
  const RobotModel model =
      LoadUrdfFile(std::string(ROBOTALK_MODELS_DIR) + "/pioneer2dx_pantilt.urdf", {.robot_name = kRobot})
          .model;
  const std::vector<std::uint8_t> real = EncodeConfig(model);
  const auto flood = [&](RobotClient& client, int count) {
    const std::size_t before = client.stats().configs_cached;
    for (int batch = 0; batch < count / 1000; ++batch) {
      for (int i = 0; i < 1000; ++i) {
        robotalk_msgs::robot_config_t msg = ToMessage(model);
        msg.links[0].mass = 1.0 + 1e-6 * (batch * 1000 + i);  // a valid description, a new hash each time
        forger_.Publish(ConfigChannel(kRobot), Encoded(msg));
      }
      EXPECT_TRUE(WaitUntil([&] { return client_end_.queued() == 0; }));
    }
    const ClientStats s = client.stats();
    EXPECT_LE(s.configs_cached, before + 4);
    EXPECT_LE(s.config_bytes_cached, (before + 4) * real.size() * 2);
  };
  StartServer("server");
  RobotClient keyed(Options());
  keyed.Connect(kRobot);
  ASSERT_EQ(keyed.stats().configs_cached, 1u);
  flood(keyed, 20000);
  EXPECT_TRUE(WaitUntil([&] { return keyed.stats().broadcasts_refused >= 20000; }));
  EXPECT_EQ(keyed.stats().configs_cached, 1u) << "keyed: nothing unsigned is kept";

  // Open mode trusts the LAN, but still keeps at most 4 descriptions nobody asked for.
  server_.reset();
  ServerOptions o;
  o.precise_timing = false;
  const RobotSpec spec{
      kRobot, "kinematic", std::string(ROBOTALK_MODELS_DIR) + "/pioneer2dx_pantilt.urdf", {}};
  server_ = std::make_unique<Server>(server_end_, o, std::vector<RobotSpec>{spec}, registry_, clock_);
  server_->Start();
  ClientOptions open;
  open.transport = &client_end_;
  RobotClient client(open);
  client.Connect(kRobot);
  flood(client, 2000);
  EXPECT_EQ(client.stats().malformed_packages, 0u) << "the forged descriptions were valid ones";
  EXPECT_EQ(client.model(), model);
}

}  // namespace
}  // namespace robotalk
