// RobotClient::Impl's session (docs/protocol.md, Sessions): the hello and its
// answer, sealing packages and checking replies in keyed mode, and what
// happens when the server no longer knows the session (a restart, an expiry).
#include "client_impl.h"
#include "robotalk/broadcast_signature.h"
#include "robotalk/channels.h"
#include "robotalk/config_message.h"
#include "robotalk/known_servers.h"
#include "robotalk/log_writer.h"
#include "robotalk/request.h"

#include <cstdio>
#include <cstdlib>
#include <random>

namespace robotalk {
namespace {

constexpr Duration kHelloRepeat = std::chrono::milliseconds(250);
constexpr std::size_t kMaxPackageBytes = 60000;  // docs/protocol.md "Limits"

std::string SecondsText(Duration d) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g s", ToSeconds(d));
  return buf;
}

}  // namespace

void RobotClient::Impl::LoadKeys() {
  std::string key_file = options_.key_file;
  if (key_file.empty()) {
    if (const char* env = std::getenv("ROBOTALK_KEY"); env != nullptr) key_file = env;
  }
  try {
    if (!key_file.empty()) identity_ = ReadSecretKeyFile(key_file);
    std::optional<PublicKey> server_key;
    if (!options_.server_key_file.empty()) server_key = ReadPublicKeyFile(options_.server_key_file).key;
    if (identity_) {
      trust_.emplace(server_key, options_.server_key_file,
                     options_.known_servers_file.empty()
                         ? DefaultKnownServersFile()
                         : std::filesystem::path(options_.known_servers_file));
    }
  } catch (const Error& e) {
    throw ClientError(std::string("RobotClient: ") + e.what());
  }
  if (!options_.server_key_file.empty() && !identity_) {
    throw ClientError("RobotClient: a server key to pin (" + options_.server_key_file +
                      ") needs a client key too (--key FILE or ROBOTALK_KEY)");
  }
}

std::vector<std::uint8_t> RobotClient::Impl::DueHello(TimePoint now) {
  if (!hello_due_ || robot_.empty() || now < next_hello_) return {};
  next_hello_ = now + kHelloRepeat;
  Hello hello;
  if (identity_) {
    if (!handshake_) handshake_ = std::make_unique<ClientHandshake>(*identity_, client_id_);
    hello.keyed = true;
    hello.body = handshake_->hello();
  } else {
    hello.body.client_id = client_id_;
    hello.body.client_nonce = hello_nonce_;
  }
  hello_nonce_ = hello.body.client_nonce;
  return EncodeHello(hello);
}

void RobotClient::Impl::OnHelloAnswer(std::span<const std::uint8_t> bytes) {
  HelloAnswer answer;
  try {
    answer = DecodeHelloAnswer(bytes);
  } catch (const ProtocolError&) {
    std::lock_guard lock(mu_);
    ++stats_.malformed_packages;
    return;
  }
  std::optional<PublicKey> first_use;  // keyed: a server key to pin before the session is used
  std::string robot;
  {
    std::lock_guard lock(mu_);
    robot = robot_;
    if (!hello_due_ || answer.body.client_id != client_id_ || answer.body.client_nonce != hello_nonce_) {
      return;  // another client's, or an answer to an earlier hello
    }
    if (answer.session_id == 0) {
      hello_refusal_ =
          "robot '" + robot_ + "' refused this client's hello: " + EscapeControls(answer.refusal);
      hello_due_ = false;
      handshake_.reset();  // the next hello is a new one
    } else if (identity_) {
      try {
        if (!answer.keyed) throw AuthError("the server answered in open mode, this client has a key");
        // Signed by the key it names, for this hello (the whole transcript).
        SessionKeys keys = handshake_->Finish(answer.body);
        if (keys.session_id != answer.session_id) throw AuthError("the answer's session id does not match");
        if (std::string why = trust_->Check(answer.body.server_key); !why.empty()) {
          // Not the server this client trusts (an impersonator, or another
          // server of that name): wait on for the trusted one; WaitSession
          // says why if none answers.
          trust_error_ = std::move(why);
          ++stats_.servers_refused;
          return;
        }
        if (trust_->first_use()) first_use = answer.body.server_key;
        session_keys_ = std::move(keys);
      } catch (const AuthError& e) {
        hello_refusal_ = "robot '" + robot_ + "': the server's answer failed authentication: " + e.what();
        hello_due_ = false;
      }
    }
  }
  if (first_use) {
    // Trust on first use: pinned before the session is used (file I/O, so
    // outside the lock; only this thread handles answers).
    std::string error;
    try {
      trust_->WritePin(*first_use);
    } catch (const KeyError& e) {
      error = "cannot pin the server key of robot '" + robot + "': " + e.what();
    }
    std::lock_guard lock(mu_);
    if (!error.empty()) {
      hello_refusal_ = error;
      hello_due_ = false;
      session_keys_.reset();
    } else {
      trust_->Trust(*first_use);
    }
  }
  {
    std::lock_guard lock(mu_);
    if (hello_refusal_.empty() && hello_due_) {
      if (server_id_ != 0 && answer.server_id != server_id_) resync_ = true;
      session_id_ = answer.session_id;
      server_id_ = answer.server_id;
      session_opened_at_ = clock_.Now();
      hello_due_ = false;
      handshake_.reset();
      trust_error_.clear();
      ++stats_.sessions_opened;
    }
  }
  cv_.notify_all();
  WakeDaemon();  // the re-sync, if any
}

void RobotClient::Impl::WaitSession(std::unique_lock<std::mutex>& lock) {
  if (session_id_ != 0) return;
  const auto deadline =
      std::chrono::steady_clock::now() +
      std::chrono::duration_cast<std::chrono::steady_clock::duration>(options_.connect_timeout);
  cv_.wait_until(lock, deadline, [&] { return session_id_ != 0 || !hello_refusal_.empty(); });
  if (!hello_refusal_.empty()) {
    // Reported to this call; the next one says hello again (a refusal may
    // not last: a bound, an access list the operator fixes).
    const std::string why = std::exchange(hello_refusal_, {});
    hello_due_ = true;
    next_hello_ = clock_.Now();
    throw ClientError("RobotClient: " + why);
  }
  if (session_id_ == 0 && !trust_error_.empty()) throw ClientError("RobotClient: " + trust_error_);
  if (session_id_ == 0) {
    throw TimeoutError(
        "RobotClient: no answer to HELLO from robot '" + robot_ + "' within " +
        SecondsText(options_.connect_timeout) +
        " (is a server offering it? every process on one bus must use the same traffic layout: "
        "docs/protocol.md, Channels)");
  }
}

std::vector<std::uint8_t> RobotClient::Impl::EncodeSealed(const Request& request) const {
  std::vector<std::uint8_t> bytes = EncodeRequest(request);
  if (bytes.size() > kMaxPackageBytes) {
    throw ClientError("RobotClient: a package of " +
                      std::to_string(request.commands.size() + request.queries.size()) + " items would be " +
                      std::to_string(bytes.size()) + " bytes, over the " + std::to_string(kMaxPackageBytes) +
                      "-byte limit; send fewer per batch");
  }
  // Keyed mode: the MAC covers every encoded byte before it (docs/security.md).
  if (session_keys_) {
    WriteMacField(bytes, ComputeMac(session_keys_->client_to_server, session_id_, MacCoveredBytes(bytes)));
  }
  return bytes;
}

std::vector<CommandId> RobotClient::Impl::LoseSession(TimePoint now) {
  std::vector<CommandId> lost = outstanding_.Clear();
  clock_packages_.clear();
  session_id_ = 0;
  session_keys_.reset();
  hello_due_ = true;
  next_hello_ = now;
  for (std::random_device rd; auto& b : hello_nonce_) b = static_cast<std::uint8_t>(rd());
  ++stats_.sessions_lost;
  return lost;
}

bool RobotClient::Impl::AcceptReplyPackage(const ReplyBatch& batch, std::span<const std::uint8_t> bytes,
                                           TimePoint now, std::vector<CommandId>& lost) {
  if (batch.session_status == SessionStatus::kUnknown) {
    // Unsealed by nature (the server has no key for it): keyed, it must
    // carry the trusted server key's signature, of any instance (a restarted
    // server's is what it is for); else it is another server's (a fake one
    // that answered first would end every session the real one opens) or
    // a forger's, refused and counted. Open mode believes it for the live
    // session: there a forger can make the client say hello again; it could
    // as well drop every package (docs/security.md, availability).
    // Its panic answer counts in open mode, where nothing is sealed; in keyed
    // mode only as a refusal for want of a session (RobotClient::Panic then
    // says hello and sends the panic again), never as a panic taken.
    if (identity_) {
      const std::optional<PublicKey> key = trust_ ? trust_->trusted() : std::nullopt;
      if (!key || VerifyBroadcast(ReplyChannel(robot_, client_id_), bytes, *key, nullptr) !=
                      BroadcastVerdict::kAuthentic) {
        ++stats_.replies_refused;
        return false;
      }
    }
    if (!identity_ || batch.panic == PanicStatus::kRefused) NotePanicAnswer(batch);
    if (session_id_ == 0 || batch.session_id != session_id_) return false;
    lost = LoseSession(now);  // each lost item's failure says why
    return false;
  }
  if (session_id_ == 0 || batch.session_id != session_id_) return false;  // an old session's
  if (session_keys_ &&
      !VerifyMac(session_keys_->server_to_client, session_id_, MacCoveredBytes(bytes), batch.mac)) {
    ++stats_.replies_refused;
    return false;
  }
  return true;
}

bool RobotClient::Impl::NotePanicAnswer(const ReplyBatch& batch) {
  if (batch.ack_sequence <= 0 || ack_waited_.count(batch.ack_sequence) == 0) return false;
  PanicAnswer answer;
  answer.session_unknown = batch.session_status == SessionStatus::kUnknown;
  switch (batch.panic) {
    case PanicStatus::kTaken:
      answer.taken = true;
      break;
    case PanicStatus::kRefused:
      answer.refusal = batch.panic_refusal.empty() ? "no reason given" : EscapeControls(batch.panic_refusal);
      break;
    case PanicStatus::kNone:  // an answer to a panic package that does not say: never counted as taken
      answer.refusal = "the server's answer to the panic package does not say that it was taken";
      break;
  }
  panic_answers_[batch.ack_sequence] = std::move(answer);
  return true;
}

// A new server instance: its clock may differ (another host), and it may
// serve another description under the robot's name. The ReadDaemon sends
// CLOCK queries and a CONFIG query; their replies update the offset and the
// model without any caller waiting.
void RobotClient::Impl::Resync() {
  {
    std::lock_guard lock(mu_);
    clock_sync_.Restart();
  }
  try {
    for (int i = 0; i < 3; ++i) SendClockSample();
    const Sent sent = SendPackage({}, {robotalk::Query{.type = QueryType::kConfig}});
    std::lock_guard lock(mu_);
    resync_config_query_ = sent.ids.front();
  } catch (const Error& e) {
    // On the ReadDaemon: stored by Run() and thrown from the next call.
    throw ClientError(std::string("RobotClient: re-syncing with the new server instance failed: ") +
                      e.what());
  }
}

void RobotClient::Impl::SendClockSample() {
  SendPackage({}, {robotalk::Query{.type = QueryType::kClock}},
              {.clock_query = true, .replies_unwaited = true});
}

void RobotClient::Impl::NoteResyncReplies(const std::vector<Reply>& replies) {
  std::lock_guard lock(mu_);
  if (!resync_config_query_) return;
  for (const Reply& r : replies) {
    if (r.id != *resync_config_query_) continue;
    resync_config_query_.reset();
    std::uint64_t hash = 0;
    try {
      hash = client::ParseConfigHash(r, "re-sync");
    } catch (const ProtocolError&) {
      return;
    }
    if (model_ && ConfigHash(*model_) == hash) return;
    if (auto model = configs_.Want(hash)) {
      model_ = std::move(model);
    } else {
      resync_hash_ = hash;  // OnConfig installs it when it arrives
    }
  }
}

}  // namespace robotalk
