// Handshake and MAC (session_auth.h). Only libsodium does
// cryptography here; this file fixes the byte strings it is applied to.
#include "robotalk/session_auth.h"

#include <sodium.h>

#include <string_view>

namespace robotalk {
namespace {

constexpr std::string_view kHelloTag = "robotalk-hello-v1";
constexpr std::string_view kAnswerTag = "robotalk-answer-v1";

void Append(std::vector<std::uint8_t>& out, std::string_view s) { out.insert(out.end(), s.begin(), s.end()); }
template <std::size_t N>
void Append(std::vector<std::uint8_t>& out, const std::array<std::uint8_t, N>& a) {
  out.insert(out.end(), a.begin(), a.end());
}
void Append(std::vector<std::uint8_t>& out, std::int64_t v) {
  const auto u = static_cast<std::uint64_t>(v);
  for (int i = 0; i < 8; ++i) out.push_back(static_cast<std::uint8_t>(u >> (8 * i)));
}

// BLAKE2b-256 of (label || data), keyed by `key` when not empty.
std::array<std::uint8_t, 32> Hash(std::span<const std::uint8_t> key, std::string_view label,
                                  std::span<const std::uint8_t> data) {
  std::array<std::uint8_t, 32> out{};
  crypto_generichash_state st;
  crypto_generichash_init(&st, key.empty() ? nullptr : key.data(), key.size(), out.size());
  crypto_generichash_update(&st, reinterpret_cast<const unsigned char*>(label.data()), label.size());
  crypto_generichash_update(&st, data.data(), data.size());
  crypto_generichash_final(&st, out.data(), out.size());
  return out;
}

// Both sides: the kx keys as the client names them (tx = client -> server).
std::array<std::uint8_t, 32> TranscriptHash(const ClientHello& hello, const ServerAnswer& answer) {
  return Hash({}, "robotalk-transcript-v1", answer.SignedBytes(hello));
}

std::int64_t SessionIdOf(std::span<const std::uint8_t, 32> th) {
  const auto sid = Hash({}, "robotalk-sid-v1", th);
  std::uint64_t id = 0;
  for (int i = 0; i < 8; ++i) id |= static_cast<std::uint64_t>(sid[static_cast<std::size_t>(i)]) << (8 * i);
  id &= 0x7fffffffffffffffULL;  // positive: prints and compares like every other id
  return id == 0 ? 1 : static_cast<std::int64_t>(id);
}

SessionKeys DeriveKeys(const ClientHello& hello, const ServerAnswer& answer,
                       std::span<const std::uint8_t, 32> tx, std::span<const std::uint8_t, 32> rx) {
  const auto th = TranscriptHash(hello, answer);
  SessionKeys keys;
  keys.client_to_server = Hash(tx, "robotalk-c2s-v1", th);
  keys.server_to_client = Hash(rx, "robotalk-s2c-v1", th);
  keys.session_id = SessionIdOf(th);
  keys.instance_nonce = answer.instance_nonce;
  return keys;
}

}  // namespace

namespace {
std::uint32_t KeyPrefix(const PublicKey& key) {
  const auto h = Hash({}, "robotalk-client-id-v1", key.bytes);
  return (static_cast<std::uint32_t>(h[0]) << 24 | static_cast<std::uint32_t>(h[1]) << 16 |
          static_cast<std::uint32_t>(h[2]) << 8 | h[3]) &
         0x7fffffffU;
}
}  // namespace

std::int64_t KeyedClientId(const PublicKey& key, std::uint32_t low) {
  return static_cast<std::int64_t>(static_cast<std::uint64_t>(KeyPrefix(key)) << 32 | (low == 0 ? 1U : low));
}

bool ClientIdBelongsTo(std::int64_t client_id, const PublicKey& key) {
  const auto id = static_cast<std::uint64_t>(client_id);
  return client_id > 0 && (id & 0xffffffffULL) != 0 && (id >> 32) == KeyPrefix(key);
}

std::int64_t SessionId(const ClientHello& hello, const ServerAnswer& answer) {
  return SessionIdOf(TranscriptHash(hello, answer));
}

Nonce RandomNonce() {
  InitSodium();
  Nonce n{};
  randombytes_buf(n.data(), n.size());
  return n;
}

std::vector<std::uint8_t> ClientHello::SignedBytes() const {
  std::vector<std::uint8_t> out;
  out.reserve(kHelloTag.size() + 32 + 8 + kNonceBytes + 32);
  Append(out, kHelloTag);
  Append(out, client_key.bytes);
  Append(out, client_id);
  Append(out, client_nonce);
  Append(out, client_kx);
  return out;
}

std::vector<std::uint8_t> ServerAnswer::SignedBytes(const ClientHello& hello) const {
  std::vector<std::uint8_t> out;
  Append(out, kAnswerTag);
  const auto h = hello.SignedBytes();
  out.insert(out.end(), h.begin(), h.end());
  Append(out, client_id);
  Append(out, client_nonce);
  Append(out, instance_nonce);
  Append(out, server_nonce);
  Append(out, server_kx);
  Append(out, server_key.bytes);
  return out;
}

SessionKeys::~SessionKeys() {
  sodium_memzero(client_to_server.data(), client_to_server.size());
  sodium_memzero(server_to_client.data(), server_to_client.size());
}

ClientHandshake::ClientHandshake(const KeyPair& identity, std::int64_t client_id) {
  InitSodium();
  hello_.client_key = identity.public_key;
  hello_.client_id = client_id;
  hello_.client_nonce = RandomNonce();
  crypto_kx_keypair(hello_.client_kx.data(), kx_secret_.data());
  hello_.signature = Sign(identity, hello_.SignedBytes());
}

ClientHandshake::~ClientHandshake() { sodium_memzero(kx_secret_.data(), kx_secret_.size()); }

SessionKeys ClientHandshake::Finish(const ServerAnswer& answer, const PublicKey* expected_server) const {
  if (answer.client_id != hello_.client_id ||
      sodium_memcmp(answer.client_nonce.data(), hello_.client_nonce.data(), kNonceBytes) != 0) {
    throw AuthError("server answer: not an answer to this hello (client id or nonce differ)");
  }
  if (expected_server != nullptr && !(answer.server_key == *expected_server)) {
    throw AuthError("server answer: signed by " + answer.server_key.Fingerprint() + ", expected server key " +
                    expected_server->Fingerprint());
  }
  if (!VerifySignature(answer.server_key, answer.SignedBytes(hello_), answer.signature)) {
    throw AuthError("server answer: bad signature of server key " + answer.server_key.Fingerprint());
  }
  std::array<std::uint8_t, 32> rx{}, tx{};
  if (crypto_kx_client_session_keys(rx.data(), tx.data(), hello_.client_kx.data(), kx_secret_.data(),
                                    answer.server_kx.data()) != 0) {
    throw AuthError("server answer: unusable key-exchange key");
  }
  SessionKeys keys = DeriveKeys(hello_, answer, tx, rx);
  sodium_memzero(rx.data(), rx.size());
  sodium_memzero(tx.data(), tx.size());
  return keys;
}

Mac ComputeMac(std::span<const std::uint8_t, 32> key, std::int64_t session_id,
               std::span<const std::uint8_t> bytes) {
  static_assert(kMacBytes >= crypto_generichash_BYTES_MIN);
  std::array<std::uint8_t, 8> sid{};
  for (std::size_t i = 0; i < 8; ++i)
    sid[i] = static_cast<std::uint8_t>(static_cast<std::uint64_t>(session_id) >> (8 * i));
  Mac mac{};
  crypto_generichash_state st;
  crypto_generichash_init(&st, key.data(), key.size(), mac.size());
  crypto_generichash_update(&st, sid.data(), sid.size());
  crypto_generichash_update(&st, bytes.data(), bytes.size());
  crypto_generichash_final(&st, mac.data(), mac.size());
  return mac;
}

bool VerifyMac(std::span<const std::uint8_t, 32> key, std::int64_t session_id,
               std::span<const std::uint8_t> bytes, const Mac& mac) {
  const Mac expected = ComputeMac(key, session_id, bytes);
  return sodium_memcmp(expected.data(), mac.data(), kMacBytes) == 0;
}

// --- ServerAuthenticator -----------------------------------------------------

ServerAuthenticator::ServerAuthenticator(KeyPair identity, const AccessList& access, Nonce instance_nonce)
    : identity_(std::move(identity)), access_(access), instance_nonce_(instance_nonce) {
  InitSodium();
}

std::string DescribeHello(const ClientHello& hello) {
  return "hello of client " + std::to_string(hello.client_id) + " (key " + hello.client_key.Fingerprint() +
         ")";
}

HelloResult ServerAuthenticator::Answer(const ClientHello& hello) const {
  const auto refuse = [&](const std::string& why) { return HelloRefused{DescribeHello(hello) + ": " + why}; };
  const AccessEntry* client = Client(hello);
  if (client == nullptr) return refuse("key not in the access list");
  if (!VerifySignature(hello.client_key, hello.SignedBytes(), hello.signature))
    return refuse("bad signature");
  if (!ClientIdBelongsTo(hello.client_id, hello.client_key)) {
    return refuse("client id " + std::to_string(hello.client_id) +
                  " is not one of this key's (keyed mode: a client id's high bits come from its key; "
                  "robotalk::KeyedClientId, docs/security.md)");
  }
  HelloAccepted out;
  out.client = client;
  ServerAnswer& answer = out.answer;
  answer.client_id = hello.client_id;
  answer.client_nonce = hello.client_nonce;
  answer.instance_nonce = instance_nonce_;
  answer.server_nonce = RandomNonce();
  answer.server_key = identity_.public_key;
  std::array<std::uint8_t, 32> kx_secret{}, rx{}, tx{};
  crypto_kx_keypair(answer.server_kx.data(), kx_secret.data());
  const int kx = crypto_kx_server_session_keys(rx.data(), tx.data(), answer.server_kx.data(),
                                               kx_secret.data(), hello.client_kx.data());
  sodium_memzero(kx_secret.data(), kx_secret.size());
  if (kx != 0) return refuse("unusable key-exchange key");
  answer.signature = Sign(identity_, answer.SignedBytes(hello));
  // The server receives on the client's tx key: (tx_client, rx_client) = (rx, tx) here.
  out.keys = DeriveKeys(hello, answer, rx, tx);
  sodium_memzero(rx.data(), rx.size());
  sodium_memzero(tx.data(), tx.size());
  return out;
}

}  // namespace robotalk
