// The keyed-mode test vectors of docs/security.md ("Keyed mode byte by byte"),
// tests/data/keyed_vectors.txt, checked twice: against the real
// implementation (ClientHandshake, ServerAuthenticator, ComputeMac,
// BroadcastSigner, KeyedClientId, PublicKey) with its random draws replaced
// by the file's fixed inputs, and against the page's formulas rebuilt here
// from libsodium alone, as another language would. A changed byte layout, tag
// or derivation fails here, and so does a page that no longer says what the
// code does.
#include "robotalk/access_list.h"
#include "robotalk/broadcast_signature.h"
#include "robotalk/keys.h"
#include "robotalk/session_auth.h"

#include <gtest/gtest.h>
#include <sodium.h>

#include <cstdio>
#include <cstdlib>
#include <deque>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <variant>
#include <vector>

namespace robotalk {
namespace {

using Bytes = std::vector<std::uint8_t>;

std::string Hex(std::span<const std::uint8_t> b) {
  std::string s;
  char buf[3];
  for (std::uint8_t x : b) {
    std::snprintf(buf, sizeof buf, "%02x", x);
    s += buf;
  }
  return s;
}

Bytes Unhex(const std::string& s) {
  Bytes out;
  for (std::size_t i = 0; i + 1 < s.size(); i += 2)
    out.push_back(static_cast<std::uint8_t>(std::stoi(s.substr(i, 2), nullptr, 16)));
  return out;
}

Bytes Cat(std::initializer_list<std::span<const std::uint8_t>> parts) {
  Bytes out;
  for (auto p : parts) out.insert(out.end(), p.begin(), p.end());
  return out;
}
std::span<const std::uint8_t> Text(std::string_view s) {
  return {reinterpret_cast<const std::uint8_t*>(s.data()), s.size()};
}
Bytes Le64(std::int64_t v) {
  Bytes out;
  for (int i = 0; i < 8; ++i)
    out.push_back(static_cast<std::uint8_t>(static_cast<std::uint64_t>(v) >> (8 * i)));
  return out;
}
Bytes Blake2b(std::size_t size, std::span<const std::uint8_t> key, std::span<const std::uint8_t> data) {
  Bytes out(size);
  crypto_generichash(out.data(), size, data.data(), data.size(), key.empty() ? nullptr : key.data(),
                     key.size());
  return out;
}
template <std::size_t N>
std::array<std::uint8_t, N> Array(const Bytes& b) {
  std::array<std::uint8_t, N> a{};
  EXPECT_EQ(b.size(), N);
  std::copy_n(b.begin(), std::min(N, b.size()), a.begin());
  return a;
}

// tests/data/keyed_vectors.txt: "name = value" lines; values are hex, a
// decimal integer (names ending in _id, _low, _sequence) or "quoted text".
std::map<std::string, std::string> ReadVectors() {
  std::ifstream in(ROBOTALK_KEYED_VECTORS);
  EXPECT_TRUE(in) << "cannot read " << ROBOTALK_KEYED_VECTORS;
  std::map<std::string, std::string> v;
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    const auto eq = line.find(" = ");
    if (eq == std::string::npos) continue;
    std::string value = line.substr(eq + 3);
    if (!value.empty() && value.front() == '"') value = value.substr(1, value.size() - 2);
    v[line.substr(0, eq)] = value;
  }
  return v;
}

// libsodium's random source, replaced by the file's inputs: a request for 16
// bytes takes the next queued nonce, one for 32 the next X25519 secret
// (crypto_kx_keypair draws its secret with randombytes_buf). Anything else
// (or an empty queue) aborts: the implementation drew randomness the page
// does not describe.
std::deque<Bytes> g_nonces, g_secrets;
void FixedBuf(void* buf, std::size_t size) {
  std::deque<Bytes>& q = size == 16 ? g_nonces : g_secrets;
  if ((size != 16 && size != 32) || q.empty()) {
    std::fprintf(stderr, "keyed_vectors_test: unexpected randombytes_buf(%zu)\n", size);
    std::abort();
  }
  std::copy(q.front().begin(), q.front().end(), static_cast<std::uint8_t*>(buf));
  q.pop_front();
}
std::uint32_t FixedRandom() {
  std::fprintf(stderr, "keyed_vectors_test: unexpected randombytes_random()\n");
  std::abort();
}
const char* FixedName() { return "keyed_vectors_test"; }
randombytes_implementation g_fixed = {FixedName, FixedRandom, nullptr, nullptr, FixedBuf, nullptr};

class KeyedVectors : public ::testing::Test {
 protected:
  void SetUp() override {
    InitSodium();  // its own draws (the guard-page canary) from the real source
    randombytes_set_implementation(&g_fixed);
  }
  void TearDown() override {
    randombytes_set_implementation(&randombytes_sysrandom_implementation);
    g_nonces.clear();
    g_secrets.clear();
  }
  // Compares `actual` with the file's `name`; a missing name prints the line to add.
  void Expect(const std::string& name, const std::string& actual) {
    auto it = v.find(name);
    if (it == v.end()) {
      ADD_FAILURE() << "tests/data/keyed_vectors.txt lacks: " << name << " = " << actual;
      return;
    }
    EXPECT_EQ(it->second, actual) << name;
  }
  void Expect(const std::string& name, std::span<const std::uint8_t> actual) { Expect(name, Hex(actual)); }
  Bytes In(const std::string& name) { return Unhex(v.at(name)); }

  std::map<std::string, std::string> v = ReadVectors();
};

TEST_F(KeyedVectors, TheHandshakeMacsAndSignaturesAreTheFilesBytes) {
  const KeyPair client = KeyPair::FromSeed(Array<32>(In("client_seed")));
  const KeyPair server = KeyPair::FromSeed(Array<32>(In("server_seed")));
  Expect("client_key", client.public_key.bytes);
  Expect("client_key_text", client.public_key.ToString());
  Expect("client_fingerprint", client.public_key.Fingerprint());
  Expect("server_key", server.public_key.bytes);

  // The client id: its top half names the key.
  const auto low = static_cast<std::uint32_t>(std::stoul(v.at("client_id_low")));
  const std::int64_t client_id = KeyedClientId(client.public_key, low);
  Expect("client_id", std::to_string(client_id));
  const Bytes prefix = Blake2b(32, {}, Cat({Text("robotalk-client-id-v1"), client.public_key.bytes}));
  const std::uint64_t by_page = (std::uint64_t{prefix[0]} << 24 | std::uint64_t{prefix[1]} << 16 |
                                 std::uint64_t{prefix[2]} << 8 | prefix[3]) &
                                0x7fffffffU;
  EXPECT_EQ(static_cast<std::uint64_t>(client_id), by_page << 32 | low);
  EXPECT_TRUE(ClientIdBelongsTo(client_id, client.public_key));
  EXPECT_FALSE(ClientIdBelongsTo(client_id, server.public_key));

  // The hello, from the client's fixed draws.
  g_nonces = {In("client_nonce")};
  g_secrets = {In("client_kx_secret")};
  ClientHandshake handshake(client, client_id);
  const ClientHello& hello = handshake.hello();
  Expect("client_kx", hello.client_kx);
  Bytes ec(32);
  crypto_scalarmult_base(ec.data(), In("client_kx_secret").data());
  EXPECT_EQ(Hex(ec), Hex(hello.client_kx)) << "client_kx = X25519 base point times the secret";
  const Bytes hello_signed = hello.SignedBytes();
  Expect("hello_signed", hello_signed);
  EXPECT_EQ(Hex(hello_signed), Hex(Cat({Text("robotalk-hello-v1"), client.public_key.bytes, Le64(client_id),
                                        In("client_nonce"), ec})));
  Expect("hello_signature", hello.signature);

  // The server's answer, from its fixed draws.
  const AccessList access =
      AccessList::Parse(client.public_key.ToString() + " alice *=all\n", "keyed_vectors_test");
  ServerAuthenticator authenticator(KeyPair::FromSeed(server.secret_key.seed()), access,
                                    Array<16>(In("instance_nonce")));
  g_nonces = {In("server_nonce")};
  g_secrets = {In("server_kx_secret")};
  const HelloResult result = authenticator.Answer(hello);
  ASSERT_TRUE(std::holds_alternative<HelloAccepted>(result)) << std::get<HelloRefused>(result).why;
  const HelloAccepted& accepted = std::get<HelloAccepted>(result);
  const ServerAnswer& answer = accepted.answer;
  Expect("server_kx", answer.server_kx);
  const Bytes answer_signed = answer.SignedBytes(hello);
  Expect("answer_signed", answer_signed);
  EXPECT_EQ(Hex(answer_signed),
            Hex(Cat({Text("robotalk-answer-v1"), hello_signed, Le64(client_id), In("client_nonce"),
                     In("instance_nonce"), In("server_nonce"), answer.server_kx, server.public_key.bytes})));
  Expect("answer_signature", answer.signature);
  EXPECT_TRUE(VerifySignature(server.public_key, answer_signed, answer.signature));

  // Both sides' keys.
  const SessionKeys keys = handshake.Finish(answer, &server.public_key);
  Bytes rx(32), tx(32);
  ASSERT_EQ(crypto_kx_client_session_keys(rx.data(), tx.data(), ec.data(), In("client_kx_secret").data(),
                                          answer.server_kx.data()),
            0);
  Expect("kx_client_rx", rx);
  Expect("kx_client_tx", tx);
  Bytes q(32);
  ASSERT_EQ(crypto_scalarmult(q.data(), In("client_kx_secret").data(), answer.server_kx.data()), 0);
  const Bytes rx_tx = Blake2b(64, {}, Cat({q, ec, answer.server_kx}));
  EXPECT_EQ(Hex(rx_tx), Hex(rx) + Hex(tx)) << "rx || tx = BLAKE2b-512(X25519(ec, Es) || Ec || Es)";
  const Bytes th = Blake2b(32, {}, Cat({Text("robotalk-transcript-v1"), answer_signed}));
  Expect("transcript_hash", th);
  Expect("key_c2s", keys.client_to_server);
  Expect("key_s2c", keys.server_to_client);
  EXPECT_EQ(Hex(keys.client_to_server), Hex(Blake2b(32, tx, Cat({Text("robotalk-c2s-v1"), th}))));
  EXPECT_EQ(Hex(keys.server_to_client), Hex(Blake2b(32, rx, Cat({Text("robotalk-s2c-v1"), th}))));
  Expect("session_id", std::to_string(keys.session_id));
  EXPECT_EQ(SessionId(hello, answer), keys.session_id);
  const Bytes sid = Blake2b(32, {}, Cat({Text("robotalk-sid-v1"), th}));
  std::uint64_t sid_by_page = 0;
  for (int i = 0; i < 8; ++i) sid_by_page |= std::uint64_t{sid[static_cast<std::size_t>(i)]} << (8 * i);
  sid_by_page &= 0x7fffffffffffffffULL;
  EXPECT_EQ(static_cast<std::uint64_t>(keys.session_id), sid_by_page == 0 ? 1 : sid_by_page);

  // A package (client -> server) and a reply (server -> client).
  const Bytes package = In("package_before_mac");
  const Mac package_mac = ComputeMac(keys.client_to_server, keys.session_id, package);
  Expect("package_mac", package_mac);
  EXPECT_EQ(Hex(package_mac), Hex(Blake2b(16, keys.client_to_server, Cat({Le64(keys.session_id), package}))));
  EXPECT_EQ(accepted.keys.session_id, keys.session_id);
  EXPECT_TRUE(ServerAuthenticator::Verify(accepted.keys, package, package_mac));
  const Bytes reply = In("reply_before_mac");
  const Mac reply_mac = ServerAuthenticator::Seal(accepted.keys, reply);
  Expect("reply_mac", reply_mac);
  EXPECT_TRUE(VerifyMac(keys.server_to_client, keys.session_id, reply, reply_mac));

  // A signed broadcast.
  const std::string channel = v.at("broadcast_channel");
  Bytes broadcast = In("broadcast_message");
  BroadcastSigner(server, Array<16>(In("instance_nonce"))).Sign(channel, broadcast);
  Expect("broadcast_signed", broadcast);
  const Bytes suffix_head = Cat({Text("rtsig-v1"), server.public_key.bytes, In("instance_nonce")});
  const Bytes covered =
      Cat({Text("robotalk-broadcast-v1"), Text(channel), Bytes{0}, In("broadcast_message"), suffix_head});
  Bytes signature(64);
  crypto_sign_detached(signature.data(), nullptr, covered.data(), covered.size(),
                       server.secret_key.bytes().data());
  EXPECT_EQ(Hex(broadcast), Hex(Cat({In("broadcast_message"), suffix_head, signature})));
  const Nonce instance = Array<16>(In("instance_nonce"));
  EXPECT_EQ(VerifyBroadcast(channel, broadcast, server.public_key, &instance), BroadcastVerdict::kAuthentic);
}

}  // namespace
}  // namespace robotalk
