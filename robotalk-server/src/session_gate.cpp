#include "session_gate.h"

#include "robotalk/channels.h"
#include "robotalk/error.h"

namespace robotalk {
namespace {

std::string Client(std::int64_t id) { return "client " + Hex64(static_cast<std::uint64_t>(id)); }

}  // namespace

std::vector<std::pair<const char*, double>> GateCounters::Table() const {
  return {{"hellos", static_cast<double>(hellos)},
          {"hellos_refused", static_cast<double>(hellos_refused)},
          {"unknown_session", static_cast<double>(unknown_session)},
          {"wrong_client", static_cast<double>(wrong_client)},
          {"forged", static_cast<double>(forged)},
          {"replayed", static_cast<double>(replayed)},
          {"rights_refused", static_cast<double>(rights_refused)},
          {"hello_repeats", static_cast<double>(hello_repeats)}};
}

SessionGate::SessionGate(std::int64_t server_id, SessionGateOptions options)
    : server_id_(server_id), options_(std::move(options)), rng_(std::random_device{}()) {
  if ((options_.identity != nullptr) != (options_.access != nullptr)) {
    throw Error(
        "SessionGate: keyed mode needs both the server's key (--key) and the access list (--clients)");
  }
  if (options_.identity) {
    ServerAuthenticator::Limits limits;
    limits.max_sessions = options_.max_sessions;
    auth_ = std::make_unique<ServerAuthenticator>(KeyPair::FromSeed(options_.identity->secret_key.seed()),
                                                  *options_.access, RandomNonce(), limits);
  }
}

SessionGate::~SessionGate() = default;

std::int64_t SessionGate::NewOpenSessionId() {
  for (;;) {
    // Positive and below 2^53, so that a client whose numbers are doubles
    // (Lua 5.2, JavaScript) holds it exactly.
    const auto id = static_cast<std::int64_t>(rng_() >> 11);
    if (id != 0 && !sessions_.count(id)) return id;
  }
}

HelloAnswer SessionGate::Refuse(HelloAnswer answer, const std::string& why) {
  ++counters_.hellos_refused;
  answer.session_id = 0;
  answer.refusal = why;
  return answer;
}

HelloAnswer SessionGate::Answer(const std::string& robot, const Hello& hello, TimePoint now) {
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
  if (!keyed()) {
    // The same hello again (its answer was lost, or a replay): the same
    // answer; nothing new is opened. (Keyed: the authenticator recognises it.)
    for (const auto& [id, s] : sessions_) {
      if (s.client_id == hello.body.client_id && s.nonce == hello.body.client_nonce && s.robot == robot) {
        ++counters_.hello_repeats;
        answer.session_id = id;
        return answer;
      }
    }
  }
  // A keyed hello seen before is answered (or refused) by the authenticator
  // without opening anything: it never makes room at another's expense.
  if (!keyed() || !auth_->KnowsNonce(hello.body.client_nonce)) {
    MakeRoom(hello.body.client_id, now);
    if (sessions_.size() >= options_.max_sessions) {
      return Refuse(answer, "the server has " + std::to_string(options_.max_sessions) +
                                " sessions in use already (the --max-sessions bound); try again later");
    }
  }
  Session session{
      robot, hello.body.client_id, false, now, now, Client(hello.body.client_id), hello.body.client_nonce};
  if (keyed()) {
    try {
      answer.body = auth_->Handshake(hello.body, now);
    } catch (const AuthError& e) {
      EraseClosedByAuthenticator();
      return Refuse(answer, e.what());
    }
    EraseClosedByAuthenticator();
    answer.session_id = SessionId(hello.body, answer.body);
    if (sessions_.count(answer.session_id)) {  // a hello answered before: nothing new
      ++counters_.hello_repeats;
      return answer;
    }
    const AccessEntry* entry = options_.access->Find(hello.body.client_key);
    session.who = "'" + (entry ? entry->name : std::string("?")) + "' (" +
                  hello.body.client_key.Fingerprint() + ", " + Client(hello.body.client_id) + ")";
  } else {
    answer.session_id = NewOpenSessionId();
  }
  sessions_[answer.session_id] = std::move(session);
  return answer;
}

// Pending sessions (opened by a hello, never used) are bounded per source
// (client id: kMaxPendingPerClient, the oldest dropped) and may use the
// whole table only while nothing else needs it: when the table is full, the
// oldest pending session makes room. Live sessions are never dropped here.
// Keyed mode adds the authenticator's bound per key.
void SessionGate::MakeRoom(std::int64_t client_id, TimePoint now) {
  if (sessions_.size() >= options_.max_sessions) Expire(now);
  std::vector<std::int64_t> mine;  // this client id's pending sessions, by id
  std::int64_t oldest = 0;
  for (const auto& [id, s] : sessions_) {
    if (s.live) continue;
    if (s.client_id == client_id) mine.push_back(id);
    if (oldest == 0 || s.opened < sessions_.at(oldest).opened) oldest = id;
  }
  if (mine.size() >= kMaxPendingPerClient) {
    std::int64_t first = mine.front();
    for (std::int64_t id : mine) {
      if (sessions_.at(id).opened < sessions_.at(first).opened) first = id;
    }
    Erase(first);
  } else if (sessions_.size() >= options_.max_sessions && oldest != 0) {
    Erase(oldest);
  }
}

void SessionGate::EraseClosedByAuthenticator() {
  if (!auth_) return;
  for (std::int64_t id : auth_->TakeClosed()) Erase(id);
}

SessionGate::Admission SessionGate::Admit(const std::string& robot, const Request& r,
                                          std::span<const std::uint8_t> bytes, TimePoint now) {
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
  if (keyed()) {
    const auto verified = auth_->Verify(r.session_id, r.client_id, r.sequence, MacCoveredBytes(bytes), r.mac);
    EraseClosedByAuthenticator();  // the client id's previous session, replaced by this one
    switch (verified.verdict) {
      case PackageVerdict::kAccepted:
        break;
      case PackageVerdict::kDuplicate:
        out.verdict = Verdict::kDuplicate;
        out.why = CheckRights(*options_.access, *verified.client, robot, r);  // "" = had the rights
        return out;
      case PackageVerdict::kUnknownSession:  // the authenticator closed it (a newer live session)
        ++counters_.unknown_session;
        Erase(r.session_id);
        out.verdict = Verdict::kUnknownSession;
        return out;
      case PackageVerdict::kForged:
        ++counters_.forged;
        out.verdict = Verdict::kRefused;
        out.why = "MAC does not verify (forged or corrupted)";
        return out;
      default:
        ++counters_.replayed;
        out.verdict = Verdict::kRefused;
        out.why = std::string("replay: ") + ToString(verified.verdict);
        return out;
    }
    if (const std::string bad = CheckRights(*options_.access, *verified.client, robot, r); !bad.empty()) {
      ++counters_.rights_refused;
      out.verdict = Verdict::kNoRights;
      out.why = bad;
      // Fall through to going live: the package was authentic.
    }
  }
  if (!s.live) {
    // First accepted package: the session becomes the client's live one and
    // ends the previous (the client said hello again, e.g. after a restart).
    s.live = true;
    const auto key = std::make_pair(robot, r.client_id);
    if (const auto prev = live_.find(key); prev != live_.end() && prev->second != r.session_id) {
      Erase(prev->second);
    }
    live_[key] = r.session_id;
  }
  s.last_used = now;
  if (out.verdict != Verdict::kNoRights) out.verdict = Verdict::kAccepted;
  return out;
}

std::int64_t SessionGate::LiveSession(const std::string& robot, std::int64_t client_id) const {
  const auto it = live_.find({robot, client_id});
  return it == live_.end() ? 0 : it->second;
}

bool SessionGate::Seal(std::int64_t session_id, std::vector<std::uint8_t>& bytes) const {
  if (!keyed()) return true;
  if (!sessions_.count(session_id)) return false;
  try {
    WriteMacField(bytes, auth_->SealReply(session_id, MacCoveredBytes(bytes)));
  } catch (const AuthError&) {
    return false;  // closed by the authenticator
  }
  return true;
}

void SessionGate::Erase(std::int64_t session_id) {
  const auto it = sessions_.find(session_id);
  if (it == sessions_.end()) return;
  const auto key = std::make_pair(it->second.robot, it->second.client_id);
  if (const auto live = live_.find(key); live != live_.end() && live->second == session_id) live_.erase(live);
  if (auth_) auth_->Close(session_id);
  sessions_.erase(it);
}

void SessionGate::Close(const std::string& robot, std::int64_t client_id) {
  std::vector<std::int64_t> ids;
  for (const auto& [id, s] : sessions_) {
    if (s.robot == robot && s.client_id == client_id && s.live) ids.push_back(id);
  }
  for (std::int64_t id : ids) Erase(id);
}

std::size_t SessionGate::Expire(TimePoint now) {
  std::vector<std::int64_t> ids;
  for (const auto& [id, s] : sessions_) {
    if ((!s.live && now - s.opened >= options_.pending_timeout) ||
        (s.live && now - s.last_used >= options_.idle_timeout)) {
      ids.push_back(id);
    }
  }
  for (std::int64_t id : ids) Erase(id);
  if (auth_) auth_->ExpirePending(now, options_.pending_timeout);
  EraseClosedByAuthenticator();
  return ids.size();
}

}  // namespace robotalk
