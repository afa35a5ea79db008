// Authenticated sessions as pure maths: the handshake that binds a client id
// to a key and derives session keys, the per-package MAC, and the replay
// window. No I/O, no clock of its own (times are passed in), no LCM: the
// ServerDaemon / RobotClient carry the values (wire proposal in
// docs/security.md). Every primitive is libsodium's.
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
// another session it is refused; inside its session the replay window
// refuses it as a duplicate.
//
// Thread safety: none of these classes locks; use each from one thread (the
// ServerDaemon's) or guard it. Free functions are thread-safe.
#pragma once

#include "robotalk/access_list.h"
#include "robotalk/clock.h"
#include "robotalk/error.h"
#include "robotalk/keys.h"

#include <array>
#include <cstdint>
#include <deque>
#include <map>
#include <set>
#include <span>
#include <string>
#include <utility>
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

/// Which sequence numbers of one session were accepted: a bitmap of the last
/// kWindow numbers below the highest (RFC 6479 style, fixed memory).
class ReplayWindow {
 public:
  enum class Verdict { kNew, kDuplicate, kTooOld, kInvalid };
  static constexpr std::int64_t kWindow = 1024;

  /// What Accept would say; changes nothing. kInvalid: sequence <= 0.
  Verdict Check(std::int64_t sequence) const;
  /// Records `sequence` if new; returns Check's verdict.
  Verdict Accept(std::int64_t sequence);
  std::int64_t highest() const { return highest_; }

 private:
  std::int64_t highest_ = 0;
  std::array<std::uint64_t, kWindow / 64>
      seen_{};  // bit (s mod kWindow) = s seen, for s in (highest-kWindow, highest]
};

/// Why a package was or was not accepted.
enum class PackageVerdict {
  kAccepted,        ///< authentic and new: decode and execute it
  kUnknownSession,  ///< no such session here (old server instance, expired, made up)
  kWrongClient,     ///< the session belongs to another client id
  kForged,          ///< the MAC does not match
  kDuplicate,       ///< authentic, already accepted: re-send its replies, never execute or refresh
  kTooOld,          ///< authentic, below the replay window
  kInvalidSequence  ///< authentic, sequence <= 0
};
const char* ToString(PackageVerdict verdict);

/// Counts of refusals, for a query and the (rate-limited) log.
struct AuthCounters {
  std::uint64_t handshakes = 0;
  std::uint64_t handshakes_refused = 0;
  std::uint64_t unknown_session = 0;
  std::uint64_t wrong_client = 0;
  std::uint64_t forged = 0;
  std::uint64_t duplicate = 0;
  std::uint64_t too_old = 0;        ///< and sequences <= 0
  std::uint64_t hello_repeats = 0;  ///< a hello answered before (lost answer or replay): answered again
};

/// The server's authentication state for one server instance: answers
/// hellos, binds client ids to keys, keeps the sessions, verifies packages.
/// A new session stays pending until its first authentic package (proof that
/// its client holds the ephemeral secret: a replayed hello opens nothing and
/// never displaces a live session); only then does it replace the client
/// id's previous session. Pending sessions are bounded per key and in all.
/// A hello is recognised by its client nonce: the same hello again (its
/// client repeats it until answered, or a recording is replayed) gets the
/// same answer and opens nothing new, without a signature check; a hello
/// whose nonce belonged to a session of this instance that has since closed
/// is refused as a replay (the last kRememberedNonces closed sessions).
class ServerAuthenticator {
 public:
  struct Limits {
    std::size_t max_sessions = 1024;          ///< live + pending, whole server
    std::size_t max_pending_per_key = 4;      ///< the oldest pending one is dropped
    std::size_t max_client_ids_per_key = 64;  ///< client ids one key may bind at once
  };
  /// `instance_nonce`: RandomNonce() at every server start. `access` must
  /// outlive this object.
  ServerAuthenticator(KeyPair identity, const AccessList& access, Nonce instance_nonce, Limits limits);
  ServerAuthenticator(KeyPair identity, const AccessList& access, Nonce instance_nonce)
      : ServerAuthenticator(std::move(identity), access, instance_nonce, Limits{}) {}
  /// The list is kept by reference: a temporary would dangle.
  ServerAuthenticator(KeyPair, const AccessList&&, Nonce, Limits) = delete;
  ServerAuthenticator(KeyPair, const AccessList&&, Nonce) = delete;

  static constexpr std::size_t kRememberedNonces = 4096;
  /// Answers `hello` and opens a pending session, or answers a hello seen
  /// before (same nonce and bytes, its session still open) with its answer.
  /// @throw AuthError (counted) when the signature is bad, the key is not in
  ///   the access list, the client id is not one of the key's
  ///   (ClientIdBelongsTo) or is bound to another key, the nonce was used
  ///   (a replay), or a bound is hit.
  /// `now`: when it arrived (any one clock; used only by ExpirePending).
  ServerAnswer Handshake(const ClientHello& hello, TimePoint now);

  /// Closes the pending sessions opened before `now - max_age` (hellos whose
  /// client never sent an authentic package: lost answers, replayed hellos);
  /// returns how many. Call it with the session timeout, e.g. from the
  /// watchdog. Live sessions are the caller's to Close.
  std::size_t ExpirePending(TimePoint now, Duration max_age);

  struct Verified {
    PackageVerdict verdict = PackageVerdict::kUnknownSession;
    const AccessEntry* client = nullptr;  ///< set unless kUnknownSession / kWrongClient / kForged
  };
  /// Verifies one package: session, client id, MAC (constant time), replay
  /// window, in that order; nothing changes unless the MAC is right. `bytes`
  /// are the encoded package with its MAC field zeroed; `sequence` and
  /// `client_id` come from those bytes. Counts every refusal.
  Verified Verify(std::int64_t session_id, std::int64_t client_id, std::int64_t sequence,
                  std::span<const std::uint8_t> bytes, const Mac& mac);

  /// MAC of a reply package of `session_id` (server -> client key).
  /// @throw AuthError for an unknown session.
  Mac SealReply(std::int64_t session_id, std::span<const std::uint8_t> bytes) const;

  /// Ends a session (expired or closed); its client id binding goes with
  /// its last session.
  void Close(std::int64_t session_id);

  /// The live session of `client_id`, or 0.
  std::int64_t LiveSession(std::int64_t client_id) const;
  /// True when a hello with `client_nonce` was answered by this instance
  /// (its session open, or among the remembered closed ones): Handshake
  /// would answer it again or refuse it as a replay, opening nothing.
  bool KnowsNonce(const Nonce& client_nonce) const {
    return by_nonce_.contains(client_nonce) || used_nonces_.contains(client_nonce);
  }
  /// The sessions this object closed on its own since the last call (a
  /// pending one dropped for a bound, replaced by a newer live one, expired):
  /// a caller that keeps its own table of sessions erases them too.
  std::vector<std::int64_t> TakeClosed() { return std::exchange(closed_, {}); }
  std::size_t session_count() const { return sessions_.size(); }
  const AuthCounters& counters() const { return counters_; }
  const Nonce& instance_nonce() const { return instance_nonce_; }
  const PublicKey& public_key() const { return identity_.public_key; }

 private:
  struct Session {
    SessionKeys keys;
    std::int64_t client_id = 0;
    const AccessEntry* client = nullptr;
    bool live = false;
    std::uint64_t opened = 0;  // handshake counter at opening: orders pending sessions
    TimePoint opened_at{};
    ReplayWindow window;
    ClientHello hello;    // as received: a repeat must equal it
    ServerAnswer answer;  // sent again to a repeat
  };
  struct Binding {
    PublicKey key;
    std::size_t sessions = 0;
  };
  [[noreturn]] void Refuse(const std::string& why);
  void DropOldestPending(const PublicKey& key);
  // Forgets a session; with `report`, TakeClosed() lists it (the gate did not close it).
  void Erase(std::map<std::int64_t, Session>::iterator it, bool report = true);

  KeyPair identity_;
  const AccessList& access_;
  Nonce instance_nonce_;
  Limits limits_;
  std::map<std::int64_t, Session> sessions_;   // by session id
  std::map<std::int64_t, Binding> bindings_;   // client id -> key
  std::map<std::int64_t, std::int64_t> live_;  // client id -> live session id
  std::map<Nonce, std::int64_t> by_nonce_;     // client nonce -> session id, open sessions
  std::set<Nonce> used_nonces_;                // nonces of closed sessions (the last kRememberedNonces)
  std::deque<Nonce> used_order_;               // the same, oldest first
  std::vector<std::int64_t> closed_;           // TakeClosed()
  AuthCounters counters_;
};

}  // namespace robotalk
