// Handshake, MAC and replay window (session_auth.h). Only libsodium does
// cryptography here; this file fixes the byte strings it is applied to.
#include "robotalk/session_auth.h"

#include <sodium.h>

#include <algorithm>
#include <iterator>
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
bool SameHello(const ClientHello& a, const ClientHello& b) {
  return a.client_key == b.client_key && a.client_id == b.client_id && a.client_nonce == b.client_nonce &&
         a.client_kx == b.client_kx && a.signature == b.signature;
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

ReplayWindow::Verdict ReplayWindow::Check(std::int64_t sequence) const {
  if (sequence <= 0) return Verdict::kInvalid;
  if (sequence > highest_) return Verdict::kNew;
  if (highest_ - sequence >= kWindow) return Verdict::kTooOld;
  const auto bit = static_cast<std::uint64_t>(sequence % kWindow);
  return (seen_[bit / 64] >> (bit % 64)) & 1U ? Verdict::kDuplicate : Verdict::kNew;
}

ReplayWindow::Verdict ReplayWindow::Accept(std::int64_t sequence) {
  const Verdict v = Check(sequence);
  if (v != Verdict::kNew) return v;
  if (sequence > highest_) {
    // Clear the bits of the numbers the window slides over (highest_, sequence].
    const std::int64_t clear = std::min<std::int64_t>(sequence - highest_, kWindow);
    for (std::int64_t s = sequence - clear + 1; s <= sequence; ++s) {
      const auto bit = static_cast<std::uint64_t>(s % kWindow);
      seen_[bit / 64] &= ~(std::uint64_t{1} << (bit % 64));
    }
    highest_ = sequence;
  }
  const auto bit = static_cast<std::uint64_t>(sequence % kWindow);
  seen_[bit / 64] |= std::uint64_t{1} << (bit % 64);
  return v;
}

const char* ToString(PackageVerdict verdict) {
  switch (verdict) {
    case PackageVerdict::kAccepted:
      return "accepted";
    case PackageVerdict::kUnknownSession:
      return "unknown session";
    case PackageVerdict::kWrongClient:
      return "session of another client";
    case PackageVerdict::kForged:
      return "bad MAC";
    case PackageVerdict::kDuplicate:
      return "duplicate";
    case PackageVerdict::kTooOld:
      return "sequence below the replay window";
    case PackageVerdict::kInvalidSequence:
      return "sequence not positive";
  }
  return "?";
}

// --- ServerAuthenticator -----------------------------------------------------

ServerAuthenticator::ServerAuthenticator(KeyPair identity, const AccessList& access, Nonce instance_nonce,
                                         Limits limits)
    : identity_(std::move(identity)), access_(access), instance_nonce_(instance_nonce), limits_(limits) {
  InitSodium();
}

void ServerAuthenticator::Refuse(const std::string& why) {
  ++counters_.handshakes_refused;
  throw AuthError(why);
}

ServerAnswer ServerAuthenticator::Handshake(const ClientHello& hello, TimePoint now) {
  const std::string who =
      "hello of client " + std::to_string(hello.client_id) + " (key " + hello.client_key.Fingerprint() + ")";
  // The cheap map lookup first: a hello from an unlisted key costs no
  // signature verification (~50 us), so a flood of them costs little.
  const AccessEntry* client = access_.Find(hello.client_key);
  if (client == nullptr) Refuse(who + ": key not in the access list");
  if (const auto seen = by_nonce_.find(hello.client_nonce); seen != by_nonce_.end()) {
    // The same hello again: its client repeats it until an answer arrives,
    // or someone replays a recording. Either way: the same answer, nothing
    // new opened, no signature to check (the bytes are the ones verified).
    const Session& s = sessions_.at(seen->second);
    if (!SameHello(s.hello, hello)) Refuse(who + ": hello nonce already used by another hello");
    ++counters_.hello_repeats;
    return s.answer;
  }
  if (used_nonces_.contains(hello.client_nonce)) {
    Refuse(who + ": replayed hello (its nonce opened a session of this server instance already)");
  }
  if (!VerifySignature(hello.client_key, hello.SignedBytes(), hello.signature)) {
    Refuse(who + ": bad signature");
  }
  if (!ClientIdBelongsTo(hello.client_id, hello.client_key)) {
    Refuse(who + ": client id " + std::to_string(hello.client_id) +
           " is not one of this key's (keyed mode: " +
           "a client id's high bits come from its key; robotalk::KeyedClientId, docs/security.md)");
  }
  const auto bound = bindings_.find(hello.client_id);
  if (bound != bindings_.end() && !(bound->second.key == hello.client_key)) {
    Refuse(who + ": client id is bound to another key (" + bound->second.key.Fingerprint() + ")");
  }
  if (bound == bindings_.end()) {
    const auto ids = std::count_if(bindings_.begin(), bindings_.end(),
                                   [&](const auto& b) { return b.second.key == hello.client_key; });
    if (static_cast<std::size_t>(ids) >= limits_.max_client_ids_per_key) {
      Refuse(who + ": '" + client->name + "' already holds " + std::to_string(ids) +
             " client ids (limit max_client_ids_per_key)");
    }
  }
  DropOldestPending(hello.client_key);
  if (sessions_.size() >= limits_.max_sessions) {
    Refuse(who + ": " + std::to_string(sessions_.size()) + " sessions open (limit max_sessions)");
  }

  ServerAnswer answer;
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
  if (kx != 0) Refuse(who + ": unusable key-exchange key");
  answer.signature = Sign(identity_, answer.SignedBytes(hello));
  // The server receives on the client's tx key: (tx_client, rx_client) = (rx, tx) here.
  Session session{DeriveKeys(hello, answer, rx, tx),
                  hello.client_id,
                  client,
                  false,
                  ++counters_.handshakes,
                  now,
                  {},
                  hello,
                  answer};
  sodium_memzero(rx.data(), rx.size());
  sodium_memzero(tx.data(), tx.size());
  const std::int64_t id = session.keys.session_id;
  if (sessions_.contains(id)) Refuse(who + ": session id collision; retry");  // 2^-63: never in practice
  sessions_.emplace(id, std::move(session));
  by_nonce_[hello.client_nonce] = id;
  auto& binding = bindings_[hello.client_id];
  binding.key = hello.client_key;
  ++binding.sessions;
  return answer;
}

void ServerAuthenticator::DropOldestPending(const PublicKey& key) {
  std::size_t pending = 0;
  auto oldest = sessions_.end();
  for (auto it = sessions_.begin(); it != sessions_.end(); ++it) {
    if (it->second.live || !(it->second.client->key == key)) continue;
    ++pending;
    if (oldest == sessions_.end() || it->second.opened < oldest->second.opened) oldest = it;
  }
  if (pending >= limits_.max_pending_per_key && oldest != sessions_.end()) Erase(oldest);
}

void ServerAuthenticator::Erase(std::map<std::int64_t, Session>::iterator it, bool report) {
  const std::int64_t client_id = it->second.client_id;
  if (const auto live = live_.find(client_id); live != live_.end() && live->second == it->first)
    live_.erase(live);
  if (const auto b = bindings_.find(client_id); b != bindings_.end() && --b->second.sessions == 0) {
    bindings_.erase(b);
  }
  // Its hello must not open a session again: remember its nonce (bounded).
  const Nonce& nonce = it->second.hello.client_nonce;
  by_nonce_.erase(nonce);
  if (used_nonces_.insert(nonce).second) used_order_.push_back(nonce);
  while (used_order_.size() > kRememberedNonces) {
    used_nonces_.erase(used_order_.front());
    used_order_.pop_front();
  }
  if (report) closed_.push_back(it->first);  // closed by the authenticator itself: TakeClosed() says so
  sessions_.erase(it);
}

ServerAuthenticator::Verified ServerAuthenticator::Verify(std::int64_t session_id, std::int64_t client_id,
                                                          std::int64_t sequence,
                                                          std::span<const std::uint8_t> bytes,
                                                          const Mac& mac) {
  const auto it = sessions_.find(session_id);
  if (it == sessions_.end()) {
    ++counters_.unknown_session;
    return {PackageVerdict::kUnknownSession, nullptr};
  }
  Session& s = it->second;
  if (s.client_id != client_id) {
    ++counters_.wrong_client;
    return {PackageVerdict::kWrongClient, nullptr};
  }
  if (!VerifyMac(s.keys.client_to_server, session_id, bytes, mac)) {
    ++counters_.forged;
    return {PackageVerdict::kForged, nullptr};
  }
  switch (s.window.Accept(sequence)) {
    case ReplayWindow::Verdict::kNew:
      break;
    case ReplayWindow::Verdict::kDuplicate:
      ++counters_.duplicate;
      return {PackageVerdict::kDuplicate, s.client};
    case ReplayWindow::Verdict::kTooOld:
      ++counters_.too_old;
      return {PackageVerdict::kTooOld, s.client};
    case ReplayWindow::Verdict::kInvalid:
      ++counters_.too_old;
      return {PackageVerdict::kInvalidSequence, s.client};
  }
  if (!s.live) {
    // First authentic package: this session proves its client holds the
    // ephemeral secret; it now replaces the client id's previous session.
    s.live = true;
    if (const auto prev = live_.find(client_id); prev != live_.end() && prev->second != session_id) {
      const auto old = sessions_.find(prev->second);
      if (old != sessions_.end()) Erase(old);
    }
    live_[client_id] = session_id;
  }
  return {PackageVerdict::kAccepted, s.client};
}

Mac ServerAuthenticator::SealReply(std::int64_t session_id, std::span<const std::uint8_t> bytes) const {
  const auto it = sessions_.find(session_id);
  if (it == sessions_.end()) throw AuthError("SealReply: unknown session " + std::to_string(session_id));
  return ComputeMac(it->second.keys.server_to_client, session_id, bytes);
}

std::size_t ServerAuthenticator::ExpirePending(TimePoint now, Duration max_age) {
  std::size_t closed = 0;
  for (auto it = sessions_.begin(); it != sessions_.end();) {
    const auto next = std::next(it);
    if (!it->second.live && now - it->second.opened_at > max_age) {
      Erase(it);
      ++closed;
    }
    it = next;
  }
  return closed;
}

void ServerAuthenticator::Close(std::int64_t session_id) {
  if (const auto it = sessions_.find(session_id); it != sessions_.end()) {
    Erase(it, /*report=*/false);  // the caller closed it: it knows
  }
}

std::int64_t ServerAuthenticator::LiveSession(std::int64_t client_id) const {
  const auto it = live_.find(client_id);
  return it == live_.end() ? 0 : it->second;
}

}  // namespace robotalk
