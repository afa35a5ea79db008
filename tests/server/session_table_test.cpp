// The server's session table in keyed mode, driven directly (no bus): hello
// repeats and replays, key bindings, the bounds, replacement of a live session
// and expiry (session_table.h). The same table behind a ServerDaemon:
// session_gate_test.cpp.
#include "session_table.h"

#include "robotalk/request.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace robotalk {
namespace {

using ::testing::HasSubstr;
using V = SessionTable::Verdict;

KeyPair Identity(std::uint8_t v) {
  std::array<std::uint8_t, 32> seed{};
  seed.fill(v);
  return KeyPair::FromSeed(seed);
}
std::int64_t Id(const KeyPair& key, std::uint32_t n) { return KeyedClientId(key.public_key, n); }

// A client's side of one session: seals packages as the wire says.
struct ClientSide {
  SessionKeys keys;
  std::int64_t client_id = 0;
};

class SessionTableTest : public ::testing::Test {
 protected:
  explicit SessionTableTest(SessionTableOptions options = {}) {
    options.identity = std::make_shared<const KeyPair>(Identity(100));
    options.access = std::make_shared<const AccessList>(AccessList::Parse(
        alice_.public_key.ToString() + " alice *=all\n" + bob_.public_key.ToString() + " bob *=all\n",
        "clients"));
    options_ = options;
    Restart();
  }
  void Restart() {
    table_ = std::make_unique<SessionTable>(1, options_);
    robot_ = table_->AddRobot("bot", {});
  }

  HelloAnswer Hello(const ClientHello& hello) {
    return table_->Answer(robot_, robotalk::Hello{.keyed = true, .body = hello}, clock_.Now());
  }
  ClientSide Connect(const KeyPair& who, std::int64_t client_id, std::string* refusal = nullptr) {
    const ClientHandshake hs(who, client_id);
    const HelloAnswer answer = Hello(hs.hello());
    if (answer.session_id == 0) {
      if (refusal) *refusal = answer.refusal;
      return {};
    }
    return {hs.Finish(answer.body), client_id};
  }
  // One package of `c` with `sequence`, as the ServerDaemon admits it (and
  // RobotSessions records its sequence when it runs).
  V Send(const ClientSide& c, std::int64_t sequence, bool corrupt = false) {
    Request r{.client_id = c.client_id, .session_id = c.keys.session_id, .sequence = sequence};
    std::vector<std::uint8_t> bytes = EncodeRequest(r);
    WriteMacField(bytes, ComputeMac(c.keys.client_to_server, c.keys.session_id, MacCoveredBytes(bytes)));
    if (corrupt) bytes[bytes.size() - 1] ^= 1;
    const V v = table_->Admit(robot_, DecodeRequest(bytes), bytes, clock_.Now()).verdict;
    if (v == V::kAccepted) table_->Find(robot_, c.client_id)->seen.Observe(sequence);
    return v;
  }

  ManualClock clock_;
  KeyPair alice_ = Identity(1);
  KeyPair bob_ = Identity(2);
  SessionTableOptions options_;
  std::unique_ptr<SessionTable> table_;
  int robot_ = 0;
};

TEST_F(SessionTableTest, AForgedPackageIsRefusedCountedAndLeavesTheWindowAlone) {
  const ClientSide alice = Connect(alice_, Id(alice_, 42));
  EXPECT_EQ(Send(alice, 1'000'000'000'000, /*corrupt=*/true), V::kRefused);
  EXPECT_EQ(table_->counters().forged, 1U);
  for (std::int64_t s = 1; s <= 3; ++s) EXPECT_EQ(Send(alice, s), V::kAccepted) << s;
}

TEST_F(SessionTableTest, APackageReplayedInTheSameSessionIsADuplicateNeverAcceptedTwice) {
  const ClientSide alice = Connect(alice_, Id(alice_, 42));
  EXPECT_EQ(Send(alice, 1), V::kAccepted);
  EXPECT_EQ(Send(alice, 3), V::kAccepted);
  for (int i = 0; i < 3; ++i) {
    EXPECT_EQ(Send(alice, 1), V::kDuplicate);
    EXPECT_EQ(Send(alice, 3), V::kDuplicate);
  }
  EXPECT_EQ(Send(alice, 2), V::kAccepted);  // late, but first: accepted once
  EXPECT_EQ(Send(alice, 2), V::kDuplicate);
  EXPECT_EQ(Send(alice, 0), V::kRefused) << "keyed: a sequence must be positive";
  EXPECT_EQ(table_->counters().replayed, 1U);
}

TEST_F(SessionTableTest, APackageRecordedBeforeARestartIsRefusedByTheNewInstance) {
  const ClientHandshake hs(alice_, Id(alice_, 42));
  const ClientSide alice{hs.Finish(Hello(hs.hello()).body), Id(alice_, 42)};
  ASSERT_EQ(Send(alice, 1), V::kAccepted);
  Restart();  // same identity key, new instance nonce
  EXPECT_EQ(Send(alice, 1), V::kUnknownSession);
  // Replaying the recorded hello too opens a session with another id, whose
  // key the recorder cannot know: re-labelled with that id, the package fails.
  const HelloAnswer answer = Hello(hs.hello());
  ASSERT_NE(answer.session_id, 0);
  EXPECT_NE(answer.session_id, alice.keys.session_id);
  EXPECT_NE(answer.body.instance_nonce, alice.keys.instance_nonce);
  ClientSide relabelled = alice;
  relabelled.keys.session_id = answer.session_id;  // public: anyone can compute it
  EXPECT_EQ(Send(relabelled, 1), V::kRefused);
  EXPECT_EQ(table_->LiveSession(robot_, Id(alice_, 42)), 0);
  EXPECT_EQ(table_->counters().unknown_session, 1U);
  EXPECT_EQ(table_->counters().forged, 1U);
}

TEST_F(SessionTableTest, ANewSessionReplacesTheOldOneOnlyWithItsFirstAuthenticPackage) {
  const ClientHandshake first(alice_, Id(alice_, 42));
  const ClientSide old_session{first.Finish(Hello(first.hello()).body), Id(alice_, 42)};
  ASSERT_EQ(Send(old_session, 1), V::kAccepted);
  // A replayed hello opens nothing: the live session runs on.
  EXPECT_EQ(Hello(first.hello()).session_id, old_session.keys.session_id);
  EXPECT_EQ(table_->LiveSession(robot_, Id(alice_, 42)), old_session.keys.session_id);
  EXPECT_EQ(Send(old_session, 2), V::kAccepted);
  // The client's real reconnect proves itself with a package; the old session
  // ends and the new one continues its window (its numbers go on).
  const ClientSide new_session = Connect(alice_, Id(alice_, 42));
  EXPECT_EQ(table_->LiveSession(robot_, Id(alice_, 42)), old_session.keys.session_id);
  EXPECT_EQ(Send(new_session, 3), V::kAccepted);
  EXPECT_EQ(table_->LiveSession(robot_, Id(alice_, 42)), new_session.keys.session_id);
  EXPECT_EQ(Send(new_session, 2), V::kDuplicate) << "one window per client and robot, taken over";
  EXPECT_EQ(Send(old_session, 4), V::kUnknownSession);
}

TEST_F(SessionTableTest, AnotherKeyCannotTakeAClientIdNowOrAfterARestartAndItsOwnerStillCan) {
  // Issue 19 item 6: after a restart (an empty binding table) bob said hello
  // first with alice's id and took it.
  const std::int64_t alices_id = Id(alice_, 42);
  const ClientSide alice = Connect(alice_, alices_id);
  ASSERT_EQ(Send(alice, 1), V::kAccepted);
  std::string why;
  Connect(bob_, alices_id, &why);
  EXPECT_THAT(why, HasSubstr("is not one of this key's"));
  ClientSide bob_in_alices = alice;
  bob_in_alices.client_id = Id(bob_, 42);  // nor can bob use alice's session under his own id
  EXPECT_EQ(Send(bob_in_alices, 2), V::kRefused);
  EXPECT_EQ(table_->counters().wrong_client, 1U);
  Restart();  // nothing bound yet
  why.clear();
  Connect(bob_, alices_id, &why);
  EXPECT_THAT(why, HasSubstr("is not one of this key's"));
  EXPECT_EQ(table_->counters().hellos_refused, 1U);
  EXPECT_EQ(Send(Connect(alice_, alices_id), 1), V::kAccepted) << "the same running client, a new hello";
  EXPECT_NE(Connect(bob_, Id(bob_, 42)).keys.session_id, 0) << "bob has ids of his own";
}

TEST_F(SessionTableTest, ARepeatedOrReplayedHelloGetsTheSameAnswerAndOpensNothingNew) {
  // Issue 19 item 5: one recorded hello replayed at 3,000/s locked every client out.
  const ClientHandshake recorded(alice_, Id(alice_, 1));
  const HelloAnswer first = Hello(recorded.hello());
  const ClientSide legit{recorded.Finish(first.body), Id(alice_, 1)};
  for (int i = 0; i < 3000; ++i) ASSERT_EQ(Hello(recorded.hello()).session_id, first.session_id) << i;
  EXPECT_EQ(table_->session_count(), 1U);
  EXPECT_EQ(table_->counters().hello_repeats, 3000U);
  EXPECT_EQ(table_->counters().hellos_refused, 0U);
  EXPECT_EQ(Send(Connect(bob_, Id(bob_, 1)), 1), V::kAccepted);
  EXPECT_EQ(Send(legit, 1), V::kAccepted) << "the session of that hello works";
  ClientHello changed = recorded.hello();  // the same nonce with other contents is not a repeat
  changed.client_kx[0] ^= 1;
  EXPECT_THAT(Hello(changed).refusal, HasSubstr("nonce already used by another hello"));
}

TEST_F(SessionTableTest, AHelloOfAClosedSessionIsRefusedAsAReplay) {
  const ClientHandshake recorded(alice_, Id(alice_, 1));
  const ClientSide alice{recorded.Finish(Hello(recorded.hello()).body), Id(alice_, 1)};
  ASSERT_EQ(Send(alice, 1), V::kAccepted);
  clock_.Advance(std::chrono::seconds(3));
  ASSERT_EQ(table_->Expire(robot_, clock_.Now(), std::chrono::seconds(2)).size(), 1U);
  EXPECT_THAT(Hello(recorded.hello()).refusal, HasSubstr("replayed hello"));
  EXPECT_EQ(table_->session_count(), 0U);
  EXPECT_NE(Connect(alice_, Id(alice_, 1)).keys.session_id, 0) << "a new hello of the same client is fine";
}

TEST_F(SessionTableTest, AHelloWithAChangedFieldOrAnUnlistedKeyIsRefused) {
  const ClientHandshake hs(alice_, Id(alice_, 42));
  ClientHello tampered = hs.hello();
  tampered.client_id = 43;  // alice's signature, another id
  EXPECT_THAT(Hello(tampered).refusal, HasSubstr("bad signature"));
  tampered = hs.hello();
  tampered.client_key = bob_.public_key;  // claims to be bob with alice's signature
  EXPECT_EQ(Hello(tampered).session_id, 0);
  const ClientHandshake stranger(Identity(3), Id(Identity(3), 44));
  EXPECT_THAT(Hello(stranger.hello()).refusal, HasSubstr("not in the access list"));
  EXPECT_EQ(table_->counters().hellos_refused, 3U);
  EXPECT_EQ(table_->session_count(), 0U);
}

class SmallTableTest : public SessionTableTest {
 protected:
  SmallTableTest()
      : SessionTableTest({.max_sessions = 3, .max_pending_per_key = 2, .max_client_ids_per_key = 3}) {}
};

class BoundedKeyTest : public SessionTableTest {
 protected:
  BoundedKeyTest()
      : SessionTableTest({.max_sessions = 8, .max_pending_per_key = 2, .max_client_ids_per_key = 3}) {}
};

TEST_F(BoundedKeyTest, PendingSessionsAndClientIdsPerKeyAreBounded) {
  const ClientSide k1 = Connect(alice_, Id(alice_, 1));
  const ClientSide k2 = Connect(alice_, Id(alice_, 1));
  const ClientSide k3 = Connect(alice_, Id(alice_, 1));  // drops k1, alice's oldest pending
  EXPECT_EQ(table_->session_count(), 2U);
  EXPECT_EQ(Send(k1, 1), V::kUnknownSession);
  EXPECT_EQ(Send(k3, 1), V::kAccepted);
  (void)k2;
  ASSERT_NE(Connect(alice_, Id(alice_, 2)).keys.session_id, 0);
  ASSERT_NE(Connect(alice_, Id(alice_, 3)).keys.session_id, 0);
  std::string why;
  Connect(alice_, Id(alice_, 4), &why);  // three ids bound to alice's key already
  EXPECT_THAT(why, HasSubstr("max_client_ids_per_key"));
}

TEST_F(SmallTableTest, ATableFullOfLiveSessionsRefusesAHelloAndTakesOneAfterAnExpiry) {
  std::vector<ClientSide> clients;
  for (std::uint32_t id = 1; id <= 3; ++id) {
    clients.push_back(Connect(id % 2 ? alice_ : bob_, Id(id % 2 ? alice_ : bob_, id)));
    ASSERT_EQ(Send(clients.back(), 1), V::kAccepted);
    clock_.Advance(std::chrono::seconds(1));
  }
  std::string why;
  Connect(bob_, Id(bob_, 4), &why);
  EXPECT_THAT(why, HasSubstr("3 sessions in use already (the --max-sessions bound)"));
  // The oldest one goes silent past the timeout: room again.
  EXPECT_EQ(table_->Expire(robot_, clock_.Now(), std::chrono::milliseconds(2500)).size(), 1U);
  const ClientSide fourth = Connect(bob_, Id(bob_, 4));
  EXPECT_EQ(Send(fourth, 1), V::kAccepted);
  EXPECT_EQ(Send(clients[0], 2), V::kUnknownSession);
}

TEST_F(SessionTableTest, APendingSessionNeverConfirmedExpiresAndReleasesItsClientId) {
  const ClientSide live = Connect(alice_, Id(alice_, 1));
  ASSERT_EQ(Send(live, 1), V::kAccepted);
  const ClientHandshake unconfirmed(alice_, Id(alice_, 2));
  ASSERT_NE(Hello(unconfirmed.hello()).session_id, 0);
  clock_.Advance(std::chrono::seconds(11));  // past the pending timeout (10 s)
  ASSERT_EQ(Send(live, 2), V::kAccepted);
  table_->Find(robot_, live.client_id)->last_heard = clock_.Now();  // RobotSessions::Handle refreshes it
  const ClientSide late = Connect(alice_, Id(alice_, 3));           // pending, younger than the bound
  EXPECT_TRUE(table_->Expire(robot_, clock_.Now(), std::chrono::seconds(2)).empty()) << "no live one expired";
  EXPECT_EQ(table_->session_count(), 2U);
  EXPECT_EQ(Send(late, 1), V::kAccepted);
  EXPECT_NE(Connect(alice_, Id(alice_, 2)).keys.session_id, 0) << "client id 2 is free again";
}

}  // namespace
}  // namespace robotalk
