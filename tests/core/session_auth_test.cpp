// Handshake, package MACs and the replay window (robotalk/session_auth.h).
#include "robotalk/session_auth.h"

#include "robotalk/request.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace robotalk {
namespace {

using ::testing::HasSubstr;

// Keyed mode: a client id of `key` (issue 19 item 6: ids come from keys).
std::int64_t Id(const KeyPair& key, std::uint32_t n) { return KeyedClientId(key.public_key, n); }

KeyPair Identity(std::uint8_t v) {
  std::array<std::uint8_t, 32> seed{};
  seed.fill(v);
  return KeyPair::FromSeed(seed);
}

Nonce FixedNonce(std::uint8_t v) {
  Nonce n{};
  n.fill(v);
  return n;
}

std::vector<std::uint8_t> PackageBytes(std::int64_t sequence, std::size_t size = 200) {
  std::vector<std::uint8_t> bytes(size);
  for (std::size_t i = 0; i < size; ++i) bytes[i] = static_cast<std::uint8_t>(i * 31 + 7);
  for (int i = 0; i < 8; ++i)
    bytes[static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(sequence >> (8 * i));
  return bytes;
}

// A client's side of one session: seals packages as the wire proposal says.
struct ClientSide {
  SessionKeys keys;
  std::int64_t client_id;
  Mac Seal(const std::vector<std::uint8_t>& bytes) const {
    return ComputeMac(keys.client_to_server, keys.session_id, bytes);
  }
};

class SessionAuth : public ::testing::Test {
 protected:
  SessionAuth()
      : access_(AccessList::Parse(alice_.public_key.ToString() + " alice *=all\n" +
                                      bob_.public_key.ToString() + " bob pioneer=query\n",
                                  "clients")) {}

  ClientSide Connect(ServerAuthenticator& server, const KeyPair& who, std::int64_t client_id) {
    const ClientHandshake hs(who, client_id);
    const ServerAnswer answer = server.Handshake(hs.hello(), clock_.Now());
    return {hs.Finish(answer), client_id};
  }
  // Sends one package of `client` through `server`.
  static PackageVerdict Send(ServerAuthenticator& server, const ClientSide& client, std::int64_t sequence) {
    const auto bytes = PackageBytes(sequence);
    return server.Verify(client.keys.session_id, client.client_id, sequence, bytes, client.Seal(bytes))
        .verdict;
  }

  ManualClock clock_;
  KeyPair server_key_ = Identity(100);
  KeyPair alice_ = Identity(1);
  KeyPair bob_ = Identity(2);
  KeyPair mallory_ = Identity(3);  // not in the access list
  AccessList access_;
};

TEST_F(SessionAuth, AHandshakeGivesBothSidesTheSameKeysInBothDirections) {
  ServerAuthenticator server(Identity(100), access_, FixedNonce(1));
  const ClientSide alice = Connect(server, alice_, Id(alice_, 42));
  const auto bytes = PackageBytes(1);
  const auto verified = server.Verify(alice.keys.session_id, Id(alice_, 42), 1, bytes, alice.Seal(bytes));
  EXPECT_EQ(verified.verdict, PackageVerdict::kAccepted);
  ASSERT_NE(verified.client, nullptr);
  EXPECT_EQ(verified.client->name, "alice");
  EXPECT_EQ(server.LiveSession(Id(alice_, 42)), alice.keys.session_id);

  const std::vector<std::uint8_t> reply{9, 8, 7};
  const Mac reply_mac = server.SealReply(alice.keys.session_id, reply);
  EXPECT_TRUE(VerifyMac(alice.keys.server_to_client, alice.keys.session_id, reply, reply_mac));
  EXPECT_FALSE(VerifyMac(alice.keys.client_to_server, alice.keys.session_id, reply, reply_mac));
}

TEST_F(SessionAuth, AForgedMacIsRefusedCountedAndLeavesTheWindowAlone) {
  ServerAuthenticator server(Identity(100), access_, FixedNonce(1));
  const ClientSide alice = Connect(server, alice_, Id(alice_, 42));
  const std::int64_t sid = alice.keys.session_id;
  auto bytes = PackageBytes(1'000'000'000'000);

  Mac flipped = alice.Seal(bytes);
  flipped[5] ^= 0x01;
  EXPECT_EQ(server.Verify(sid, Id(alice_, 42), 1'000'000'000'000, bytes, flipped).verdict,
            PackageVerdict::kForged);
  const Mac good = alice.Seal(bytes);
  bytes[100] ^= 0x80;  // one bit of the payload changed after sealing
  EXPECT_EQ(server.Verify(sid, Id(alice_, 42), 1'000'000'000'000, bytes, good).verdict,
            PackageVerdict::kForged);
  const Mac zero{};
  EXPECT_EQ(server.Verify(sid, Id(alice_, 42), 1'000'000'000'000, bytes, zero).verdict,
            PackageVerdict::kForged);
  // The reply key is not the request key.
  const auto fresh = PackageBytes(1'000'000'000'000);
  EXPECT_EQ(server
                .Verify(sid, Id(alice_, 42), 1'000'000'000'000, fresh,
                        ComputeMac(alice.keys.server_to_client, sid, fresh))
                .verdict,
            PackageVerdict::kForged);
  // The MAC covers the session id: the same bytes and key under another id fail.
  EXPECT_FALSE(VerifyMac(alice.keys.client_to_server, sid + 1, fresh, alice.Seal(fresh)));
  EXPECT_EQ(server.counters().forged, 4U);

  // The forged sequence 10^12 poisoned nothing: 1, 2, 3 run.
  for (std::int64_t s = 1; s <= 3; ++s) EXPECT_EQ(Send(server, alice, s), PackageVerdict::kAccepted) << s;
}

TEST_F(SessionAuth, APackageReplayedInTheSameSessionIsADuplicateNeverAcceptedTwice) {
  ServerAuthenticator server(Identity(100), access_, FixedNonce(1));
  const ClientSide alice = Connect(server, alice_, Id(alice_, 42));
  EXPECT_EQ(Send(server, alice, 1), PackageVerdict::kAccepted);
  EXPECT_EQ(Send(server, alice, 3), PackageVerdict::kAccepted);
  for (int i = 0; i < 3; ++i) {
    EXPECT_EQ(Send(server, alice, 1), PackageVerdict::kDuplicate);
    EXPECT_EQ(Send(server, alice, 3), PackageVerdict::kDuplicate);
  }
  EXPECT_EQ(Send(server, alice, 2), PackageVerdict::kAccepted);  // late, but first: accepted once
  EXPECT_EQ(Send(server, alice, 2), PackageVerdict::kDuplicate);
  EXPECT_EQ(server.counters().duplicate, 7U);
}

TEST_F(SessionAuth, APackageRecordedBeforeAServerRestartIsRefusedByTheNewInstance) {
  std::vector<std::uint8_t> recorded_bytes;
  Mac recorded_mac{};
  std::int64_t recorded_sid = 0;
  ClientHello recorded_hello;
  {
    ServerAuthenticator old_server(Identity(100), access_, FixedNonce(1));
    const ClientHandshake hs(alice_, Id(alice_, 42));
    recorded_hello = hs.hello();
    const ClientSide alice{hs.Finish(old_server.Handshake(hs.hello(), clock_.Now())), Id(alice_, 42)};
    recorded_bytes = PackageBytes(1);
    recorded_mac = alice.Seal(recorded_bytes);
    recorded_sid = alice.keys.session_id;
    ASSERT_EQ(old_server.Verify(recorded_sid, Id(alice_, 42), 1, recorded_bytes, recorded_mac).verdict,
              PackageVerdict::kAccepted);
  }
  // Same identity key, new instance nonce: a restart.
  ServerAuthenticator new_server(Identity(100), access_, FixedNonce(2));
  EXPECT_EQ(new_server.Verify(recorded_sid, Id(alice_, 42), 1, recorded_bytes, recorded_mac).verdict,
            PackageVerdict::kUnknownSession);
  // Replaying the recorded hello too opens a session with another id, whose
  // key the recorder cannot know: re-labelled with that id, the package fails.
  const ServerAnswer answer = new_server.Handshake(recorded_hello, clock_.Now());
  EXPECT_EQ(answer.instance_nonce, FixedNonce(2));
  EXPECT_EQ(new_server.session_count(), 1U);
  const std::int64_t replayed_sid = SessionId(recorded_hello, answer);  // public: anyone can compute it
  EXPECT_NE(replayed_sid, recorded_sid);
  EXPECT_EQ(new_server.Verify(replayed_sid, Id(alice_, 42), 1, recorded_bytes, recorded_mac).verdict,
            PackageVerdict::kForged);
  EXPECT_EQ(new_server.LiveSession(Id(alice_, 42)), 0);
  EXPECT_EQ(new_server.counters().unknown_session, 1U);
  EXPECT_EQ(new_server.counters().forged, 1U);
}

TEST_F(SessionAuth, TheSameHelloAnsweredByTwoInstancesGivesUnrelatedSessions) {
  ServerAuthenticator a(Identity(100), access_, FixedNonce(1));
  ServerAuthenticator b(Identity(100), access_, FixedNonce(2));
  const ClientHandshake hs(alice_, Id(alice_, 42));
  const SessionKeys ka = hs.Finish(a.Handshake(hs.hello(), clock_.Now()));
  const SessionKeys kb = hs.Finish(b.Handshake(hs.hello(), clock_.Now()));
  EXPECT_NE(ka.session_id, kb.session_id);
  EXPECT_NE(ka.client_to_server, kb.client_to_server);
  EXPECT_EQ(ka.instance_nonce, FixedNonce(1));
  EXPECT_EQ(kb.instance_nonce, FixedNonce(2));
  // A package sealed for instance a, re-labelled for b's session, is forged there.
  const auto bytes = PackageBytes(1);
  const Mac mac = ComputeMac(ka.client_to_server, ka.session_id, bytes);
  EXPECT_EQ(b.Verify(kb.session_id, Id(alice_, 42), 1, bytes, mac).verdict, PackageVerdict::kForged);
  EXPECT_EQ(b.Verify(ka.session_id, Id(alice_, 42), 1, bytes, mac).verdict, PackageVerdict::kUnknownSession);
}

TEST_F(SessionAuth, ANewSessionReplacesTheOldOneOnlyWithItsFirstAuthenticPackage) {
  ServerAuthenticator server(Identity(100), access_, FixedNonce(1));
  const ClientHandshake first(alice_, Id(alice_, 42));
  const ClientSide old_session{first.Finish(server.Handshake(first.hello(), clock_.Now())), Id(alice_, 42)};
  ASSERT_EQ(Send(server, old_session, 1), PackageVerdict::kAccepted);

  // A replayed hello opens only a pending session: the live one runs on.
  (void)server.Handshake(first.hello(), clock_.Now());
  EXPECT_EQ(server.LiveSession(Id(alice_, 42)), old_session.keys.session_id);
  EXPECT_EQ(Send(server, old_session, 2), PackageVerdict::kAccepted);

  // The client's real reconnect proves itself with a package; the old session ends.
  const ClientSide new_session = Connect(server, alice_, Id(alice_, 42));
  EXPECT_EQ(server.LiveSession(Id(alice_, 42)), old_session.keys.session_id);
  EXPECT_EQ(Send(server, new_session, 1), PackageVerdict::kAccepted);
  EXPECT_EQ(server.LiveSession(Id(alice_, 42)), new_session.keys.session_id);
  EXPECT_EQ(Send(server, old_session, 3), PackageVerdict::kUnknownSession);
}

TEST_F(SessionAuth, AnotherKeyCannotTakeAClientIdNowOrAfterARestartAndItsOwnerStillCan) {
  // Issue 19 item 6: after a restart (an empty binding table) bob said hello
  // first with alice's id and took it; alice's running client was refused
  // ("client id is bound to another key") until it was recreated.
  const std::int64_t alices_id = Id(alice_, 42);
  {
    ServerAuthenticator server(Identity(100), access_, FixedNonce(1));
    const ClientSide alice = Connect(server, alice_, alices_id);
    ASSERT_EQ(Send(server, alice, 1), PackageVerdict::kAccepted);
    const ClientHandshake bob(bob_, alices_id);
    EXPECT_THROW(server.Handshake(bob.hello(), clock_.Now()), AuthError);
    // Nor can bob use alice's session under his own id.
    const auto bytes = PackageBytes(2);
    EXPECT_EQ(server.Verify(alice.keys.session_id, Id(bob_, 42), 2, bytes, alice.Seal(bytes)).verdict,
              PackageVerdict::kWrongClient);
  }
  ServerAuthenticator restarted(Identity(100), access_, FixedNonce(2));  // nothing bound yet
  const ClientHandshake bob(bob_, alices_id);
  try {
    restarted.Handshake(bob.hello(), clock_.Now());
    ADD_FAILURE() << "bob took alice's client id on the restarted server";
  } catch (const AuthError& e) {
    EXPECT_THAT(e.what(), HasSubstr("is not one of this key's"));
  }
  EXPECT_EQ(restarted.counters().handshakes_refused, 1U);
  const ClientSide alice = Connect(restarted, alice_, alices_id);  // the same running client, a new hello
  EXPECT_EQ(Send(restarted, alice, 1), PackageVerdict::kAccepted);
  EXPECT_NO_THROW(Connect(restarted, bob_, Id(bob_, 42))) << "bob has ids of his own";
}

TEST(KeyedClientId, IsTheKeysOwnAndKeepsTheClientsLowBits) {
  std::array<std::uint8_t, 32> seed{};
  seed.fill(7);
  const PublicKey a = KeyPair::FromSeed(seed).public_key;
  seed.fill(8);
  const PublicKey b = KeyPair::FromSeed(seed).public_key;
  for (std::uint32_t low : {1U, 2U, 0xffffffffU}) {
    const std::int64_t id = KeyedClientId(a, low);
    EXPECT_GT(id, 0);
    EXPECT_EQ(static_cast<std::uint32_t>(id), low);
    EXPECT_TRUE(ClientIdBelongsTo(id, a));
    EXPECT_FALSE(ClientIdBelongsTo(id, b));
  }
  EXPECT_EQ(KeyedClientId(a, 0), KeyedClientId(a, 1)) << "never 0 low bits";
  EXPECT_FALSE(ClientIdBelongsTo(42, a));
  EXPECT_FALSE(ClientIdBelongsTo(-KeyedClientId(a, 5), a));
}

TEST_F(SessionAuth, ARepeatedOrReplayedHelloGetsTheSameAnswerAndOpensNothingNew) {
  // Issue 19 item 5: one recorded hello replayed at 3,000/s locked every
  // client out; each copy opened a new pending session.
  ServerAuthenticator server(Identity(100), access_, FixedNonce(1),
                             {.max_sessions = 16, .max_pending_per_key = 4, .max_client_ids_per_key = 64});
  const ClientHandshake recorded(alice_, Id(alice_, 1));
  const ServerAnswer first = server.Handshake(recorded.hello(), clock_.Now());
  const ClientSide legit{recorded.Finish(first), Id(alice_, 1)};
  for (int i = 0; i < 3000; ++i) {
    const ServerAnswer again = server.Handshake(recorded.hello(), clock_.Now());
    ASSERT_EQ(SessionId(recorded.hello(), again), legit.keys.session_id) << "copy " << i;
  }
  EXPECT_EQ(server.session_count(), 1U);
  EXPECT_EQ(server.counters().hello_repeats, 3000U);
  EXPECT_EQ(server.counters().handshakes, 1U);
  EXPECT_TRUE(server.TakeClosed().empty()) << "no pending session was dropped for a replay";
  // Room for every other key, and for alice's own new hellos.
  const ClientSide bob = Connect(server, bob_, Id(bob_, 1));
  EXPECT_EQ(Send(server, bob, 1), PackageVerdict::kAccepted);
  EXPECT_EQ(Send(server, legit, 1), PackageVerdict::kAccepted);  // the session of that hello works
  // The same nonce with other contents is not a repeat.
  ClientHello changed = recorded.hello();
  changed.client_kx[0] ^= 1;
  EXPECT_THROW(server.Handshake(changed, clock_.Now()), AuthError);
}

TEST_F(SessionAuth, AHelloOfAClosedSessionIsRefusedAsAReplay) {
  ServerAuthenticator server(Identity(100), access_, FixedNonce(1));
  const ClientHandshake recorded(alice_, Id(alice_, 1));
  const ClientSide alice{recorded.Finish(server.Handshake(recorded.hello(), clock_.Now())), Id(alice_, 1)};
  ASSERT_EQ(Send(server, alice, 1), PackageVerdict::kAccepted);
  server.Close(alice.keys.session_id);
  try {
    server.Handshake(recorded.hello(), clock_.Now());
    ADD_FAILURE() << "a closed session's hello opened a new one";
  } catch (const AuthError& e) {
    EXPECT_THAT(e.what(), HasSubstr("replayed hello"));
  }
  EXPECT_EQ(server.session_count(), 0U);
  EXPECT_NO_THROW(Connect(server, alice_, Id(alice_, 1))) << "a new hello of the same client is fine";
}

TEST_F(SessionAuth, AHelloWithAChangedFieldOrAnUnlistedKeyIsRefused) {
  ServerAuthenticator server(Identity(100), access_, FixedNonce(1));
  const ClientHandshake hs(alice_, Id(alice_, 42));
  ClientHello tampered = hs.hello();
  tampered.client_id = 43;  // alice's signature, another id
  EXPECT_THROW(
      try { server.Handshake(tampered, clock_.Now()); } catch (const AuthError& e) {
        EXPECT_THAT(e.what(), HasSubstr("bad signature"));
        throw;
      },
      AuthError);
  tampered = hs.hello();
  tampered.client_key = bob_.public_key;  // claims to be bob with alice's signature
  EXPECT_THROW(server.Handshake(tampered, clock_.Now()), AuthError);
  const ClientHandshake stranger(mallory_, Id(mallory_, 44));
  EXPECT_THROW(
      try { server.Handshake(stranger.hello(), clock_.Now()); } catch (const AuthError& e) {
        EXPECT_THAT(e.what(), HasSubstr("not in the access list"));
        throw;
      },
      AuthError);
  EXPECT_EQ(server.counters().handshakes_refused, 3U);
  EXPECT_EQ(server.session_count(), 0U);
}

TEST_F(SessionAuth, TheClientRefusesATamperedAnswerAndAnUnexpectedServer) {
  ServerAuthenticator server(Identity(100), access_, FixedNonce(1));
  const ClientHandshake hs(alice_, Id(alice_, 42));
  const ServerAnswer answer = server.Handshake(hs.hello(), clock_.Now());
  ServerAnswer bad = answer;
  bad.instance_nonce[0] ^= 1;
  EXPECT_THROW(hs.Finish(bad), AuthError);
  bad = answer;
  bad.client_nonce[0] ^= 1;
  EXPECT_THROW(hs.Finish(bad), AuthError);
  const PublicKey other = Identity(101).public_key;
  EXPECT_THROW(hs.Finish(answer, &other), AuthError);
  const PublicKey pinned = Identity(100).public_key;
  EXPECT_NO_THROW(hs.Finish(answer, &pinned));
}

TEST_F(SessionAuth, TheVerifiedClientsRightsDecideWhatItMayDo) {
  ServerAuthenticator server(Identity(100), access_, FixedNonce(1));
  const ClientSide bob = Connect(server, bob_, Id(bob_, 7));
  const auto bytes = PackageBytes(1);
  const auto v = server.Verify(bob.keys.session_id, Id(bob_, 7), 1, bytes, bob.Seal(bytes));
  ASSERT_EQ(v.verdict, PackageVerdict::kAccepted);
  Request goto_request;
  goto_request.commands.push_back(Command{.id = 1, .type = CommandType::kGoto});
  EXPECT_EQ(CheckRights(access_, *v.client, "pioneer", goto_request),
            "client 'bob' may not command robot 'pioneer' (its rights there: query)");
  Request query;
  query.queries.push_back(Query{.id = 2});
  EXPECT_EQ(CheckRights(access_, *v.client, "pioneer", query), "");
  EXPECT_NE(CheckRights(access_, *v.client, "arm", query), "");
}

TEST_F(SessionAuth, PendingSessionsAndClientIdsPerKeyAreBounded) {
  ServerAuthenticator server(Identity(100), access_, FixedNonce(1),
                             {.max_sessions = 8, .max_pending_per_key = 2, .max_client_ids_per_key = 3});
  const ClientHandshake h1(alice_, Id(alice_, 1)), h2(alice_, Id(alice_, 1)), h3(alice_, Id(alice_, 1));
  const SessionKeys k1 = h1.Finish(server.Handshake(h1.hello(), clock_.Now()));
  const SessionKeys k2 = h2.Finish(server.Handshake(h2.hello(), clock_.Now()));
  const SessionKeys k3 =
      h3.Finish(server.Handshake(h3.hello(), clock_.Now()));  // drops k1, the oldest pending
  EXPECT_EQ(server.session_count(), 2U);
  EXPECT_EQ(Send(server, {k1, Id(alice_, 1)}, 1), PackageVerdict::kUnknownSession);
  EXPECT_EQ(Send(server, {k3, Id(alice_, 1)}, 1), PackageVerdict::kAccepted);
  (void)k2;
  (void)Connect(server, alice_, Id(alice_, 2));
  (void)Connect(server, alice_, Id(alice_, 3));
  EXPECT_THROW(
      try { Connect(server, alice_, Id(alice_, 4)); } catch (const AuthError& e) {
        EXPECT_THAT(e.what(), HasSubstr("max_client_ids_per_key"));
        throw;
      },
      AuthError);
}

TEST_F(SessionAuth, TheServerRefusesAHandshakeBeyondItsSessionBoundAndAcceptsOneAfterAClose) {
  ServerAuthenticator server(Identity(100), access_, FixedNonce(1), {.max_sessions = 3});
  std::vector<ClientSide> clients;
  for (std::int64_t id = 1; id <= 3; ++id)
    clients.push_back(
        Connect(server, id % 2 ? alice_ : bob_, Id(id % 2 ? alice_ : bob_, static_cast<std::uint32_t>(id))));
  EXPECT_THROW(
      try { Connect(server, alice_, Id(alice_, 4)); } catch (const AuthError& e) {
        EXPECT_THAT(e.what(), HasSubstr("3 sessions open (limit max_sessions)"));
        throw;
      },
      AuthError);
  server.Close(clients[1].keys.session_id);
  EXPECT_EQ(server.session_count(), 2U);
  const ClientSide fourth = Connect(server, alice_, Id(alice_, 4));
  EXPECT_EQ(Send(server, fourth, 1), PackageVerdict::kAccepted);
  EXPECT_EQ(Send(server, clients[1], 1), PackageVerdict::kUnknownSession);
}

TEST_F(SessionAuth, APendingSessionNeverConfirmedExpiresAndReleasesItsClientId) {
  ServerAuthenticator server(Identity(100), access_, FixedNonce(1));
  const ClientSide live = Connect(server, alice_, Id(alice_, 1));
  ASSERT_EQ(Send(server, live, 1), PackageVerdict::kAccepted);
  clock_.Advance(std::chrono::seconds(1));
  const ClientHandshake unconfirmed(alice_, Id(alice_, 2));
  (void)server.Handshake(unconfirmed.hello(), clock_.Now());
  clock_.Advance(std::chrono::seconds(2));
  const ClientSide late = Connect(server, alice_, Id(alice_, 3));  // pending, younger than the bound
  EXPECT_EQ(server.ExpirePending(clock_.Now(), std::chrono::milliseconds(1500)), 1U);
  EXPECT_EQ(server.session_count(), 2U);
  EXPECT_EQ(Send(server, live, 2), PackageVerdict::kAccepted);  // live sessions never expire here
  EXPECT_EQ(Send(server, late, 1), PackageVerdict::kAccepted);
  // Client id 2 is free again.
  EXPECT_NO_THROW(Connect(server, alice_, Id(alice_, 2)));
}

TEST(ReplayWindow, AcceptsEachSequenceOnceInAnyOrderWithinTheWindow) {
  ReplayWindow w;
  using V = ReplayWindow::Verdict;
  EXPECT_EQ(w.Accept(0), V::kInvalid);
  EXPECT_EQ(w.Accept(-5), V::kInvalid);
  EXPECT_EQ(w.Accept(5), V::kNew);
  EXPECT_EQ(w.Accept(2), V::kNew);
  EXPECT_EQ(w.Accept(5), V::kDuplicate);
  EXPECT_EQ(w.Accept(2), V::kDuplicate);
  EXPECT_EQ(w.Check(3), V::kNew);
  EXPECT_EQ(w.Check(3), V::kNew);  // Check changes nothing
  EXPECT_EQ(w.Accept(3), V::kNew);
  EXPECT_EQ(w.highest(), 5);

  EXPECT_EQ(w.Accept(5 + ReplayWindow::kWindow), V::kNew);
  EXPECT_EQ(w.Accept(5), V::kTooOld);  // now exactly kWindow below the highest
  EXPECT_EQ(w.Accept(6), V::kNew);     // inside the window, never seen: the slide cleared its bit
  EXPECT_EQ(w.Accept(6), V::kDuplicate);
  EXPECT_EQ(w.Accept(1'000'000), V::kNew);  // a far jump clears the whole bitmap
  EXPECT_EQ(w.Accept(1'000'000 - 1), V::kNew);
  EXPECT_EQ(w.Accept(1'000'000 - ReplayWindow::kWindow + 1), V::kNew);
  EXPECT_EQ(w.Accept(1'000'000 - ReplayWindow::kWindow), V::kTooOld);
}

TEST(PackageVerdict, EveryVerdictHasAName) {
  for (const auto v : {PackageVerdict::kAccepted, PackageVerdict::kUnknownSession,
                       PackageVerdict::kWrongClient, PackageVerdict::kForged, PackageVerdict::kDuplicate,
                       PackageVerdict::kTooOld, PackageVerdict::kInvalidSequence}) {
    EXPECT_STRNE(ToString(v), "?");
  }
}

}  // namespace
}  // namespace robotalk
