#include "session_table.h"

#include "robotalk/channels.h"
#include "robotalk/error.h"

#include <algorithm>

namespace robotalk {
namespace {

std::string Client(std::int64_t id) { return "client " + Hex64(static_cast<std::uint64_t>(id)); }

}  // namespace

std::vector<std::pair<const char*, double>> SessionCounters::Table() const {
  return {{"hellos", static_cast<double>(hellos)},
          {"hellos_refused", static_cast<double>(hellos_refused)},
          {"unknown_session", static_cast<double>(unknown_session)},
          {"wrong_client", static_cast<double>(wrong_client)},
          {"forged", static_cast<double>(forged)},
          {"replayed", static_cast<double>(replayed)},
          {"rights_refused", static_cast<double>(rights_refused)},
          {"hello_repeats", static_cast<double>(hello_repeats)}};
}

SessionTable::SessionTable(std::int64_t server_id, SessionTableOptions options)
    : server_id_(server_id), options_(std::move(options)), rng_(std::random_device{}()) {
  if ((options_.identity != nullptr) != (options_.access != nullptr)) {
    throw Error(
        "SessionTable: keyed mode needs both the server's key (--key) and the access list (--clients)");
  }
  if (options_.identity) {
    auth_ = std::make_unique<ServerAuthenticator>(KeyPair::FromSeed(options_.identity->secret_key.seed()),
                                                  *options_.access, RandomNonce());
  }
}

SessionTable::~SessionTable() = default;

int SessionTable::AddRobot(const std::string& name, ReplyCache::Limits replies) {
  robots_.push_back(Robot{name, replies, {}});
  return static_cast<int>(robots_.size() - 1);
}

std::int64_t SessionTable::NewOpenSessionId() {
  for (;;) {
    // Positive and below 2^53, so that a client whose numbers are doubles
    // (Lua 5.2, JavaScript) holds it exactly.
    const auto id = static_cast<std::int64_t>(rng_() >> 11);
    if (id != 0 && !sessions_.count(id)) return id;
  }
}

HelloAnswer SessionTable::Refuse(HelloAnswer answer, const std::string& why) {
  ++counters_.hellos_refused;
  answer.session_id = 0;
  answer.refusal = why;
  return answer;
}

HelloAnswer SessionTable::Answer(int robot, const Hello& hello, TimePoint now) {
  ++counters_.hellos;
  HelloAnswer answer;
  answer.server_id = server_id_;
  answer.keyed = keyed();
  answer.body.client_id = hello.body.client_id;
  answer.body.client_nonce = hello.body.client_nonce;
  if (keyed() != hello.keyed) {
    return Refuse(answer, keyed() ? "this server runs in keyed mode: give the client a key (--key FILE or "
                                    "ROBOTALK_KEY; docs/security.md)"
                                  : "this server runs in open mode and takes no keys");
  }
  // The cheap map lookup first: a hello from an unlisted key costs no
  // signature verification (~50 us), so a flood of them costs little.
  if (keyed() && auth_->Client(hello.body) == nullptr) {
    return Refuse(answer, DescribeHello(hello.body) + ": key not in the access list");
  }
  // The same hello again: its client repeats it until an answer arrives, or
  // someone replays a recording. Either way: the same answer, nothing new
  // opened, no signature to check (the bytes are the ones verified).
  if (const auto seen = by_nonce_.find(hello.body.client_nonce); seen != by_nonce_.end()) {
    const Session& s = sessions_.at(seen->second);
    if (s.keyed) {
      if (!(s.keyed->hello == hello.body)) {
        return Refuse(answer, DescribeHello(hello.body) + ": hello nonce already used by another hello");
      }
      ++counters_.hello_repeats;
      answer.session_id = s.session_id;
      answer.body = s.keyed->answer;
      return answer;
    }
    if (s.client_id == hello.body.client_id && s.robot == robot) {
      ++counters_.hello_repeats;
      answer.session_id = s.session_id;
      return answer;
    }
  }
  if (keyed() && used_nonces_.contains(hello.body.client_nonce)) {
    return Refuse(answer,
                  DescribeHello(hello.body) +
                      ": replayed hello (its nonce opened a session of this server instance already)");
  }
  std::optional<Session::Keyed> keys;
  if (keyed()) {
    keys.emplace();
    if (std::string why = Handshake(hello, answer, *keys); !why.empty()) return Refuse(answer, why);
  }
  // Only a hello that passed every check may drop another pending session.
  MakeRoom(hello.body.client_id, keys ? &hello.body.client_key : nullptr, now);
  if (sessions_.size() >= options_.max_sessions) {
    return Refuse(answer, "the server has " + std::to_string(options_.max_sessions) +
                              " sessions in use already (the --max-sessions bound); try again later");
  }
  if (keys) {
    answer.session_id = keys->keys.session_id;
    if (sessions_.count(answer.session_id)) {  // 2^-63: never in practice
      return Refuse(answer, DescribeHello(hello.body) + ": session id collision; retry");
    }
  } else {
    answer.session_id = NewOpenSessionId();
  }
  Session& s = Open(robot, answer.session_id, hello.body.client_id, now);
  s.hello_nonce = hello.body.client_nonce;
  by_nonce_.try_emplace(s.hello_nonce, s.session_id);  // taken: a nonce reused by another open-mode client
  if (keys) {
    auto& binding = bindings_[s.client_id];
    binding.key = hello.body.client_key;
    ++binding.sessions;
    s.who = "'" + keys->client->name + "' (" + hello.body.client_key.Fingerprint() + ", " +
            Client(s.client_id) + ")";
    s.keyed = std::move(keys);
  }
  return answer;
}

std::string SessionTable::Handshake(const Hello& hello, HelloAnswer& answer, Session::Keyed& keyed) {
  HelloResult result = auth_->Answer(hello.body);
  if (const auto* refused = std::get_if<HelloRefused>(&result)) return refused->why;
  auto& accepted = std::get<HelloAccepted>(result);
  const ClientHello& h = hello.body;
  if (const auto bound = bindings_.find(h.client_id); bound != bindings_.end()) {
    if (!(bound->second.key == h.client_key)) {
      return DescribeHello(h) + ": client id is bound to another key (" + bound->second.key.Fingerprint() +
             ")";
    }
  } else {
    const auto ids = std::count_if(bindings_.begin(), bindings_.end(),
                                   [&](const auto& b) { return b.second.key == h.client_key; });
    if (static_cast<std::size_t>(ids) >= options_.max_client_ids_per_key) {
      return DescribeHello(h) + ": '" + accepted.client->name + "' already holds " + std::to_string(ids) +
             " client ids (limit max_client_ids_per_key)";
    }
  }
  answer.body = accepted.answer;
  keyed.keys = accepted.keys;
  keyed.client = accepted.client;
  keyed.hello = h;
  keyed.answer = accepted.answer;
  return "";
}

// Pending sessions (opened by a hello, never used) are bounded per source
// (client id: 2, the oldest dropped; keyed: per key, max_pending_per_key)
// and may use the whole table only while nothing else needs it: when the
// table is full, the expired ones go, then the oldest pending session makes
// room. Live sessions are never dropped here.
void SessionTable::MakeRoom(std::int64_t client_id, const PublicKey* key, TimePoint now) {
  constexpr std::size_t kMaxPendingPerClient = 2;  // LCM does not tell the server a datagram's source
  if (sessions_.size() >= options_.max_sessions) {
    for (auto it = sessions_.begin(); it != sessions_.end();) {
      const auto next = std::next(it);
      if (!it->second.live && now - it->second.created >= options_.pending_timeout) Remove(it);
      it = next;
    }
  }
  const auto drop_oldest = [&](auto mine, std::size_t bound) {
    std::size_t n = 0;
    auto oldest = sessions_.end();
    for (auto it = sessions_.begin(); it != sessions_.end(); ++it) {
      if (it->second.live || !mine(it->second)) continue;
      ++n;
      if (oldest == sessions_.end() || it->second.order < oldest->second.order) oldest = it;
    }
    if (n >= bound && oldest != sessions_.end()) {
      Remove(oldest);
      return true;
    }
    return false;
  };
  if (key != nullptr) {
    drop_oldest([&](const Session& s) { return s.keyed && s.keyed->hello.client_key == *key; },
                options_.max_pending_per_key);
  }
  if (!drop_oldest([&](const Session& s) { return s.client_id == client_id; }, kMaxPendingPerClient) &&
      sessions_.size() >= options_.max_sessions) {
    drop_oldest([](const Session&) { return true; }, 1);
  }
}

Session& SessionTable::Open(int robot, std::int64_t session_id, std::int64_t client_id, TimePoint now) {
  Session& s =
      sessions_.try_emplace(session_id, client_id, now, robots_[static_cast<std::size_t>(robot)].replies)
          .first->second;
  s.session_id = session_id;
  s.robot = robot;
  s.order = ++opened_;
  s.who = Client(client_id);
  return s;
}

Session& SessionTable::FindOrOpen(int robot, std::int64_t client_id, TimePoint now) {
  if (Session* s = Find(robot, client_id)) return *s;
  Session& s = Open(robot, NewOpenSessionId(), client_id, now);
  GoLive(s, now);
  return s;
}

// The first accepted package: the session becomes the client's live one on
// its robot and ends the previous (the client said hello again, e.g. after a
// lost session), taking over its client-side state.
void SessionTable::GoLive(Session& s, TimePoint now) {
  s.live = true;
  s.last_heard = now;
  Session*& slot = robots_[static_cast<std::size_t>(s.robot)].live[s.client_id];
  Session* previous = slot;
  slot = &s;
  if (previous != nullptr && previous != &s) s.Continue(Remove(sessions_.find(previous->session_id)));
}

SessionTable::Admission SessionTable::Admit(int robot, const Request& r, std::span<const std::uint8_t> bytes,
                                            TimePoint now) {
  Admission out;
  out.who = Client(r.client_id);
  const auto it = sessions_.find(r.session_id);
  if (r.session_id == 0 || it == sessions_.end() || it->second.robot != robot) {
    ++counters_.unknown_session;
    out.verdict = Verdict::kUnknownSession;
    return out;
  }
  Session& s = it->second;
  if (s.client_id != r.client_id) {
    ++counters_.wrong_client;
    out.verdict = Verdict::kRefused;
    out.why = "package of " + Client(r.client_id) + " names the session of " + Client(s.client_id);
    return out;
  }
  out.who = s.who;
  std::string rights;
  if (s.keyed) {
    // Nothing changes unless the MAC is right.
    if (!ServerAuthenticator::Verify(s.keyed->keys, MacCoveredBytes(bytes), r.mac)) {
      ++counters_.forged;
      out.verdict = Verdict::kRefused;
      out.why = "MAC does not verify (forged or corrupted)";
      return out;
    }
    if (r.sequence <= 0) {
      ++counters_.replayed;
      out.verdict = Verdict::kRefused;
      out.why = "replay: sequence not positive";
      return out;
    }
    rights = CheckRights(auth_->access(), *s.keyed->client, robot_name(robot), r);
  }
  if (!s.live) GoLive(s, now);  // authentic: it now replaces the client's previous session
  // (A sequence <= 0 is no package of a client's: RobotSessions answers the
  // codec's header error, not "seen before".)
  if (r.sequence > 0 && s.seen.Check(r.sequence) == SequenceWindow::Verdict::kDuplicate) {
    // A retransmission (or a replay inside the session): never run or refresh.
    out.verdict = Verdict::kDuplicate;
    out.why = rights;  // "" = had the rights
    return out;
  }
  if (!rights.empty()) {
    ++counters_.rights_refused;
    out.verdict = Verdict::kNoRights;
    out.why = rights;
    return out;
  }
  out.verdict = Verdict::kAccepted;
  return out;
}

Session* SessionTable::Find(int robot, std::int64_t client_id) {
  auto& live = robots_[static_cast<std::size_t>(robot)].live;
  const auto it = live.find(client_id);
  return it == live.end() ? nullptr : it->second;
}

const Session* SessionTable::Find(int robot, std::int64_t client_id) const {
  return const_cast<SessionTable*>(this)->Find(robot, client_id);
}

std::size_t SessionTable::active(int robot) const {
  const auto& live = robots_[static_cast<std::size_t>(robot)].live;
  return static_cast<std::size_t>(
      std::count_if(live.begin(), live.end(), [](const auto& e) { return e.second->active; }));
}

std::int64_t SessionTable::LiveSession(int robot, std::int64_t client_id) const {
  const Session* s = Find(robot, client_id);
  return s == nullptr ? 0 : s->session_id;
}

bool SessionTable::Seal(std::int64_t session_id, std::vector<std::uint8_t>& bytes) const {
  if (!keyed()) return true;
  const auto it = sessions_.find(session_id);
  if (it == sessions_.end() || !it->second.keyed) return false;
  WriteMacField(bytes, ServerAuthenticator::Seal(it->second.keyed->keys, MacCoveredBytes(bytes)));
  return true;
}

Session SessionTable::Remove(Iterator it) {
  const Session& s = it->second;
  auto& live = robots_[static_cast<std::size_t>(s.robot)].live;
  if (const auto l = live.find(s.client_id); l != live.end() && l->second == &s) live.erase(l);
  if (const auto n = by_nonce_.find(s.hello_nonce); n != by_nonce_.end() && n->second == s.session_id) {
    by_nonce_.erase(n);
  }
  if (s.keyed) {
    if (const auto b = bindings_.find(s.client_id); b != bindings_.end() && --b->second.sessions == 0) {
      bindings_.erase(b);
    }
    // Its hello must not open a session again: remember its nonce (bounded).
    if (used_nonces_.insert(s.hello_nonce).second) used_order_.push_back(s.hello_nonce);
    while (used_order_.size() > kRememberedNonces) {
      used_nonces_.erase(used_order_.front());
      used_order_.pop_front();
    }
  }
  return std::move(sessions_.extract(it).mapped());
}

std::vector<Session> SessionTable::Expire(int robot, TimePoint now, Duration live_timeout) {
  std::vector<Session> expired;
  for (auto it = sessions_.begin(); it != sessions_.end();) {
    const auto next = std::next(it);
    const Session& s = it->second;
    if (s.robot == robot &&
        (s.live ? now - s.last_heard > live_timeout : now - s.created >= options_.pending_timeout)) {
      if (s.live) {
        expired.push_back(Remove(it));
      } else {
        Remove(it);
      }
    }
    it = next;
  }
  return expired;
}

}  // namespace robotalk
