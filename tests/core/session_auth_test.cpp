// Handshake and package MACs (robotalk/session_auth.h). The session state
// (hello repeats, bindings, bounds, the window): tests/server/session_table_test.cpp.
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

  // The server's side of a handshake that must succeed.
  static HelloAccepted Accept(const ServerAuthenticator& server, const ClientHello& hello) {
    HelloResult result = server.Answer(hello);
    if (const auto* refused = std::get_if<HelloRefused>(&result)) throw Error(refused->why);
    return std::get<HelloAccepted>(std::move(result));
  }
  // The refusal of a hello that must be refused ("" when it was accepted).
  static std::string Refusal(const ServerAuthenticator& server, const ClientHello& hello) {
    const HelloResult result = server.Answer(hello);
    const auto* refused = std::get_if<HelloRefused>(&result);
    return refused ? refused->why : "";
  }

  KeyPair server_key_ = Identity(100);
  KeyPair alice_ = Identity(1);
  KeyPair bob_ = Identity(2);
  KeyPair mallory_ = Identity(3);  // not in the access list
  AccessList access_;
};

TEST_F(SessionAuth, AHandshakeGivesBothSidesTheSameKeysInBothDirections) {
  const ServerAuthenticator server(Identity(100), access_, FixedNonce(1));
  const ClientHandshake hs(alice_, Id(alice_, 42));
  const HelloAccepted accepted = Accept(server, hs.hello());
  ASSERT_NE(accepted.client, nullptr);
  EXPECT_EQ(accepted.client->name, "alice");
  const ClientSide alice{hs.Finish(accepted.answer), Id(alice_, 42)};
  EXPECT_EQ(alice.keys.session_id, accepted.keys.session_id);
  EXPECT_EQ(alice.keys.session_id, SessionId(hs.hello(), accepted.answer));
  const auto bytes = PackageBytes(1);
  EXPECT_TRUE(ServerAuthenticator::Verify(accepted.keys, bytes, alice.Seal(bytes)));

  const std::vector<std::uint8_t> reply{9, 8, 7};
  const Mac reply_mac = ServerAuthenticator::Seal(accepted.keys, reply);
  EXPECT_TRUE(VerifyMac(alice.keys.server_to_client, alice.keys.session_id, reply, reply_mac));
  EXPECT_FALSE(VerifyMac(alice.keys.client_to_server, alice.keys.session_id, reply, reply_mac));
}

TEST_F(SessionAuth, AForgedMacIsRefused) {
  const ServerAuthenticator server(Identity(100), access_, FixedNonce(1));
  const ClientHandshake hs(alice_, Id(alice_, 42));
  const HelloAccepted accepted = Accept(server, hs.hello());
  const ClientSide alice{hs.Finish(accepted.answer), Id(alice_, 42)};
  const std::int64_t sid = alice.keys.session_id;
  auto bytes = PackageBytes(1'000'000'000'000);

  Mac flipped = alice.Seal(bytes);
  flipped[5] ^= 0x01;
  EXPECT_FALSE(ServerAuthenticator::Verify(accepted.keys, bytes, flipped));
  const Mac good = alice.Seal(bytes);
  bytes[100] ^= 0x80;  // one bit of the payload changed after sealing
  EXPECT_FALSE(ServerAuthenticator::Verify(accepted.keys, bytes, good));
  EXPECT_FALSE(ServerAuthenticator::Verify(accepted.keys, bytes, Mac{}));
  // The reply key is not the request key.
  const auto fresh = PackageBytes(1'000'000'000'000);
  EXPECT_FALSE(
      ServerAuthenticator::Verify(accepted.keys, fresh, ComputeMac(alice.keys.server_to_client, sid, fresh)));
  // The MAC covers the session id: the same bytes and key under another id fail.
  EXPECT_FALSE(VerifyMac(alice.keys.client_to_server, sid + 1, fresh, alice.Seal(fresh)));
}

TEST_F(SessionAuth, TheSameHelloAnsweredByTwoInstancesGivesUnrelatedSessions) {
  const ServerAuthenticator a(Identity(100), access_, FixedNonce(1));
  const ServerAuthenticator b(Identity(100), access_, FixedNonce(2));
  const ClientHandshake hs(alice_, Id(alice_, 42));
  const SessionKeys ka = hs.Finish(Accept(a, hs.hello()).answer);
  const HelloAccepted at_b = Accept(b, hs.hello());
  const SessionKeys kb = hs.Finish(at_b.answer);
  EXPECT_NE(ka.session_id, kb.session_id);
  EXPECT_NE(ka.client_to_server, kb.client_to_server);
  EXPECT_EQ(ka.instance_nonce, FixedNonce(1));
  EXPECT_EQ(kb.instance_nonce, FixedNonce(2));
  // A package sealed for instance a, re-labelled for b's session, is forged there.
  const auto bytes = PackageBytes(1);
  EXPECT_FALSE(
      ServerAuthenticator::Verify(at_b.keys, bytes, ComputeMac(ka.client_to_server, ka.session_id, bytes)));
}

TEST_F(SessionAuth, AnotherKeyCannotClaimAClientIdOfAKey) {
  // Issue 19 item 6: after a restart (an empty binding table) bob said hello
  // first with alice's id and took it. The id's high bits come from the key.
  const ServerAuthenticator server(Identity(100), access_, FixedNonce(1));
  const ClientHandshake bob(bob_, Id(alice_, 42));
  EXPECT_THAT(Refusal(server, bob.hello()), HasSubstr("is not one of this key's"));
  const ClientHandshake bobs_own(bob_, Id(bob_, 42));
  EXPECT_EQ(Refusal(server, bobs_own.hello()), "") << "bob has ids of his own";
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

TEST_F(SessionAuth, AHelloWithAChangedFieldOrAnUnlistedKeyIsRefused) {
  const ServerAuthenticator server(Identity(100), access_, FixedNonce(1));
  const ClientHandshake hs(alice_, Id(alice_, 42));
  ClientHello tampered = hs.hello();
  tampered.client_id = 43;  // alice's signature, another id
  EXPECT_THAT(Refusal(server, tampered), HasSubstr("bad signature"));
  tampered = hs.hello();
  tampered.client_key = bob_.public_key;  // claims to be bob with alice's signature
  EXPECT_THAT(Refusal(server, tampered), HasSubstr("bad signature"));
  const ClientHandshake stranger(mallory_, Id(mallory_, 44));
  EXPECT_THAT(Refusal(server, stranger.hello()), HasSubstr("not in the access list"));
}

TEST_F(SessionAuth, TheClientRefusesATamperedAnswerAndAnUnexpectedServer) {
  const ServerAuthenticator server(Identity(100), access_, FixedNonce(1));
  const ClientHandshake hs(alice_, Id(alice_, 42));
  const ServerAnswer answer = Accept(server, hs.hello()).answer;
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
  const ServerAuthenticator server(Identity(100), access_, FixedNonce(1));
  const ClientHandshake hs(bob_, Id(bob_, 7));
  const HelloAccepted bob = Accept(server, hs.hello());
  ASSERT_NE(bob.client, nullptr);
  Request goto_request;
  goto_request.commands.push_back(Command{.id = 1, .type = CommandType::kGoto});
  EXPECT_EQ(CheckRights(access_, *bob.client, "pioneer", goto_request),
            "client 'bob' may not command robot 'pioneer' (its rights there: query)");
  Request query;
  query.queries.push_back(Query{.id = 2});
  EXPECT_EQ(CheckRights(access_, *bob.client, "pioneer", query), "");
  EXPECT_NE(CheckRights(access_, *bob.client, "arm", query), "");
}

}  // namespace
}  // namespace robotalk
