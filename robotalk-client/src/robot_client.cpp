// RobotClient's public calls: connection, blocking / non-blocking calls,
// panic and convenience wrappers. The machinery is in read_daemon.cpp.
#include "robotalk/robot_client.h"

#include "client_impl.h"
#include "robotalk/broadcast_signature.h"
#include "robotalk/channels.h"
#include "robotalk/heard_announcement.h"
#include "robotalk/keys.h"
#include "robotalk/log_writer.h"  // EscapeControls
#include "robotalk/request.h"
#include "robotalk/routed_lcm_transport.h"

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <set>
#include <utility>

namespace robotalk {
namespace {

using SteadyPoint = std::chrono::steady_clock::time_point;

SteadyPoint SteadyNow() { return std::chrono::steady_clock::now(); }
SteadyPoint SteadyAfter(Duration d) {
  return SteadyNow() + std::chrono::duration_cast<std::chrono::steady_clock::duration>(d);
}

std::string Describe(const Command& c) {
  std::string s = ToString(c.type);
  if (!c.target.empty()) s += " '" + c.target + "'";
  return s;
}
std::string Describe(const Query& q) {
  std::string s = std::string("query ") + ToString(q.type);
  if (!q.target.empty()) s += " '" + q.target + "'";
  return s;
}

}  // namespace

namespace client {

std::string Answered(const Reply& reply) {
  return std::string(ToString(reply.signal)) + ": " + EscapeControls(reply.message);
}

std::uint64_t ParseConfigHash(const Reply& reply, const std::string& call) {
  const std::string& m = reply.message;
  const bool hex = !m.empty() && m.size() <= 16 && std::all_of(m.begin(), m.end(), [](char c) {
    return std::isxdigit(static_cast<unsigned char>(c));
  });
  if (!hex)
    throw ProtocolError(call + ": CONFIG reply message '" + EscapeControls(m) +
                        "' is not a hexadecimal hash");
  return std::stoull(m, nullptr, 16);
}

}  // namespace client

// --- PendingReply ------------------------------------------------------------

PendingReply::PendingReply(CommandId id, std::shared_ptr<client::ReturnCache> cache, std::string what)
    : id_(id), cache_(std::move(cache)), what_(std::move(what)) {}

PendingReply::PendingReply(PendingReply&& o) noexcept
    : id_(o.id_), cache_(std::move(o.cache_)), what_(std::move(o.what_)), reply_(std::move(o.reply_)) {}

PendingReply& PendingReply::operator=(PendingReply&& o) noexcept {
  if (this != &o) {
    if (cache_ && !reply_) cache_->Forget(id_);
    id_ = o.id_;
    cache_ = std::move(o.cache_);
    what_ = std::move(o.what_);
    reply_ = std::move(o.reply_);
  }
  return *this;
}

PendingReply::~PendingReply() {
  if (cache_ && !reply_) cache_->Forget(id_);
}

namespace {
// Turns a collected outcome into a reply or the matching exception.
std::optional<Reply> Resolve(client::ReturnCache::Outcome o, CommandId id, const std::string& what) {
  using Kind = client::ReturnCache::Outcome::Kind;
  switch (o.kind) {
    case Kind::kReply:
      return std::move(o.reply);
    case Kind::kFailed:
      if (o.timed_out) throw UnknownOutcomeError(what + " (id " + std::to_string(id) + "): " + o.failure);
      throw ClientError(what + " (id " + std::to_string(id) + "): " + o.failure);
    case Kind::kUnknown:
      throw ClientError(what + " (id " + std::to_string(id) +
                        "): no such pending reply (already collected?)");
    case Kind::kPending:
      break;
  }
  return std::nullopt;
}
}  // namespace

std::optional<Reply> PendingReply::Poll() {
  if (reply_) return reply_;
  if (!cache_) throw ClientError("PendingReply::Poll: moved-from handle");
  reply_ = Resolve(cache_->Take(id_), id_, what_);
  return reply_;
}

Reply PendingReply::Wait(Duration timeout) {
  if (reply_) return *reply_;
  if (!cache_) throw ClientError("PendingReply::Wait: moved-from handle");
  reply_ = Resolve(cache_->WaitTake(id_, SteadyAfter(timeout)), id_, what_);
  if (!reply_) {
    throw TimeoutError(what_ + " (id " + std::to_string(id_) + "): no reply within " +
                       std::to_string(ToSeconds(timeout)) + " s");
  }
  return *reply_;
}

std::optional<Reply> PendingReply::WaitFor(Duration most, std::stop_token stop) {
  if (reply_) return reply_;
  if (!cache_) throw ClientError("PendingReply::WaitFor: moved-from handle");
  reply_ = Resolve(cache_->WaitTake(id_, SteadyAfter(most), std::move(stop)), id_, what_);
  return reply_;
}

// --- ListRobots --------------------------------------------------------------

std::optional<PublicKey> ExplicitServerKey(const ClientOptions& options) {
  if (options.server_key_file.empty()) return std::nullopt;
  try {
    return ReadPublicKeyFile(options.server_key_file).key;
  } catch (const KeyError& e) {
    throw ClientError(std::string("server key: ") + e.what());
  }
}

std::vector<AnnouncedRobot> ListRobots(const ClientOptions& options, Duration listen, std::size_t* unlisted) {
  if (unlisted) *unlisted = 0;
  std::unique_ptr<Transport> own;
  Transport* transport = options.transport;
  if (!transport) {
    try {
      own = OpenLcmTransport(options.lcm_url);
    } catch (const TransportError& e) {
      throw ClientError(std::string("ListRobots: ") + e.what());
    }
    transport = own.get();
  }
  // An explicit server key: only what it signed (server_trust.h: that key and
  // nothing else), dropped before the list's bound so others' names cannot
  // crowd its robots out.
  const std::optional<PublicKey> only_key = ExplicitServerKey(options);
  // Keyed by (server id, name): a flood of names costs a lookup each, and
  // past kMaxListedRobots only a count.
  struct Collector {
    const PublicKey* only_key;
    std::vector<AnnouncedRobot> robots;
    std::set<std::pair<std::int64_t, std::string>> seen;
    std::size_t unlisted = 0;
    void On(std::span<const std::uint8_t> bytes) {
      const std::optional<HeardAnnouncement> heard = HearAnnouncement(bytes, only_key);
      if (!heard) return;
      const Announcement& msg = heard->announcement;
      for (const auto& r : msg.robots) {
        if (seen.contains({msg.server_id, r.name})) continue;
        if (robots.size() >= kMaxListedRobots) {
          ++unlisted;
          continue;
        }
        seen.insert({msg.server_id, r.name});
        robots.push_back({.name = r.name,
                          .driver = r.driver,
                          .config_hash = r.config_hash,
                          .total_dofs = r.total_dofs,
                          .base_type = r.base_type,
                          .panic = r.panic,
                          .num_clients = r.num_clients,
                          .server_id = msg.server_id,
                          .url_hint = msg.url_hint,
                          .server_key = heard->server_key});
      }
    }
  } collector{.only_key = only_key ? &*only_key : nullptr};
  // The checked decoder: LCM's typed one throws through its C callback on a
  // zero-length string (tests/fuzz/regressions/announce).
  auto sub = transport->Subscribe(
      kAnnounceChannel,
      [&](const std::string&, std::span<const std::uint8_t> bytes) { collector.On(bytes); });
  const SteadyPoint deadline = SteadyAfter(listen);
  for (int round = 0; round < 1000000; ++round) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - SteadyNow());
    if (left.count() <= 0) break;
    try {
      transport->HandleFor(std::min<Duration>(left, std::chrono::milliseconds(50)));
    } catch (const ProtocolError&) {
      // a malformed announcement: ignored
    }
  }
  sub.reset();
  if (unlisted) *unlisted = collector.unlisted;
  std::sort(collector.robots.begin(), collector.robots.end(),
            [](const AnnouncedRobot& a, const AnnouncedRobot& b) {
              return a.name != b.name ? a.name < b.name : a.server_id < b.server_id;
            });
  return collector.robots;
}

// --- RobotClient -------------------------------------------------------------

RobotClient::RobotClient(ClientOptions options) : impl_(std::make_unique<Impl>(std::move(options))) {}
RobotClient::~RobotClient() = default;

void RobotClient::Connect(const std::string& robot) {
  if (const std::string why = RobotNameProblem(robot); !why.empty()) {
    throw ClientError("RobotClient::Connect: invalid robot name '" + robot + "': " + why);
  }
  {
    std::lock_guard lock(impl_->mu_);
    if (!impl_->robot_.empty()) {
      throw ClientError("RobotClient::Connect('" + robot + "'): already attached to '" + impl_->robot_ + "'");
    }
  }
  impl_->Attach(robot);
  const Duration connect_timeout = impl_->options_.connect_timeout;
  const SteadyPoint deadline = SteadyAfter(connect_timeout);
  auto timeout = [&](const std::string& what) {
    return TimeoutError("RobotClient::Connect('" + robot + "'): " + what + " within " +
                        std::to_string(ToSeconds(connect_timeout)) + " s (is a server offering it?)");
  };

  // 1. The configuration query leaves first and travels while the clock
  //    rounds run (a CLI process connects in fewer round trips).
  std::optional<PendingReply> first_config = impl_->MakePending(
      impl_->SendPackage({}, {robotalk::Query{.type = QueryType::kConfig}}).ids[0], "CONFIG");

  // 2. Clock: `clock_sync_rounds` CLOCK round trips, more if none counted
  //    (a resent package gives no sample).
  const int rounds = std::max(1, impl_->options_.clock_sync_rounds);
  int answered = 0;  // CLOCK answers received, usable or not
  for (int i = 0; SteadyNow() < deadline; ++i) {
    {
      std::lock_guard lock(impl_->mu_);
      if (i >= rounds && impl_->clock_sync_.synced()) break;
      // Answers that never give a sample (a round trip <= 0 on the client's
      // clock): asking on would flood the server, not help.
      if (answered >= 4 * rounds + 4 && !impl_->clock_sync_.synced()) {
        throw ClientError("RobotClient::Connect('" + robot + "'): " + std::to_string(answered) +
                          " CLOCK answers gave no usable sample (each round trip came out negative on the "
                          "client's clock: does ClientOptions::clock move with real time?)");
      }
    }
    auto sent = impl_->SendPackage({}, {robotalk::Query{.type = QueryType::kClock}}, {.clock_query = true});
    PendingReply p = impl_->MakePending(sent.ids[0], "CLOCK");
    try {
      p.Wait(std::chrono::duration_cast<Duration>(deadline - SteadyNow()));
      ++answered;
    } catch (const TimeoutError&) {
      break;
    }
  }
  {
    std::lock_guard lock(impl_->mu_);
    if (!impl_->clock_sync_.synced()) {
      const ClientStats& st = impl_->stats_;
      throw timeout("no CLOCK answer (" + std::to_string(st.packages_sent) + " packages sent, " +
                    std::to_string(st.retransmissions) + " resent, " + std::to_string(st.replies_filed) +
                    " replies)");
    }
  }

  // 3. Configuration: learn its hash from the reply, wait for the
  //    description on the CONFIG channel; ask again if that message was lost.
  std::shared_ptr<const RobotModel> model;
  while (!model && SteadyNow() < deadline) {
    PendingReply p =
        first_config
            ? std::move(*first_config)
            : impl_->MakePending(impl_->SendPackage({}, {robotalk::Query{.type = QueryType::kConfig}}).ids[0],
                                 "CONFIG");
    first_config.reset();
    Reply r;
    try {
      r = p.Wait(std::chrono::duration_cast<Duration>(deadline - SteadyNow()));
    } catch (const TimeoutError&) {
      break;
    }
    const std::string call = "RobotClient::Connect('" + robot + "')";
    if (!Succeeded(r.signal)) throw ClientError(call + ": CONFIG answered " + client::Answered(r));
    const std::uint64_t hash = client::ParseConfigHash(r, call);
    model = impl_->WaitModel(hash, std::min(deadline, SteadyAfter(std::chrono::milliseconds(500))));
  }
  if (!model) {
    const std::string err = impl_->LastConfigError();
    throw timeout("no configuration received" + (err.empty() ? std::string() : " (last error: " + err + ")"));
  }
  std::lock_guard lock(impl_->mu_);
  impl_->model_ = std::move(model);
  impl_->connected_ = true;
}

bool RobotClient::connected() const {
  std::lock_guard lock(impl_->mu_);
  return impl_->connected_;
}

const std::string& RobotClient::robot() const {
  std::lock_guard lock(impl_->mu_);
  return impl_->robot_;  // set once by Connect, then constant
}

std::int64_t RobotClient::client_id() const { return impl_->client_id_; }

const RobotModel& RobotClient::model() const {
  std::lock_guard lock(impl_->mu_);
  if (!impl_->model_) throw ClientError("RobotClient::model: not connected");
  return *impl_->model_;  // kept alive in configs_ for the client's lifetime (config_store.h)
}

const RobotModel& RobotClient::ReloadModel() {
  Reply r = Query(QueryType::kConfig);
  if (!Succeeded(r.signal))
    throw ClientError("RobotClient::ReloadModel: CONFIG answered " + client::Answered(r));
  auto model = impl_->WaitModel(client::ParseConfigHash(r, "RobotClient::ReloadModel"),
                                SteadyAfter(impl_->options_.timeout));
  if (!model) throw TimeoutError("RobotClient::ReloadModel: no configuration received");
  std::lock_guard lock(impl_->mu_);
  impl_->model_ = model;
  return *model;
}

TimePoint RobotClient::ServerNow() const { return ServerTime(impl_->clock_.Now()); }
TimePoint RobotClient::ServerTime(TimePoint client_time) const {
  std::lock_guard lock(impl_->mu_);
  return impl_->clock_sync_.ServerTime(client_time);
}
TimePoint RobotClient::ClientTime(TimePoint server_time) const {
  std::lock_guard lock(impl_->mu_);
  return impl_->clock_sync_.ClientTime(server_time);
}
Duration RobotClient::clock_offset() const {
  std::lock_guard lock(impl_->mu_);
  return impl_->clock_sync_.offset();
}
Duration RobotClient::clock_round_trip() const {
  std::lock_guard lock(impl_->mu_);
  return impl_->clock_sync_.best_round_trip().value_or(Duration::zero());
}

void RobotClient::SyncClock(int rounds) {
  for (int i = 0; i < rounds; ++i) {
    auto sent = impl_->SendPackage({}, {robotalk::Query{.type = QueryType::kClock}}, {.clock_query = true});
    impl_->MakePending(sent.ids[0], "CLOCK").Wait(impl_->options_.timeout);
  }
}

namespace {
void RequireConnected(const RobotClient& c, const char* call) {
  if (!c.connected())
    throw ClientError(std::string("RobotClient::") + call + ": not connected (call Connect first)");
}
}  // namespace

Reply RobotClient::Execute(Command command) {
  RequireConnected(*this, "Execute");
  impl_->RethrowDaemonError();
  // The reply of a command scheduled ahead cannot come before its start.
  Duration wait = impl_->options_.timeout;
  if (auto at = command.start_time.time()) wait += std::max(Duration::zero(), *at - ServerNow());
  PendingReply p = Send(std::move(command));
  try {
    return p.Wait(wait);
  } catch (const TimeoutError&) {
    impl_->RethrowDaemonError();
    throw;
  }
}

Reply RobotClient::Query(QueryType type, const std::string& target) {
  return Query(robotalk::Query{.type = type, .target = target});
}

Reply RobotClient::CommandStatus(CommandId id) {
  return Query(robotalk::Query{.type = QueryType::kCommandStatus, .about = id});
}

Reply RobotClient::ServerCounters() { return Query(robotalk::Query{.type = QueryType::kServerCounters}); }

Reply RobotClient::Query(robotalk::Query query) {
  RequireConnected(*this, "Query");
  impl_->RethrowDaemonError();
  PendingReply p = SendQuery(std::move(query));
  try {
    return p.Wait(impl_->options_.timeout);
  } catch (const TimeoutError&) {
    impl_->RethrowDaemonError();
    throw;
  }
}

PendingReply RobotClient::Send(Command command) {
  RequireConnected(*this, "Send");
  const std::string what = Describe(command);
  auto sent = impl_->SendPackage({std::move(command)}, {});
  return impl_->MakePending(sent.ids[0], what);
}

PendingReply RobotClient::SendQuery(robotalk::Query query) {
  RequireConnected(*this, "SendQuery");
  const std::string what = Describe(query);
  auto sent = impl_->SendPackage({}, {std::move(query)});
  return impl_->MakePending(sent.ids[0], what);
}

std::vector<PendingReply> RobotClient::SendBatch(std::vector<Command> commands, CommandMode mode) {
  RequireConnected(*this, "SendBatch");
  if (mode == CommandMode::kPlayback) {
    throw ClientError("RobotClient::SendBatch: a playback sequence is declared whole; use RunSequence");
  }
  if (commands.empty()) return {};
  std::vector<std::string> what;
  for (const Command& c : commands) what.push_back(Describe(c));
  auto sent =
      impl_->SendPackage(std::move(commands), {},
                         {.mode = mode == CommandMode::kDelay ? RequestMode::kDelay : RequestMode::kDirect});
  std::vector<PendingReply> pending;
  for (std::size_t i = 0; i < sent.ids.size(); ++i)
    pending.push_back(impl_->MakePending(sent.ids[i], what[i]));
  return pending;
}

void RobotClient::Panic() {
  RequireConnected(*this, "Panic");
  const auto deadline = SteadyAfter(impl_->options_.timeout);
  std::string unknown;  // the last "session unknown" answer, if any
  for (;;) {
    auto sent = impl_->SendPackage({}, {}, {.panic = true});
    const auto answer = impl_->WaitPanicAnswer(sent.sequence, deadline);
    if (!answer) {
      throw TimeoutError("RobotClient::Panic: panic package " + std::to_string(sent.sequence) +
                         " not answered by robot '" + robot() + "' within " +
                         std::to_string(ToSeconds(impl_->options_.timeout)) + " s" +
                         (unknown.empty() ? ""
                                          : " (each earlier attempt's session was unknown: " + unknown +
                                                "); whether the robot is in panic is not known"));
    }
    if (answer->taken) return;
    // Keyed mode: the session was gone (a restarted server); the client says
    // hello again and the panic goes out once more, in the new session, as
    // often as the timeout allows: "session unknown" says nothing of whether
    // the robot is in panic, so it is never reported as a refusal.
    if (answer->session_unknown && impl_->identity_) {
      unknown = answer->refusal;
      if (std::chrono::steady_clock::now() < deadline) continue;
      throw TimeoutError("RobotClient::Panic: robot '" + robot() + "' did not take the panic within " +
                         std::to_string(ToSeconds(impl_->options_.timeout)) +
                         " s: each attempt's session was unknown (" + unknown +
                         "); whether the robot is in panic is not known");
    }
    throw PanicRefusedError(
        "RobotClient::Panic: robot '" + robot() +
        "' refused the panic (the robot is NOT in panic because of it): " + answer->refusal);
  }
}

Reply RobotClient::ResetPanic() { return Execute(Command{.type = CommandType::kPanicReset}); }

Reply RobotClient::SetJoint(const std::string& joint, std::vector<double> positions,
                            std::optional<TimePoint> start) {
  return Execute(Command{.type = CommandType::kJointSetPoint,
                         .start_time = start,
                         .target = joint,
                         .values = std::move(positions)});
}
Reply RobotClient::JointSpeed(const std::string& joint, std::vector<double> velocities,
                              std::optional<TimePoint> start) {
  return Execute(Command{.type = CommandType::kJointSpeed,
                         .start_time = start,
                         .target = joint,
                         .values = std::move(velocities)});
}
Reply RobotClient::Goto(double x, double y, double theta, std::optional<TimePoint> start) {
  return Execute(Command{.type = CommandType::kGoto, .start_time = start, .values = {x, y, theta}});
}
Reply RobotClient::SetSpeed(double v, double omega, std::optional<TimePoint> start) {
  return Execute(Command{.type = CommandType::kSetSpeed, .start_time = start, .values = {v, omega}});
}
Reply RobotClient::Stop(std::optional<TimePoint> start) {
  return Execute(Command{.type = CommandType::kStop, .start_time = start});
}
Reply RobotClient::JointState(const std::string& joint) { return Query(QueryType::kJointState, joint); }
Reply RobotClient::BasePose() { return Query(QueryType::kBasePose); }

ClientStats RobotClient::stats() const {
  std::lock_guard lock(impl_->mu_);
  ClientStats s = impl_->stats_;
  s.replies_ignored = std::max(s.replies_ignored, impl_->cache_->ignored());
  s.configs_cached = impl_->configs_.size();
  s.config_bytes_cached = impl_->configs_.bytes();
  return s;
}

const ClientOptions& RobotClient::options() const { return impl_->options_; }

TrustedServer RobotClient::trusted_server() const {
  std::lock_guard lock(impl_->mu_);
  return impl_->trust_ ? impl_->trust_->Describe() : TrustedServer{};
}

}  // namespace robotalk
