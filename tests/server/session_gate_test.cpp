// Issue 9's reproducers against the ServerDaemon's session gate, bytes in and
// out on the in-memory bus: replays across sessions and restarts (open and
// keyed mode), spoofing, forged MACs, sequence poisoning, rights, and the
// COMMAND_STATUS / SERVER_COUNTERS queries.
#include "fake_driver.h"
#include "robotalk/channels.h"
#include "robotalk/memory_transport.h"
#include "robotalk/request.h"
#include "server_daemon.h"
#include "session_test_util.h"
#include "support/test_clients.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <optional>
#include <sstream>

namespace robotalk {
namespace {

using testing::FakeDriver;
using ::testing::HasSubstr;
using testing::PanRobot;
using testing::SayHello;

using testing::kAlice;
constexpr std::int64_t kMallory = 0xBAD;

// One server (replaceable: Restart) with robot "bot" on a bus, and a client's
// view of the bus: replies by id and every reply package's status.
class GateTest : public ::testing::Test {
 protected:
  explicit GateTest(SessionTableOptions gate = {}) : gate_(std::move(gate)) {
    Restart();
    sub_ = client_.Subscribe("ROBOTALK/bot/REPLY/.*",
                             [this](const std::string&, std::span<const std::uint8_t> b) {
                               ReplyBatch batch = DecodeReplyBatch(b);
                               batches_.push_back(batch);
                               for (Reply& r : batch.replies) replies_[r.id] = r;
                             });
  }

  void Restart() {
    server_.reset();
    robot_.reset();
    auto driver = std::make_unique<FakeDriver>(PanRobot());
    fake_ = driver.get();
    robot_ = std::make_unique<RobotDaemon>("bot", "fake", std::move(driver), clock_);
    server_ = std::make_unique<ServerDaemon>(transport_, clock_, ServerDaemonOptions{.sessions = gate_});
    server_->AddRobot(*robot_, robot_options_);
  }

  void Step() {
    server_->RunOnce(Duration(0));
    robot_->RunOnce(clock_.Now());
    server_->RunOnce(Duration(0));
    client_.HandleFor(Duration(0));
  }

  std::int64_t OpenSession(std::int64_t client_id) {
    return SayHello(client_, "bot", client_id, [this] { Step(); }).session_id;
  }

  static Request Move(std::int64_t client, std::int64_t session, std::int64_t sequence, CommandId id) {
    Request r{.client_id = client, .session_id = session, .sequence = sequence};
    r.commands.push_back(Command{id, CommandType::kJointSetPoint, std::nullopt, "pan", {0.5}});
    return r;
  }

  std::vector<std::uint8_t> Publish(const std::vector<std::uint8_t>& bytes) {
    client_.Publish(RequestChannel("bot"), bytes);
    Step();
    return bytes;
  }

  std::size_t Executed() const { return fake_->calls.size(); }

  SessionTableOptions gate_;
  SessionOptions robot_options_;  // the robot's (Restart applies a change)
  ManualClock clock_;
  std::shared_ptr<MemoryBus> bus_ = std::make_shared<MemoryBus>();
  MemoryTransport transport_{bus_};
  MemoryTransport client_{bus_};
  FakeDriver* fake_ = nullptr;
  std::unique_ptr<RobotDaemon> robot_;
  std::unique_ptr<ServerDaemon> server_;
  std::unique_ptr<Subscription> sub_;
  std::vector<ReplyBatch> batches_;
  std::map<CommandId, Reply> replies_;
};

TEST_F(GateTest, APackageOutsideAnySessionIsAnsweredSessionUnknownAndNotExecuted) {
  Publish(EncodeRequest(Move(kAlice, 0, 1, 1)));
  Publish(EncodeRequest(Move(kAlice, 123456789, 2, 2)));  // a made-up session
  EXPECT_EQ(Executed(), 0u);
  ASSERT_EQ(batches_.size(), 2u);
  for (const ReplyBatch& b : batches_) {
    EXPECT_EQ(b.session_status, SessionStatus::kUnknown);
    EXPECT_TRUE(b.replies.empty());
  }
  EXPECT_EQ(server_->sessions().counters().unknown_session, 2u);
}

TEST_F(GateTest, ARecordedSessionReplayedOnARestartedServerDoesNotRun) {
  // Issue 9: after kill -9 and a restart, a recorded GOTO / set-points ran again.
  const std::int64_t session = OpenSession(kAlice);
  const auto recorded = Publish(EncodeRequest(Move(kAlice, session, 1, 1)));
  ASSERT_EQ(Executed(), 1u);
  Restart();          // the new instance has its own sessions
  Publish(recorded);  // what lcm-logplayer would send
  EXPECT_EQ(Executed(), 0u) << "a package of a session this instance did not open never runs";
  EXPECT_EQ(batches_.back().session_status, SessionStatus::kUnknown);
  EXPECT_NE(batches_.back().server_id, batches_.front().server_id) << "replies name the new instance";
}

TEST_F(GateTest, APackageOfAnExpiredSessionIsNotExecutedAgain) {
  // Issue 9: after the session expired, all 7 commands of a recorded sequence ran again.
  const std::int64_t session = OpenSession(kAlice);
  const auto recorded = Publish(EncodeRequest(Move(kAlice, session, 1, 1)));
  ASSERT_EQ(Executed(), 1u);
  clock_.Advance(std::chrono::seconds(3));  // past the 2 s session timeout
  Step();
  const std::size_t after_expiry = Executed();
  Publish(recorded);
  EXPECT_EQ(Executed(), after_expiry);
  EXPECT_EQ(batches_.back().session_status, SessionStatus::kUnknown);
  // The client says hello again and goes on.
  const std::int64_t fresh = OpenSession(kAlice);
  Publish(EncodeRequest(Move(kAlice, fresh, 2, 2)));
  EXPECT_EQ(replies_.at(2).signal, Signal::kSuccess);
}

// Review of issue 20: with one window, a package numbered 0 in a live open
// session was answered "seen before" instead of the header error.
TEST_F(GateTest, APackageNumberedZeroInASessionIsAnsweredWithTheHeaderError) {
  const std::int64_t session = OpenSession(kAlice);
  Publish(EncodeRequest(Move(kAlice, session, 1, 1)));
  ASSERT_EQ(replies_.at(1).signal, Signal::kSuccess);
  Publish(EncodeRequest(Move(kAlice, session, 0, 2)));
  ASSERT_EQ(replies_.count(2), 1u);
  EXPECT_EQ(replies_.at(2).signal, Signal::kError);
  EXPECT_THAT(replies_.at(2).message, HasSubstr("not positive"));
  EXPECT_EQ(Executed(), 1u);
}

TEST_F(GateTest, AnotherClientsSessionIdIsRefused) {
  const std::int64_t session = OpenSession(kAlice);
  Publish(EncodeRequest(Move(kMallory, session, 1, 1)));
  EXPECT_EQ(Executed(), 0u);
  EXPECT_EQ(server_->sessions().counters().wrong_client, 1u);
}

TEST_F(GateTest, CommandStatusTellsWhatBecameOfACommand) {
  const std::int64_t session = OpenSession(kAlice);
  Publish(EncodeRequest(Move(kAlice, session, 1, 7)));
  Request ask{.client_id = kAlice, .session_id = session, .sequence = 2};
  ask.queries.push_back(Query{.id = 8, .type = QueryType::kCommandStatus, .about = 7});
  ask.queries.push_back(Query{.id = 9, .type = QueryType::kCommandStatus, .about = 99});
  Publish(EncodeRequest(ask));
  EXPECT_EQ(replies_.at(8).signal, Signal::kSuccess) << replies_.at(8).message;
  EXPECT_EQ(replies_.at(9).signal, Signal::kNa);
  EXPECT_THAT(replies_.at(9).message, HasSubstr("never received in this session"));
}

TEST_F(GateTest, ServerCountersNameAndCountRefusals) {
  Publish(EncodeRequest(Move(kAlice, 42, 1, 1)));
  const std::int64_t session = OpenSession(kAlice);
  Request ask{.client_id = kAlice, .session_id = session, .sequence = 2};
  ask.queries.push_back(Query{.id = 5, .type = QueryType::kServerCounters});
  Publish(EncodeRequest(ask));
  const Reply& r = replies_.at(5);
  ASSERT_EQ(r.signal, Signal::kSuccess);
  EXPECT_THAT(r.message, HasSubstr("unknown_session"));
  std::istringstream names(r.message);
  std::string name;
  for (std::size_t i = 0; names >> name; ++i) {
    ASSERT_LT(i, r.values.size());
    if (name == "unknown_session" || name == "hellos") {
      EXPECT_EQ(r.values[i], 1.0) << name;
    }
  }
}

// A long reply batch leaves in parts (each under LCM's 64 KB); the ack is
// the copy's, so only the first part carries it: a client counting acks
// against copies sent (LinkLoss) would otherwise take the parts for copies
// and miss a lost one.
TEST_F(GateTest, ALongReplyBatchSplitInPartsAcknowledgesItsPackageOnce) {
  const std::int64_t session = OpenSession(kAlice);
  Request r{.client_id = kAlice, .session_id = session, .sequence = 1};
  for (CommandId id = 1; id <= 300; ++id) {  // each answered ERROR naming its 200-byte unknown joint
    r.commands.push_back(
        Command{id, CommandType::kJointSetPoint, std::nullopt, std::string(200, 'j'), {0.1}});
  }
  const std::size_t before = batches_.size();
  Publish(EncodeRequest(r));
  std::size_t parts = 0, acks = 0, replies = 0;
  for (std::size_t b = before; b < batches_.size(); ++b) {
    ++parts;
    acks += batches_[b].ack_sequence == 1;
    replies += batches_[b].replies.size();
  }
  EXPECT_GE(parts, 2u) << "the batch is long enough to be split";
  EXPECT_EQ(replies, 300u) << "every reply sent";
  EXPECT_EQ(acks, 1u) << "one ack for one copy received";
  EXPECT_EQ(batches_[before].ack_sequence, 1) << "in the first part";
}

// Issue 23 item 2: a copy of a package (a retransmission whose answer was
// lost, a duplicated datagram) is answered by the gate from the session
// table and never reaches RobotSessions::Handle; the session's link health
// counts it all the same.
TEST_F(GateTest, TheLinkHealthCountsTheCopiesTheGateAnswers) {
  const std::int64_t session = OpenSession(kAlice);
  const auto move = Publish(EncodeRequest(Move(kAlice, session, 1, 1)));
  Publish(move);
  Publish(move);
  EXPECT_EQ(Executed(), 1u);
  Request ask{.client_id = kAlice, .session_id = session, .sequence = 2};
  ask.queries.push_back(Query{.id = 5, .type = QueryType::kServerCounters});
  Publish(EncodeRequest(ask));
  const Reply& r = replies_.at(5);
  ASSERT_EQ(r.signal, Signal::kSuccess);
  std::istringstream names(r.message);
  std::string name;
  std::optional<double> duplicates;
  for (std::size_t i = 0; names >> name && i < r.values.size(); ++i)
    if (name == "link_duplicates") duplicates = r.values[i];
  ASSERT_TRUE(duplicates) << r.message;
  EXPECT_EQ(*duplicates, 2.0);
}

TEST_F(GateTest, InOpenModeAPanicOutsideAnySessionStillStopsTheRobot) {
  Request panic{.client_id = kAlice, .sequence = 1, .panic = true};
  Publish(EncodeRequest(panic));
  EXPECT_TRUE(robot_->in_panic());
  // Issue 19 item 2: the answer says the panic was taken, explicitly; the
  // SESSION_UNKNOWN status alone no longer counts as its acknowledgement.
  ASSERT_FALSE(batches_.empty());
  EXPECT_EQ(batches_.back().session_status, SessionStatus::kUnknown);
  EXPECT_EQ(batches_.back().panic, PanicStatus::kTaken);
}

TEST_F(GateTest, APanicInASessionIsAnsweredTakenAndAPlainPackageNone) {
  const std::int64_t session = OpenSession(kAlice);
  Publish(EncodeRequest(Move(kAlice, session, 1, 1)));
  EXPECT_EQ(batches_.back().panic, PanicStatus::kNone);
  const auto bytes = Publish(
      EncodeRequest(Request{.client_id = kAlice, .session_id = session, .sequence = 2, .panic = true}));
  EXPECT_TRUE(robot_->in_panic());
  EXPECT_EQ(batches_.back().panic, PanicStatus::kTaken);
  Publish(bytes);  // a retransmission is answered as the first copy was
  EXPECT_EQ(batches_.back().panic, PanicStatus::kTaken);
}

TEST_F(GateTest, APanicInAPackageWithABadHeaderIsAnsweredRefusedWithTheReason) {
  const std::int64_t session = OpenSession(kAlice);
  Request panic{.client_id = kAlice, .session_id = session, .sequence = 1, .panic = true};
  panic.queries.push_back(Query{.id = 1, .type = QueryType::kBasePose});
  panic.commands.push_back(Command{2, CommandType::kStop, std::nullopt, "", {}});  // mixed: refused
  Publish(EncodeRequest(panic));
  EXPECT_FALSE(robot_->in_panic());
  EXPECT_EQ(batches_.back().panic, PanicStatus::kRefused);
  EXPECT_FALSE(batches_.back().panic_refusal.empty());
}

// protocol.md, Protocol versions: the server refuses a package or hello of
// another version naming both versions. `bytes`' version (an int16 after the
// 8-byte fingerprint, the first field of hello_t and of package_header_t)
// becomes `version`; returns the version it had.
int SetProtocolVersion(std::vector<std::uint8_t>& bytes, int version) {
  const int had = bytes.at(8) << 8 | bytes.at(9);
  bytes[8] = static_cast<std::uint8_t>(version >> 8);
  bytes[9] = static_cast<std::uint8_t>(version & 0xff);
  return had;
}

TEST_F(GateTest, AHelloOfAnotherProtocolVersionIsRefusedNamingBothVersions) {
  Hello hello;
  hello.body.client_id = kAlice;
  hello.body.client_nonce = RandomNonce();
  std::vector<std::uint8_t> bytes = EncodeHello(hello);
  const int ours = SetProtocolVersion(bytes, 3);
  ASSERT_NE(ours, 3);
  bool answered = false;
  auto sub = client_.Subscribe(HelloAnswerChannel("bot", kAlice),
                               [&](const std::string&, std::span<const std::uint8_t>) { answered = true; });
  ::testing::internal::CaptureStderr();
  client_.Publish(HelloChannel("bot"), bytes);
  Step();
  const std::string log = ::testing::internal::GetCapturedStderr();
  EXPECT_FALSE(answered) << "no session for a hello of another version";
  EXPECT_EQ(server_->malformed(), 1u);
  EXPECT_THAT(log, HasSubstr("protocol version 3 is not supported"));
  EXPECT_THAT(log, HasSubstr("speaks " + std::to_string(ours))) << log;
  EXPECT_NE(OpenSession(kAlice), 0) << "a hello of this version is answered";
}

TEST_F(GateTest, APackageOfAnotherProtocolVersionIsRefusedNamingBothVersions) {
  const std::int64_t session = OpenSession(kAlice);
  std::vector<std::uint8_t> bytes = EncodeRequest(Move(kAlice, session, 1, 1));
  const int ours = SetProtocolVersion(bytes, 3);
  ::testing::internal::CaptureStderr();
  Publish(bytes);
  const std::string log = ::testing::internal::GetCapturedStderr();
  EXPECT_EQ(Executed(), 0u);
  ASSERT_EQ(replies_.count(1), 1u);
  EXPECT_EQ(replies_.at(1).signal, Signal::kError);
  for (const std::string& text : {replies_.at(1).message, log}) {
    EXPECT_THAT(text, HasSubstr("protocol version 3 is not supported"));
    EXPECT_THAT(text, HasSubstr("speaks " + std::to_string(ours))) << text;
  }
  EXPECT_THAT(log, HasSubstr("refused package from client"));
}

// --- keyed mode ------------------------------------------------------------

KeyPair Key(std::uint8_t seed) {
  std::array<std::uint8_t, SecretKey::kSeedBytes> bytes{};
  bytes.fill(seed);
  return KeyPair::FromSeed(bytes);
}

// Keyed mode: a client id of `key` (issue 19 item 6).
std::int64_t Id(const KeyPair& key, std::int64_t low) {
  return KeyedClientId(key.public_key, static_cast<std::uint32_t>(low));
}

SessionTableOptions Keyed() {
  SessionTableOptions gate;
  gate.identity = std::make_shared<const KeyPair>(Key(1));
  const std::string list = Key(2).public_key.ToString() + " alice *=all\n" + Key(3).public_key.ToString() +
                           " monitor *=query,panic\n" + Key(4).public_key.ToString() + " viewer *=query\n";
  gate.access = std::make_shared<const AccessList>(AccessList::Parse(list, "test"));
  return gate;
}

class KeyedGateTest : public GateTest {
 protected:
  KeyedGateTest() : GateTest(Keyed()) {}

  struct Client {
    std::int64_t id = 0;
    SessionKeys keys;
    std::int64_t sequence = 0;
  };
  // A handshake as the client library does it; nullopt when refused.
  std::optional<Client> Handshake(const KeyPair& key, std::int64_t client_id,
                                  std::string* refusal = nullptr) {
    ClientHandshake handshake(key, client_id);
    Hello hello{.keyed = true, .body = handshake.hello()};
    const HelloAnswer answer = SayHello(
        client_, "bot", client_id, [this] { Step(); }, hello);
    if (answer.session_id == 0) {
      if (refusal) *refusal = answer.refusal;
      return std::nullopt;
    }
    return Client{client_id, handshake.Finish(answer.body), 0};
  }
  std::vector<std::uint8_t> Sealed(Client& c, Request r) {
    r.client_id = c.id;
    r.session_id = c.keys.session_id;
    r.sequence = ++c.sequence;
    std::vector<std::uint8_t> bytes = EncodeRequest(r);
    WriteMacField(bytes, ComputeMac(c.keys.client_to_server, c.keys.session_id, MacCoveredBytes(bytes)));
    return bytes;
  }
  // Publishes `c`'s sealed package `r` with the panic flag; returns its bytes.
  std::vector<std::uint8_t> PublishPanic(Client& c, Request r = {}) {
    r.panic = true;
    return Publish(Sealed(c, std::move(r)));
  }
  static Request Commands(CommandType type, CommandId id, std::vector<double> values = {}) {
    Request r;
    r.commands.push_back(
        Command{id, type, std::nullopt, type == CommandType::kJointSetPoint ? "pan" : "", values});
    return r;
  }
};

TEST_F(KeyedGateTest, RefusesAnOpenHelloAndAnUnlistedKey) {
  const HelloAnswer open = SayHello(client_, "bot", kAlice, [this] { Step(); });
  EXPECT_EQ(open.session_id, 0);
  EXPECT_THAT(open.refusal, HasSubstr("keyed mode"));
  std::string why;
  EXPECT_FALSE(Handshake(Key(9), Id(Key(9), kMallory), &why));
  EXPECT_THAT(why, HasSubstr("not in the access list"));
}

TEST_F(KeyedGateTest, ExecutesSealedPackagesOnceAndDropsForgedOnes) {
  auto alice = Handshake(Key(2), Id(Key(2), kAlice));
  ASSERT_TRUE(alice);
  const auto bytes = Publish(Sealed(*alice, Commands(CommandType::kJointSetPoint, 1, {0.5})));
  EXPECT_EQ(replies_.at(1).signal, Signal::kSuccess);
  EXPECT_TRUE(batches_.back().mac != Mac{}) << "replies are sealed";
  Publish(bytes);  // a replay inside the session: a duplicate
  EXPECT_EQ(Executed(), 1u);
  auto forged = Sealed(*alice, Commands(CommandType::kJointSetPoint, 2, {-2.0}));
  forged[forged.size() - 1] ^= 1;
  Publish(forged);
  EXPECT_EQ(Executed(), 1u);
  EXPECT_EQ(server_->sessions().counters().forged, 1u);
  EXPECT_EQ(replies_.count(2), 0u) << "a forged package gets no answer";
}

TEST_F(KeyedGateTest, ASpoofedClientIdCannotMoveTheRobotOrPoisonTheSequence) {
  // Issue 9: 40 sequences under the victim's id, and one heartbeat with
  // sequence INT64_MAX, took over the victim's session.
  auto alice = Handshake(Key(2), Id(Key(2), kAlice));
  ASSERT_TRUE(alice);
  Publish(Sealed(*alice, Commands(CommandType::kJointSetPoint, 1, {0.5})));
  std::string why;
  EXPECT_FALSE(Handshake(Key(3), alice->id, &why)) << "another key may not take Alice's client id";
  Request poison{.client_id = alice->id, .session_id = alice->keys.session_id, .sequence = INT64_MAX};
  Publish(EncodeRequest(poison));  // no key, zero MAC
  Request spoof = Move(alice->id, alice->keys.session_id, 2, 2);
  spoof.commands[0].values = {-2.0};
  Publish(EncodeRequest(spoof));
  EXPECT_EQ(Executed(), 1u);
  Publish(Sealed(*alice, Commands(CommandType::kJointSetPoint, 3, {0.25})));
  EXPECT_EQ(replies_.at(3).signal, Signal::kSuccess) << "Alice's own next package still runs";
  EXPECT_EQ(Executed(), 2u);
}

TEST_F(KeyedGateTest, ASessionRecordedBeforeARestartNeverRunsAgain) {
  auto alice = Handshake(Key(2), Id(Key(2), kAlice));
  ASSERT_TRUE(alice);
  const auto recorded = Publish(Sealed(*alice, Commands(CommandType::kJointSetPoint, 1, {0.5})));
  Restart();
  Publish(recorded);
  EXPECT_EQ(Executed(), 0u);
  EXPECT_EQ(batches_.back().session_status, SessionStatus::kUnknown);
}

TEST_F(KeyedGateTest, RightsAreCheckedPerPackage) {
  // Issue 9: a random client id reset another client's panic and stopped its GOTO.
  auto alice = Handshake(Key(2), Id(Key(2), kAlice));
  auto monitor = Handshake(Key(3), Id(Key(3), kMallory));
  ASSERT_TRUE(alice && monitor);
  PublishPanic(*monitor);
  EXPECT_TRUE(robot_->in_panic()) << "monitor may raise a panic";
  Publish(Sealed(*monitor, Commands(CommandType::kPanicReset, 10)));
  EXPECT_TRUE(robot_->in_panic()) << "but not reset it";
  EXPECT_EQ(replies_.at(10).signal, Signal::kError);
  EXPECT_THAT(replies_.at(10).message, HasSubstr("monitor"));
  Publish(Sealed(*monitor, Commands(CommandType::kStop, 11)));
  EXPECT_EQ(replies_.at(11).signal, Signal::kError) << "nor stop the robot";
  Publish(Sealed(*alice, Commands(CommandType::kPanicReset, 12)));
  EXPECT_FALSE(robot_->in_panic());
  EXPECT_EQ(server_->sessions().counters().rights_refused, 2u);
}

// Review of issue 20: a package refused because the robot serves its
// --max-sessions-per-robot clients already was not recorded in the session's
// window, so its captured bytes, replayed, raised the panic again after the
// reset and kept the session alive.
TEST_F(KeyedGateTest, APanicRefusedByAFullRobotIsNotRaisedAgainByItsReplay) {
  robot_options_.max_sessions_per_robot = 1;
  Restart();
  auto alice = Handshake(Key(2), Id(Key(2), kAlice));
  auto monitor = Handshake(Key(3), Id(Key(3), kMallory));
  ASSERT_TRUE(alice && monitor);
  Publish(Sealed(*alice, Commands(CommandType::kJointSetPoint, 1, {0.5})));  // Alice fills the robot
  ASSERT_EQ(replies_.at(1).signal, Signal::kSuccess);
  const auto captured = PublishPanic(*monitor);
  EXPECT_TRUE(robot_->in_panic()) << "a panic is taken from a full robot's refused client";
  Publish(Sealed(*alice, Commands(CommandType::kPanicReset, 3)));
  ASSERT_FALSE(robot_->in_panic());
  for (int i = 0; i < 3; ++i) {
    clock_.Advance(std::chrono::seconds(1));
    Publish(captured);  // the same bytes, again
    EXPECT_FALSE(robot_->in_panic()) << "replay " << i << " raised the panic again";
  }
  Publish(Sealed(*monitor, Request{}));  // a heartbeat
  EXPECT_EQ(batches_.back().session_status, SessionStatus::kUnknown)
      << "replays kept the session alive past --session-timeout";
}

TEST_F(KeyedGateTest, ASessionWhosePackagesAreAllRefusedForRightsIsClosedWhenIdle) {
  auto monitor = Handshake(Key(3), Id(Key(3), kMallory));
  ASSERT_TRUE(monitor);
  Publish(Sealed(*monitor, Commands(CommandType::kJointSetPoint, 1, {0.5})));
  EXPECT_EQ(replies_.at(1).signal, Signal::kError);
  clock_.Advance(std::chrono::seconds(61));
  Step();  // the watchdog
  Publish(Sealed(*monitor, Commands(CommandType::kJointSetPoint, 2, {0.5})));
  EXPECT_EQ(batches_.back().session_status, SessionStatus::kUnknown) << "closed, not kept for ever";
  EXPECT_EQ(server_->sessions().session_count(), 0u);
}

TEST_F(KeyedGateTest, ASessionWhosePackagesAreAllRefusedForRightsLastsWhileItSends) {
  auto monitor = Handshake(Key(3), Id(Key(3), kMallory));
  ASSERT_TRUE(monitor);
  for (CommandId id = 1; id <= 5; ++id) {
    Publish(Sealed(*monitor, Commands(CommandType::kJointSetPoint, id, {0.5})));
    ASSERT_EQ(batches_.back().session_status, SessionStatus::kOk) << "package " << id;
    EXPECT_EQ(replies_.at(id).signal, Signal::kError);
    clock_.Advance(std::chrono::milliseconds(1500));  // under the 2 s session timeout each time
    Step();                                           // the watchdog
  }
  EXPECT_EQ(server_->sessions().session_count(), 1u);
}

TEST_F(KeyedGateTest, APanicRefusedForRightsIsAnsweredRefusedWithTheReasonAndDoesNothing) {
  // Issue 19 item 2: a query-only key's panic was reported as acknowledged
  // while the robot went on; another client's motion completed.
  auto viewer = Handshake(Key(4), Id(Key(4), kMallory));
  ASSERT_TRUE(viewer);
  const auto bytes = PublishPanic(*viewer);
  EXPECT_FALSE(robot_->in_panic());
  ASSERT_FALSE(batches_.empty());
  EXPECT_EQ(batches_.back().session_status, SessionStatus::kOk);
  EXPECT_EQ(batches_.back().panic, PanicStatus::kRefused);
  EXPECT_THAT(batches_.back().panic_refusal, HasSubstr("may not panic robot 'bot'"));
  EXPECT_TRUE(batches_.back().mac != Mac{}) << "the refusal is sealed: the client can believe it";
  Publish(bytes);  // its retransmission: refused the same way
  EXPECT_EQ(batches_.back().panic, PanicStatus::kRefused);
  EXPECT_FALSE(robot_->in_panic());
}

TEST_F(KeyedGateTest, APanicWithTheRightIsAnsweredTaken) {
  auto monitor = Handshake(Key(3), Id(Key(3), kMallory));
  ASSERT_TRUE(monitor);
  const auto bytes = PublishPanic(*monitor);
  EXPECT_TRUE(robot_->in_panic());
  EXPECT_EQ(batches_.back().panic, PanicStatus::kTaken);
  Publish(bytes);
  EXPECT_EQ(batches_.back().panic, PanicStatus::kTaken) << "a retransmission: taken when first seen";
}

TEST_F(KeyedGateTest, ARetransmittedPanicWithABadHeaderIsAnsweredRefusedAgain) {
  auto monitor = Handshake(Key(3), Id(Key(3), kMallory));
  ASSERT_TRUE(monitor);
  Request mixed;  // queries and commands: refused
  mixed.queries.push_back(Query{.id = 1, .type = QueryType::kBasePose});
  mixed.commands.push_back(Command{2, CommandType::kStop, std::nullopt, "", {}});
  const auto bytes = PublishPanic(*monitor, mixed);
  EXPECT_EQ(batches_.back().panic, PanicStatus::kRefused);
  Publish(bytes);  // the replay window's duplicate path
  EXPECT_EQ(batches_.back().panic, PanicStatus::kRefused);
  EXPECT_FALSE(batches_.back().panic_refusal.empty());
  EXPECT_FALSE(robot_->in_panic());
}

TEST_F(KeyedGateTest, APanicOutsideAnySessionIsAnsweredRefusedNotTaken) {
  Request panic{.client_id = kAlice, .session_id = 77, .sequence = 1, .panic = true};
  Publish(EncodeRequest(panic));
  EXPECT_FALSE(robot_->in_panic());
  ASSERT_FALSE(batches_.empty());
  EXPECT_EQ(batches_.back().session_status, SessionStatus::kUnknown);
  EXPECT_EQ(batches_.back().panic, PanicStatus::kRefused);
  EXPECT_THAT(batches_.back().panic_refusal, HasSubstr("say hello"));
}

// The tenth session's known gap: a keyed server signs every SESSION_UNKNOWN
// it answers (a fake server's cannot end a keyed client's sessions), one
// Ed25519 signature each (19 µs of the thread a package against 3 µs open), so
// a flood of packages naming made-up sessions bought that much of the
// ServerDaemon thread per datagram. Now the signed answers have a budget per
// second (panics their own); the rest are counted and not answered, and a
// client's live session is served as before.
TEST_F(KeyedGateTest,
       AFloodNamingMadeUpSessionsIsAnsweredWithinTheSignedAnswerBudgetAndLiveSessionsAreServed) {
  auto alice = Handshake(Key(2), Id(Key(2), kAlice));
  ASSERT_TRUE(alice);
  const std::size_t before = batches_.size();
  constexpr int kFlood = 2000;
  for (int i = 0; i < kFlood; ++i) {
    Publish(EncodeRequest(Move(kMallory + i, 1'000'000 + i, 1, 1)));  // made-up clients and sessions
  }
  const auto unknown_answers = [&](std::size_t from) {
    std::size_t n = 0;
    for (std::size_t b = from; b < batches_.size(); ++b)
      n += batches_[b].session_status == SessionStatus::kUnknown;
    return n;
  };
  const std::size_t answered = unknown_answers(before);
  EXPECT_EQ(answered, static_cast<std::size_t>(ServerDaemonOptions{}.unknown_answers_per_second))
      << "at most the budget of signed answers within one second";
  EXPECT_EQ(server_->sessions().counters().unknown_session, static_cast<std::uint64_t>(kFlood));
  EXPECT_EQ(server_->unknown_unanswered(), kFlood - answered) << "the rest counted";

  // The live session is served during the flood.
  Publish(Sealed(*alice, Commands(CommandType::kJointSetPoint, 1, {0.5})));
  EXPECT_EQ(replies_.at(1).signal, Signal::kSuccess);
  // A panic outside any session keeps its own budget: its refusal still comes.
  Request panic{.client_id = kAlice, .session_id = 77, .sequence = 1, .panic = true};
  Publish(EncodeRequest(panic));
  EXPECT_EQ(batches_.back().panic, PanicStatus::kRefused);
  EXPECT_THAT(batches_.back().panic_refusal, HasSubstr("say hello"));
  // A second later the budget is back: a client whose server restarted learns it.
  clock_.Advance(std::chrono::seconds(1));
  const std::size_t later = batches_.size();
  Publish(EncodeRequest(Move(kAlice + 1, 5, 9, 9)));
  EXPECT_EQ(unknown_answers(later), 1u);
}

// Review 12: the panic answers' budget (1,000 signed refusals a second)
// serves packages naming no session only. A flood of panic packages naming
// made-up sessions, past that budget, never delays a live session's panic:
// it is admitted by its session's MAC and taken (answered TAKEN), the robot
// in panic. (A keyed client whose server restarted has no live session: see
// safety.md's Known gaps.)
TEST_F(KeyedGateTest, AFloodOfPanicsNamingMadeUpSessionsNeverKeepsALiveSessionsPanicFromBeingTaken) {
  auto alice = Handshake(Key(2), Id(Key(2), kAlice));
  ASSERT_TRUE(alice);
  constexpr int kFlood = 3000;
  for (int i = 0; i < kFlood; ++i) {
    Publish(EncodeRequest(
        Request{.client_id = kMallory + i, .session_id = 1'000'000 + i, .sequence = 1, .panic = true}));
  }
  ASSERT_GT(server_->unknown_unanswered(), 0u) << "the flood went past the panic answers' budget";
  ASSERT_FALSE(robot_->in_panic()) << "a panic outside any session is refused in keyed mode";
  PublishPanic(*alice);
  EXPECT_EQ(batches_.back().panic, PanicStatus::kTaken);
  EXPECT_EQ(batches_.back().client_id, alice->id);
  EXPECT_TRUE(robot_->in_panic());
}

TEST_F(GateTest, ARepeatedHelloGetsTheSameSessionAndPendingSessionsAreBoundedPerClientId) {
  Hello hello;
  hello.body.client_id = kAlice;
  hello.body.client_nonce = RandomNonce();
  const auto step = [this] { Step(); };
  const std::int64_t first = SayHello(client_, "bot", kAlice, step, hello).session_id;
  EXPECT_EQ(SayHello(client_, "bot", kAlice, step, hello).session_id, first) << "its answer was lost: again";
  EXPECT_EQ(server_->sessions().session_count(), 1u);
  std::int64_t last = 0;
  for (int i = 0; i < 5; ++i) last = OpenSession(kAlice);  // new hellos of one source, never used
  EXPECT_EQ(server_->sessions().session_count(), 2u) << "pending sessions per client id are bounded";
  Publish(EncodeRequest(Move(kAlice, last, 1, 1)));
  EXPECT_EQ(replies_.at(1).signal, Signal::kSuccess);
}

class SmallGateTest : public GateTest {
 protected:
  SmallGateTest() : GateTest(SessionTableOptions{.max_sessions = 4}) {}
};

TEST_F(SmallGateTest, AFloodOfHellosNeverLocksANewClientOutOrDropsALiveSession) {
  const std::int64_t live = OpenSession(kAlice);
  Publish(EncodeRequest(Move(kAlice, live, 1, 1)));
  for (std::int64_t id = 1; id <= 20; ++id) OpenSession(1000 + id);  // never used
  const std::int64_t late = OpenSession(kMallory);
  ASSERT_NE(late, 0) << "the oldest pending session made room";
  Publish(EncodeRequest(Move(kMallory, late, 1, 2)));
  EXPECT_EQ(replies_.at(2).signal, Signal::kSuccess);
  Publish(EncodeRequest(Move(kAlice, live, 2, 3)));
  EXPECT_EQ(replies_.at(3).signal, Signal::kSuccess) << "a live session is never dropped for a hello";
  EXPECT_LE(server_->sessions().session_count(), 4u);
}

TEST_F(KeyedGateTest, OneHelloReplayedThousandsOfTimesLeavesRoomForEveryOtherKey) {
  // Issue 19 item 5: "the server has 1024 sessions open already" for everyone.
  const ClientHandshake recorded(Key(2), Id(Key(2), kAlice));
  const auto bytes = EncodeHello(Hello{.keyed = true, .body = recorded.hello()});
  for (int i = 0; i < 3000; ++i) client_.Publish(HelloChannel("bot"), bytes);
  Step();
  EXPECT_EQ(server_->sessions().session_count(), 1u) << "one hello, one pending session";
  EXPECT_EQ(server_->sessions().counters().hellos_refused, 0u)
      << "its copies are answered again, not refused";
  EXPECT_EQ(server_->sessions().counters().hello_repeats, 2999u) << "and counted (SERVER_COUNTERS)";
  for (std::uint8_t key : {3, 4}) {
    auto other = Handshake(Key(key), Id(Key(key), kMallory));
    ASSERT_TRUE(other) << "key " << int{key};
    Publish(Sealed(*other, Commands(CommandType::kStop, 10 + key)));
    EXPECT_EQ(batches_.back().session_status, SessionStatus::kOk);
  }
}

TEST_F(KeyedGateTest, PendingSessionsPerKeyAreBoundedAndTheGateForgetsTheDroppedOnes) {
  for (std::int64_t id = 1; id <= 6; ++id) ASSERT_TRUE(Handshake(Key(2), Id(Key(2), id)));  // never used
  EXPECT_EQ(server_->sessions().session_count(), 4u) << "4 pending per key, as the authenticator keeps them";
  auto monitor = Handshake(Key(3), Id(Key(3), 1));
  ASSERT_TRUE(monitor);
  Publish(Sealed(*monitor, Commands(CommandType::kStop, 1)));
  EXPECT_EQ(replies_.at(1).signal, Signal::kError) << "monitor may not STOP; but it has a session";
}

}  // namespace
}  // namespace robotalk
