// Authenticated sessions as pure maths: the handshake that binds a client id
// to a key and derives session keys, and the per-package MAC. No session
// state (the server's session table keeps it, with the replay window). No I/O, no clock of its own (times are
// passed in), no LCM: the ServerDaemon / RobotClient carry the values (wire proposal in docs/security.md).
// Every primitive is libsodium's.
//
//   client                                           server (instance nonce I, fresh per start)
//   ClientHello{key C, client id, nonce Nc, X25519 eph. Ec, sig_C}  ->
//                                                    checks sig_C, ACL, client-id binding
//      <-  ServerAnswer{client id, Nc, I, Ns, X25519 eph. Es, key S, sig_S over hello+answer}
//   both: (rx, tx) = crypto_kx(Ec, Es); th = BLAKE2b(hello || answer)
//         c2s = BLAKE2b(key tx_client, "c2s" || th), s2c = BLAKE2b(key rx_client, "s2c" || th)
//         session id = first 8 bytes of BLAKE2b("sid" || th) (positive, non-zero)
//   each package: mac = BLAKE2b-128(key c2s, session id || package bytes)
//
// A recorded package carries a session id and a MAC under a key that depend
// on I and on ephemeral secrets never sent: after a restart (new I) or in
// another session it is refused; inside its session the server's sequence
// window refuses it as a duplicate.
//
// Thread safety: ClientHandshake: one thread; ServerAuthenticator and the
// free functions: any thread.
#pragma once

#include "robotalk/access_list.h"
#include "robotalk/clock.h"
#include "robotalk/error.h"
#include "robotalk/keys.h"

#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <utility>
#include <variant>
#include <vector>

namespace robotalk {

/// A hello or answer is forged, malformed or does not match: the handshake fails.
class AuthError : public Error {
 public:
  using Error::Error;
};

constexpr std::size_t kNonceBytes = 16;
constexpr std::size_t kMacBytes = 16;  // 128-bit tag: forging one takes ~2^128 tries
using Nonce = std::array<std::uint8_t, kNonceBytes>;
using Mac = std::array<std::uint8_t, kMacBytes>;
using KxKey = std::array<std::uint8_t, 32>;  // X25519 public key (crypto_kx)
using Signature = std::array<std::uint8_t, 64>;

/// kNonceBytes from libsodium's CSPRNG.
Nonce RandomNonce();

/// Client -> server, first message of a session.
struct ClientHello {
  PublicKey client_key;
  std::int64_t client_id = 0;
  Nonce client_nonce{};
  KxKey client_kx{};      ///< ephemeral, one per session
  Signature signature{};  ///< by client_key over SignedBytes()

  /// "robotalk-hello-v1" || key || client id (8 bytes LE) || nonce || kx: the
  /// signed bytes, independent of the wire encoding.
  std::vector<std::uint8_t> SignedBytes() const;
  /// Every field equal: the same hello (sent again, or replayed).
  friend bool operator==(const ClientHello&, const ClientHello&) = default;
};

/// Server -> client, second message.
struct ServerAnswer {
  std::int64_t client_id = 0;  ///< echoed
  Nonce client_nonce{};        ///< echoed
  Nonce instance_nonce{};      ///< fresh per server start
  Nonce server_nonce{};        ///< fresh per answer
  KxKey server_kx{};           ///< ephemeral, one per session
  PublicKey server_key;
  Signature signature{};  ///< by server_key over SignedBytes(hello)

  /// "robotalk-answer-v1" || hello.SignedBytes() || the fields above but the
  /// signature: the server signs the whole transcript.
  std::vector<std::uint8_t> SignedBytes(const ClientHello& hello) const;
};

/// The keys of one session, one per direction. Bytes wiped on destruction.
struct SessionKeys {
  std::int64_t session_id = 0;
  std::array<std::uint8_t, 32> client_to_server{};
  std::array<std::uint8_t, 32> server_to_client{};
  Nonce instance_nonce{};  ///< the server instance this session belongs to

  SessionKeys() = default;
  SessionKeys(const SessionKeys&) = default;
  SessionKeys& operator=(const SessionKeys&) = default;
  ~SessionKeys();
};

/// The client's side of one handshake. Holds its ephemeral secret until destroyed.
class ClientHandshake {
 public:
  /// Makes a fresh ephemeral key and nonce and signs the hello.
  ClientHandshake(const KeyPair& identity, std::int64_t client_id);
  ~ClientHandshake();
  ClientHandshake(const ClientHandshake&) = delete;
  ClientHandshake& operator=(const ClientHandshake&) = delete;

  const ClientHello& hello() const { return hello_; }
  /// Checks the answer (echoes, server signature; and, when `expected_server`
  /// is not null, that the server is that key) and derives the session keys.
  /// @throw AuthError naming what did not match.
  SessionKeys Finish(const ServerAnswer& answer, const PublicKey* expected_server = nullptr) const;

 private:
  ClientHello hello_;
  std::array<std::uint8_t, 32> kx_secret_{};
};

/// Keyed mode: the client ids a key may use. A client id belongs to a key
/// when its bits 62..32 are the first 31 bits of BLAKE2b-256("robotalk-client-id-v1"
/// || key); bits 31..0 are the client's own choice (random, non-zero), so one
/// key may run several clients at once and no other key can claim one of its
/// ids, on this server instance or the next (docs/security.md, Binding).
/// `low` = 0 is made 1. The result is positive and non-zero.
std::int64_t KeyedClientId(const PublicKey& key, std::uint32_t low);
/// True when `client_id` is one of `key`'s (KeyedClientId with any `low`).
bool ClientIdBelongsTo(std::int64_t client_id, const PublicKey& key);

/// The session id both sides derive from a hello and its answer. Not a
/// secret (it is a hash of public values); the session keys are.
std::int64_t SessionId(const ClientHello& hello, const ServerAnswer& answer);

/// A MAC of `bytes` in session `session_id` under `key` (keyed BLAKE2b-128).
Mac ComputeMac(std::span<const std::uint8_t, 32> key, std::int64_t session_id,
               std::span<const std::uint8_t> bytes);
/// Constant-time check of ComputeMac (sodium_memcmp).
bool VerifyMac(std::span<const std::uint8_t, 32> key, std::int64_t session_id,
               std::span<const std::uint8_t> bytes, const Mac& mac);

/// A hello the server accepts: the answer to send, the session's keys and
/// the access-list entry of the hello's key.
struct HelloAccepted {
  ServerAnswer answer;
  SessionKeys keys;
  const AccessEntry* client = nullptr;
};
/// A hello the server refuses, and why (sent back to the client in the answer).
struct HelloRefused {
  std::string why;
};
using HelloResult = std::variant<HelloAccepted, HelloRefused>;

/// The server's side of the handshake and of the per-package MACs, as pure
/// functions of one server instance (its key, access list and instance
/// nonce). It keeps no session: the server's session table does (which
/// hellos it answered, which client id is bound to which key, the bounds).
/// Thread safety: const after construction; safe from any thread.
class ServerAuthenticator {
 public:
  /// `instance_nonce`: RandomNonce() at every server start. `access` must
  /// outlive this object.
  ServerAuthenticator(KeyPair identity, const AccessList& access, Nonce instance_nonce);
  /// The list is kept by reference: a temporary would dangle.
  ServerAuthenticator(KeyPair, const AccessList&&, Nonce) = delete;

  /// The access-list entry of the hello's key, or nullptr (a map lookup:
  /// the cheap check, before any signature is verified).
  const AccessEntry* Client(const ClientHello& hello) const { return access_.Find(hello.client_key); }
  /// Checks `hello` on its own (key in the access list, signature, the
  /// client id one of the key's: ClientIdBelongsTo) and answers it with a
  /// fresh server nonce and ephemeral key; or refuses it, saying why. Never
  /// throws for bad input.
  HelloResult Answer(const ClientHello& hello) const;
  /// Constant-time check of a package's MAC under the session's client -> server key.
  static bool Verify(const SessionKeys& keys, std::span<const std::uint8_t> bytes, const Mac& mac) {
    return VerifyMac(keys.client_to_server, keys.session_id, bytes, mac);
  }
  /// MAC of a reply package of the session (server -> client key).
  static Mac Seal(const SessionKeys& keys, std::span<const std::uint8_t> bytes) {
    return ComputeMac(keys.server_to_client, keys.session_id, bytes);
  }

  const Nonce& instance_nonce() const { return instance_nonce_; }
  const PublicKey& public_key() const { return identity_.public_key; }
  const AccessList& access() const { return access_; }

 private:
  KeyPair identity_;
  const AccessList& access_;
  Nonce instance_nonce_;
};

/// "client 00000000000a11ce (key rt:...)": names a hello's sender in a refusal.
std::string DescribeHello(const ClientHello& hello);

}  // namespace robotalk
