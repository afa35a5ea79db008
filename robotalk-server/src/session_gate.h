// Who may talk to this server: the sessions opened by HELLO, in open mode
// (the server picks a random session id) and in keyed mode (the libsodium
// handshake of session_auth.h binds the client id to a listed key and derives
// the session's MAC keys). Every REQUEST names its session; a package of a
// session this server instance did not open (a restart, an expired session,
// an lcm-logplayer replay of a recorded one) is never executed. In keyed mode
// every package must also carry a valid MAC and a new sequence number, and
// the sender's rights on that robot are checked (docs/security.md).
//
// Thread safety: none; the ServerDaemon's thread uses it.
#pragma once

#include "robotalk/access_list.h"
#include "robotalk/clock.h"
#include "robotalk/keys.h"
#include "robotalk/request.h"
#include "robotalk/session_auth.h"

#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <random>
#include <span>
#include <string>
#include <vector>

namespace robotalk {

struct SessionGateOptions {
  /// Keyed mode: the server's identity and the access list (both or neither).
  std::shared_ptr<const KeyPair> identity;
  std::shared_ptr<const AccessList> access;
  /// Most sessions, open and pending, in the whole server.
  std::size_t max_sessions = 1024;
  /// A session opened by a hello but never used is closed after this long.
  Duration pending_timeout = std::chrono::seconds(10);
  /// A used session that has sent nothing accepted for this long is closed
  /// (sessions normally end sooner, with their RobotSessions state; this
  /// catches those that never had one, e.g. every package refused for rights).
  Duration idle_timeout = std::chrono::seconds(60);
};

/// Refusal counts, for the SERVER_COUNTERS query and the log.
struct GateCounters {
  std::uint64_t hellos = 0;
  std::uint64_t hellos_refused = 0;
  std::uint64_t unknown_session = 0;  ///< packages naming no session of this instance and robot
  std::uint64_t wrong_client = 0;     ///< packages naming another client's session
  std::uint64_t forged = 0;           ///< keyed: the MAC did not verify
  std::uint64_t replayed = 0;         ///< keyed: duplicate or too old in the replay window
  std::uint64_t rights_refused = 0;   ///< keyed: the key may not do that on that robot
  std::uint64_t hello_repeats = 0;    ///< a hello answered before (lost answer, or replayed): answered again

  /// Names and values, in a fixed order (the reply's values and message).
  std::vector<std::pair<const char*, double>> Table() const;
};

class SessionGate {
 public:
  SessionGate(std::int64_t server_id, SessionGateOptions options);
  ~SessionGate();
  SessionGate(const SessionGate&) = delete;
  SessionGate& operator=(const SessionGate&) = delete;

  bool keyed() const { return auth_ != nullptr; }
  /// Keyed mode: this server instance's nonce (it signs broadcasts too); nullptr in open mode.
  const Nonce* instance_nonce() const { return auth_ ? &auth_->instance_nonce() : nullptr; }

  /// Answers a hello for `robot`. Never throws for bad input: a refused
  /// hello gets an answer with session_id 0 and the reason (counted).
  HelloAnswer Answer(const std::string& robot, const Hello& hello, TimePoint now);

  enum class Verdict {
    kAccepted,        ///< run it
    kDuplicate,       ///< keyed: authentic retransmission: re-send its replies, run nothing
    kUnknownSession,  ///< answer SESSION_UNKNOWN: the client must say hello again
    kRefused,         ///< forged, replayed too late, wrong client: drop silently
    kNoRights,        ///< authentic, but the key lacks the rights: answer every item ERROR `why`
  };
  struct Admission {
    Verdict verdict = Verdict::kUnknownSession;
    std::string who;  ///< for logs: "client 503d..." or "'alice' (rt:1a2b:..., client 503d...)"
    std::string why;  ///< kRefused / kNoRights: what was wrong; kDuplicate: the rights it lacks, or ""
  };
  /// Checks one decoded package of `robot` against its session. `bytes` are
  /// the package as received (the MAC is their last 16 bytes).
  Admission Admit(const std::string& robot, const Request& request, std::span<const std::uint8_t> bytes,
                  TimePoint now);

  /// The live session of `client_id` on `robot`, or 0.
  std::int64_t LiveSession(const std::string& robot, std::int64_t client_id) const;
  /// Keyed mode: writes the MAC of an encoded reply package of `session_id`
  /// into its last 16 bytes. Returns false (nothing written) when the session
  /// is gone: the reply must not be sent. Open mode: true, nothing to do.
  bool Seal(std::int64_t session_id, std::vector<std::uint8_t>& bytes) const;

  /// Ends `client_id`'s sessions on `robot` (its RobotSessions state expired):
  /// later packages of them are SESSION_UNKNOWN.
  void Close(const std::string& robot, std::int64_t client_id);
  /// Closes sessions opened by a hello and never used, and used ones idle
  /// for `idle_timeout`. Returns how many.
  std::size_t Expire(TimePoint now);

  const GateCounters& counters() const { return counters_; }
  std::size_t session_count() const { return sessions_.size(); }

 private:
  struct Session {
    std::string robot;
    std::int64_t client_id = 0;
    bool live = false;  ///< used by at least one accepted package
    TimePoint opened{};
    TimePoint last_used{};  ///< the last accepted (or rights-refused) package
    std::string who;
    Nonce nonce{};  ///< of the hello that opened it
  };
  /// Most pending sessions of one client id (the "source": LCM does not tell
  /// the server a datagram's address); a new hello drops the oldest.
  static constexpr std::size_t kMaxPendingPerClient = 2;
  void MakeRoom(std::int64_t client_id, TimePoint now);
  void EraseClosedByAuthenticator();
  HelloAnswer Refuse(HelloAnswer answer, const std::string& why);
  std::int64_t NewOpenSessionId();
  void Erase(std::int64_t session_id);

  const std::int64_t server_id_;
  SessionGateOptions options_;
  std::unique_ptr<ServerAuthenticator> auth_;                          // keyed mode only
  std::map<std::int64_t, Session> sessions_;                           // by session id
  std::map<std::pair<std::string, std::int64_t>, std::int64_t> live_;  // (robot, client) -> session
  std::mt19937_64 rng_;
  GateCounters counters_;
};

}  // namespace robotalk
