// The server's one table of client sessions, keyed by session id: every
// session opened by a HELLO, in open mode (the server picks a random session
// id) and in keyed mode (the libsodium handshake of session_auth.h binds the
// client id to a listed key and derives the session's MAC keys), with all
// it holds (session.h): robot, client id, key binding, sequence window, reply
// cache, playbacks, expiry. Every REQUEST names its session; a package of a
// session this server instance did not open (a restart, an expired session,
// an lcm-logplayer replay of a recorded one) is never executed. In keyed mode
// every package must also carry a valid MAC, and the sender's rights on that
// robot are checked (docs/security.md).
//
// A session is pending until its first accepted package (keyed: its first
// authentic one, proof that its client holds the ephemeral secret); only
// then does it replace its client's previous session on that robot, taking
// over its client-side state (Session::Continue). A replayed hello opens
// nothing and never displaces a live session. Bounds: max_sessions in all;
// pending sessions 2 per client id and (keyed) 4 per key, the oldest
// dropped; (keyed) 64 client ids per key; the nonces of the last
// kRememberedNonces closed sessions (a hello carrying one is a replay).
//
// Thread safety: none; the ServerDaemon's thread uses it (RobotSessions too,
// on that thread).
#pragma once

#include "robotalk/access_list.h"
#include "robotalk/clock.h"
#include "robotalk/keys.h"
#include "robotalk/request.h"
#include "robotalk/server.h"
#include "robotalk/session_auth.h"
#include "session.h"

#include <cstdint>
#include <deque>
#include <map>
#include <memory>
#include <random>
#include <set>
#include <span>
#include <string>
#include <vector>

namespace robotalk {

struct SessionTableOptions {
  /// Keyed mode: the server's identity and the access list (both or neither).
  std::shared_ptr<const KeyPair> identity;
  std::shared_ptr<const AccessList> access;
  /// Most sessions, live and pending, in the whole server (--max-sessions).
  std::size_t max_sessions = kDefaultMaxSessions;
  /// A session opened by a hello but never used is closed after this long.
  Duration pending_timeout = std::chrono::seconds(10);
  /// Keyed: pending sessions of one key (the oldest is dropped).
  std::size_t max_pending_per_key = 4;
  /// Keyed: client ids one key may hold at once.
  std::size_t max_client_ids_per_key = 64;
};

/// The server's refusal counts: the SERVER_COUNTERS query's values and the log's.
struct SessionCounters {
  std::uint64_t hellos = 0;
  std::uint64_t hellos_refused = 0;
  std::uint64_t unknown_session = 0;  ///< packages naming no session of this instance and robot
  std::uint64_t wrong_client = 0;     ///< packages naming another client's session
  std::uint64_t forged = 0;           ///< keyed: the MAC did not verify
  std::uint64_t replayed = 0;         ///< keyed: an authentic package with a sequence <= 0
  std::uint64_t rights_refused = 0;   ///< keyed: the key may not do that on that robot
  std::uint64_t hello_repeats = 0;    ///< a hello answered before (lost answer, or replayed): answered again

  /// Names and values, in a fixed order (the reply's values and message).
  std::vector<std::pair<const char*, double>> Table() const;
};

class SessionTable {
 public:
  /// @throw Error when only one of identity and access is given.
  SessionTable(std::int64_t server_id, SessionTableOptions options);
  ~SessionTable();
  SessionTable(const SessionTable&) = delete;
  SessionTable& operator=(const SessionTable&) = delete;

  static constexpr std::size_t kRememberedNonces = 4096;

  /// Registers a robot; returns its number (the `robot` of the calls below).
  /// `replies`: the reply cache bounds of its sessions.
  int AddRobot(const std::string& name, ReplyCache::Limits replies);
  const std::string& robot_name(int robot) const { return robots_[static_cast<std::size_t>(robot)].name; }

  bool keyed() const { return auth_ != nullptr; }
  /// Keyed mode: this server instance's nonce (it signs broadcasts too); nullptr in open mode.
  const Nonce* instance_nonce() const { return auth_ ? &auth_->instance_nonce() : nullptr; }

  /// Answers a hello for `robot`: opens a pending session, answers a hello
  /// seen before with its answer, or refuses (session_id 0 and the reason;
  /// counted). Never throws for bad input.
  HelloAnswer Answer(int robot, const Hello& hello, TimePoint now);

  enum class Verdict {
    kAccepted,        ///< run it
    kDuplicate,       ///< seen before in the session's window: re-send its replies, run nothing
    kUnknownSession,  ///< answer SESSION_UNKNOWN: the client must say hello again
    kRefused,         ///< forged, sequence <= 0 (keyed), wrong client: drop silently
    kNoRights,        ///< authentic, but the key lacks the rights: answer every item ERROR `why`
  };
  struct Admission {
    Verdict verdict = Verdict::kUnknownSession;
    std::string who;  ///< for logs: "client 503d..." or "'alice' (rt:1a2b:..., client 503d...)"
    std::string why;  ///< kRefused / kNoRights: what was wrong; kDuplicate: the rights it lacks, or ""
  };
  /// Checks one decoded package of `robot` against its session (client id,
  /// keyed: MAC, sequence > 0, rights; the window's duplicates) and makes its
  /// session live. `bytes` are the package as received (the MAC is their
  /// last 16 bytes). Going live stamps the session's first package (or takes
  /// the previous session's state, Session::Continue); every later refresh
  /// is RobotSessions::Handle's.
  Admission Admit(int robot, const Request& request, std::span<const std::uint8_t> bytes, TimePoint now);

  /// The live session of `client_id` on `robot`, or nullptr.
  Session* Find(int robot, std::int64_t client_id);
  const Session* Find(int robot, std::int64_t client_id) const;
  /// The live session of `client_id` on `robot`, opened now (open mode, no
  /// hello) when there is none: RobotSessions used without a ServerDaemon.
  Session& FindOrOpen(int robot, std::int64_t client_id, TimePoint now);
  /// The live sessions of `robot`, by client id.
  const std::map<std::int64_t, Session*>& live(int robot) const {
    return robots_[static_cast<std::size_t>(robot)].live;
  }
  /// Live sessions of `robot` its robot serves (Session::active).
  std::size_t active(int robot) const;
  /// The live session id of `client_id` on `robot`, or 0.
  std::int64_t LiveSession(int robot, std::int64_t client_id) const;
  /// Keyed mode: writes the MAC of an encoded reply package of `session_id`
  /// into its last 16 bytes. Returns false (nothing written) when the session
  /// is gone: the reply must not be sent. Open mode: true, nothing to do.
  bool Seal(std::int64_t session_id, std::vector<std::uint8_t>& bytes) const;

  /// The one expiry: removes `robot`'s sessions pending for pending_timeout
  /// and its live ones silent (Session::last_heard) for longer than
  /// `live_timeout`; returns them (the caller stops what they moved).
  std::vector<Session> Expire(int robot, TimePoint now, Duration live_timeout);

  const SessionCounters& counters() const { return counters_; }
  std::size_t session_count() const { return sessions_.size(); }

 private:
  struct Robot {
    std::string name;
    ReplyCache::Limits replies;
    std::map<std::int64_t, Session*> live;  // client id -> its live session
  };
  struct Binding {
    PublicKey key;
    std::size_t sessions = 0;
  };
  using Iterator = std::map<std::int64_t, Session>::iterator;
  HelloAnswer Refuse(HelloAnswer answer, const std::string& why);
  // The keyed checks and answer; a refusal's text, or "" with `answer` filled.
  std::string Handshake(const Hello& hello, HelloAnswer& answer, Session::Keyed& keyed);
  void MakeRoom(std::int64_t client_id, const PublicKey* key, TimePoint now);
  void GoLive(Session& s, TimePoint now);
  std::int64_t NewOpenSessionId();
  Session& Open(int robot, std::int64_t session_id, std::int64_t client_id, TimePoint now);
  // Takes a session out of the table and its indexes.
  Session Remove(Iterator it);

  const std::int64_t server_id_;
  const SessionTableOptions options_;
  std::unique_ptr<ServerAuthenticator> auth_;  // keyed mode only
  std::vector<Robot> robots_;
  std::map<std::int64_t, Session> sessions_;  // by session id
  std::map<Nonce, std::int64_t> by_nonce_;    // hello nonce -> session id, open sessions
  std::map<std::int64_t, Binding> bindings_;  // keyed: client id -> key
  std::set<Nonce> used_nonces_;               // keyed: nonces of closed sessions (the last kRememberedNonces)
  std::deque<Nonce> used_order_;              // the same, oldest first
  std::uint64_t opened_ = 0;
  std::mt19937_64 rng_;
  SessionCounters counters_;
};

}  // namespace robotalk
