// RobotClient::Impl: LCM set-up, package sending, and the ReadDaemon thread
// (replies -> ReturnCache, acks, clock samples, retransmission, heartbeats).
#include "client_impl.h"

#include "robotalk/broadcast_signature.h"
#include "robotalk/config_message.h"
#include "robotalk/heard_announcement.h"
#include "robotalk/known_servers.h"

#include "robotalk/routed_lcm_transport.h"

#include <poll.h>
#include <sys/eventfd.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <climits>
#include <cstdio>
#include <cstring>
#include <random>
#include <utility>

namespace robotalk {
namespace {

std::int64_t RandomClientId() {
  std::random_device rd;
  std::uint64_t id = 0;
  while (id == 0 || static_cast<std::int64_t>(id) == 0) id = (static_cast<std::uint64_t>(rd()) << 32) ^ rd();
  return static_cast<std::int64_t>(id);
}

client::RetransmitPolicy PolicyOf(const ClientOptions& o) {
  return {.interval = o.retransmit_interval,
          .backoff = o.retransmit_backoff,
          .max_interval = o.retransmit_max_interval,
          .give_up_after = o.give_up_after};
}

}  // namespace

RobotClient::Impl::Impl(ClientOptions options)
    : options_(std::move(options)),
      clock_(options_.clock ? *options_.clock : static_cast<const Clock&>(steady_clock_)),
      client_id_(options_.client_id != 0 ? options_.client_id : RandomClientId()),
      cache_(std::make_shared<client::ReturnCache>(options_.return_cache_capacity)),
      outstanding_(PolicyOf(options_)),
      fault_rng_(options_.fault_seed) {
  if (options_.transport) {
    transport_ = options_.transport;
  } else {
    try {
      own_transport_ = OpenLcmTransport(
          options_.lcm_url, OpenLcmOptions{.lane = {.queue_capacity = options_.lcm_queue_capacity}});
    } catch (const TransportError& e) {
      throw ClientError(std::string("RobotClient: ") + e.what());
    }
    transport_ = own_transport_.get();
  }
  if (options_.playback_copies < kPlaybackCopiesAuto || options_.playback_copies > 2) {
    throw ClientError("RobotClient: ClientOptions::playback_copies is " +
                      std::to_string(options_.playback_copies) +
                      "; expected 0 (kPlaybackCopiesAuto: twice once the link has lost a message), 1 "
                      "(each playback package once) or 2 (twice)");
  }
  LoadKeys();
  if (identity_) {
    // Keyed mode: the client id is one of the key's (docs/security.md,
    // Binding), so no other key can take it, before or after a restart.
    if (options_.client_id == 0) {
      client_id_ = KeyedClientId(identity_->public_key, static_cast<std::uint32_t>(RandomClientId()));
    } else if (!ClientIdBelongsTo(options_.client_id, identity_->public_key)) {
      throw ClientError("RobotClient: client id " + std::to_string(options_.client_id) +
                        " is not one of key " + identity_->public_key.Fingerprint() +
                        "'s (keyed mode: use robotalk::KeyedClientId, or leave client_id 0)");
    }
  }
  for (std::random_device rd; auto& b : hello_nonce_) b = static_cast<std::uint8_t>(rd());
  wake_fd_ = ::eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC);
  if (wake_fd_ < 0) throw ClientError(std::string("RobotClient: eventfd failed: ") + std::strerror(errno));
  last_send_ = clock_.Now();
  // Asked here, not on the ReadDaemon: LCM 1.3.1 sets up its receive side
  // (and lazily creates glib mutexes) on the first fileno() or subscribe, so
  // that set-up stays on one thread rather than racing Connect's subscribe
  // (TSan flagged it; glib's own atomics may make it safe, TSan cannot tell).
  transport_fd_ = transport_->fileno();
  daemon_ = std::thread([this] { Run(); });
}

RobotClient::Impl::~Impl() {
  stop_ = true;
  WakeDaemon();
  if (daemon_.joinable()) daemon_.join();
  {
    std::lock_guard lock(mu_);
    // A shared transport outlives us: its handlers must not call into a dead Impl.
    subscriptions_.clear();
    state_subscription_.reset();
    outstanding_.Clear();
  }
  ::close(wake_fd_);
  cache_->FailAll("RobotClient closed before the reply arrived", /*timed_out=*/false);
}

void RobotClient::Impl::WakeDaemon() {
  const std::uint64_t one = 1;
  [[maybe_unused]] auto n = ::write(wake_fd_, &one, sizeof one);
}

void RobotClient::Impl::Attach(const std::string& robot) {
  {
    std::lock_guard lock(mu_);
    try {
      if (trust_) trust_->Load(robot, PinNetwork(transport_->url()));  // keyed: the pinned server key
    } catch (const KeyError& e) {
      throw ClientError(std::string("RobotClient::Connect('") + robot + "'): " + e.what());
    }
    AttachLocked(robot);
    hello_due_ = true;  // the ReadDaemon says hello
    next_hello_ = clock_.Now();
  }
  WakeDaemon();
}

void RobotClient::Impl::AttachLocked(const std::string& robot) {
  robot_ = robot;
  request_channel_ = RequestChannel(robot);
  const std::string reply_channel = ReplyChannel(robot, client_id_);
  try {
    subscriptions_.push_back(transport_->Subscribe(
        reply_channel, [this](const std::string&, std::span<const std::uint8_t> b) { OnReplyPackage(b); }));
    subscriptions_.push_back(transport_->Subscribe(
        ConfigChannel(robot), [this](const std::string&, std::span<const std::uint8_t> b) { OnConfig(b); }));
    subscriptions_.push_back(transport_->Subscribe(
        HelloAnswerChannel(robot, client_id_),
        [this](const std::string&, std::span<const std::uint8_t> b) { OnHelloAnswer(b); }));
    if (identity_) {  // keyed: a restart heard while a panic waits (OnAnnounce)
      subscriptions_.push_back(transport_->Subscribe(
          kAnnounceChannel, [this](const std::string&, std::span<const std::uint8_t> b) { OnAnnounce(b); }));
    }
  } catch (const TransportError& e) {
    throw ClientError("RobotClient::Connect: cannot subscribe to " + reply_channel + ": " + e.what());
  }
}

RobotClient::Impl::Sent RobotClient::Impl::SendPackage(std::vector<Command> commands,
                                                       std::vector<robotalk::Query> queries,
                                                       const PackageOptions& options) {
  Sent sent;
  std::vector<std::uint8_t> bytes;
  std::string channel;
  int copies = 1;
  {
    std::unique_lock lock(mu_);
    if (daemon_error_) std::rethrow_exception(std::exchange(daemon_error_, nullptr));
    if (robot_.empty()) throw ClientError("RobotClient: not connected (call Connect first)");
    // An open-mode panic never waits for a session: a client whose server
    // restarted must still stop the robot, and an open-mode server takes a
    // panic outside any session. A keyed server takes one only in an
    // authenticated session, so a keyed client waits for its hello's answer.
    if (!(options.panic && session_id_ == 0 && !identity_)) WaitSession(lock);
    channel = request_channel_;
    const TimePoint now = clock_.Now();
    Request request = NextRequest(now);
    request.panic = options.panic;
    request.mode = options.mode;
    request.playback = options.playback;
    request.interpolation = options.interpolation;
    request.max_late = options.max_late.value_or(options_.max_late);
    // Ids are taken from next_id_ only once the package is encoded: a
    // package EncodeRequest refuses consumes nothing.
    CommandId id = next_id_;
    std::vector<client::OutstandingPackages::Item> items;
    for (Command& c : commands) {
      c.id = id++;
      std::optional<TimePoint> start;
      if (options.mode == RequestMode::kPlayback) {
        // A playback frame's start is an offset; when it runs is known only
        // once the server has chosen the delay (SetStartTimes). Until then,
        // do not re-ask an acknowledged frame before the whole sequence could
        // have played: re-asks would only load a congested server.
        start = now + options.playback.duration + options_.timeout;
      } else if (auto at = c.start_time.time()) {
        start = clock_sync_.ClientTime(*at);
      }
      items.push_back({c.id, start});
      sent.ids.push_back(c.id);
    }
    if (options.ask_for_delay) items.push_back({options.playback.id, std::nullopt});
    for (robotalk::Query& q : queries) {
      q.id = id++;
      items.push_back({q.id, std::nullopt});
      sent.ids.push_back(q.id);
    }
    request.commands = std::move(commands);
    request.queries = std::move(queries);
    bytes = EncodeSealed(request);
    next_id_ = id;
    sent.sequence = next_sequence_++;
    if (options.mode == RequestMode::kPlayback) copies = PlaybackCopies(now, options.playback_headroom);
    link_loss_.OnSend(sent.sequence, now, copies);
    stats_.playback_copies += static_cast<std::uint64_t>(copies - 1);
    for (CommandId i : sent.ids) {
      if (!options.replies_unwaited) {
        cache_->Expect(i);
        continue;
      }
      unwaited_ids_.push_back(i);
      if (unwaited_ids_.size() > kMaxUnwaitedIds) unwaited_ids_.pop_front();
    }
    outstanding_.Add(sent.sequence, bytes, std::move(items), now);
    if (options.clock_query) {
      clock_packages_.insert(sent.sequence);
      last_clock_query_ = now;
    }
    if (options.panic) ack_waited_.emplace(sent.sequence, now);
    last_send_ = now;
    ++stats_.packages_sent;
  }
  // No wake-up of the ReadDaemon (a context switch per command): it never
  // sleeps longer than retransmit_interval (IdleWait), and a new package's
  // first resend is at least that far away.
  // Playback redundancy: the copy is a duplicate by sequence number, which
  // the server drops (it re-acknowledges it; the frames run once).
  for (int k = 0; k < copies; ++k) Publish(channel, bytes);
  return sent;
}

int RobotClient::Impl::PlaybackCopies(TimePoint now, std::optional<Duration> headroom) const {
  if (options_.playback_copies != kPlaybackCopiesAuto) return options_.playback_copies;
  return link_loss_.WantsSecondCopy(now, outstanding_.retransmit_timeout(), headroom) ? 2 : 1;
}

PendingReply RobotClient::Impl::MakePending(CommandId id, std::string what) {
  return PendingReply(id, cache_, std::move(what));
}

void RobotClient::Impl::Publish(const std::string& channel, const std::vector<std::uint8_t>& bytes) {
  int copies = 1;
  if (options_.drop_probability > 0 || options_.duplicate_probability > 0) {
    std::lock_guard lock(fault_mu_);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    if (u(fault_rng_) < options_.drop_probability) {
      copies = 0;
    } else if (u(fault_rng_) < options_.duplicate_probability) {
      copies = 2;
    }
  }
  for (int i = 0; i < copies; ++i) transport_->Publish(channel, bytes);
}

std::optional<RobotClient::Impl::PanicAnswer> RobotClient::Impl::WaitPanicAnswer(
    std::int64_t sequence, std::chrono::steady_clock::time_point deadline) {
  std::unique_lock lock(mu_);
  cv_.wait_until(lock, deadline, [&] { return panic_answers_.count(sequence) != 0; });
  std::optional<PanicAnswer> answer;
  if (const auto it = panic_answers_.find(sequence); it != panic_answers_.end())
    answer = std::move(it->second);
  panic_answers_.erase(sequence);
  ack_waited_.erase(sequence);
  return answer;
}

std::shared_ptr<const RobotModel> RobotClient::Impl::WaitModel(
    std::uint64_t hash, std::chrono::steady_clock::time_point deadline) {
  std::unique_lock lock(mu_);
  std::shared_ptr<const RobotModel> model;
  cv_.wait_until(lock, deadline, [&] { return (model = configs_.Want(hash)) != nullptr; });
  return model;
}

void RobotClient::Impl::RethrowDaemonError() {
  std::lock_guard lock(mu_);
  if (daemon_error_) std::rethrow_exception(std::exchange(daemon_error_, nullptr));
}

std::string RobotClient::Impl::LastConfigError() const {
  std::lock_guard lock(mu_);
  return last_config_error_;
}

// ---------------------------------------------------------------------------
// The ReadDaemon.

// Sleeps until a message, a wake-up (new package, Close) or the next
// deadline, at most max_idle_wait; then dispatches and ticks.
void RobotClient::Impl::Run() {
  bool reported = false;
  const int fd = transport_fd_;
  while (!stop_) {
    const Duration wait = IdleWait(clock_.Now());
    const auto ms = std::chrono::ceil<std::chrono::milliseconds>(wait).count();
    try {
      if (fd >= 0) {
        pollfd fds[2] = {{wake_fd_, POLLIN, 0}, {fd, POLLIN, 0}};
        ::poll(fds, 2, static_cast<int>(std::clamp<long long>(ms, 0, INT_MAX)));
        if (fds[0].revents & POLLIN) {
          std::uint64_t v = 0;
          [[maybe_unused]] auto n = ::read(wake_fd_, &v, sizeof v);
        }
        if (stop_) break;
        if (fds[1].revents & POLLIN) transport_->HandleFor(Duration(0));
      } else {
        transport_->HandleFor(std::min<Duration>(wait, std::chrono::milliseconds(10)));
      }
    } catch (const TransportError& e) {
      // The transport failed (socket gone): report once and keep ticking so
      // that waits still time out rather than hang.
      if (!reported) {
        std::lock_guard lock(mu_);
        daemon_error_ = std::make_exception_ptr(ClientError(std::string("RobotClient: ") + e.what()));
        reported = true;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    } catch (...) {
      std::lock_guard lock(mu_);
      daemon_error_ = std::current_exception();
    }
    try {
      Tick(clock_.Now());
    } catch (...) {
      std::lock_guard lock(mu_);
      daemon_error_ = std::current_exception();
    }
  }
}

Duration RobotClient::Impl::IdleWait(TimePoint now) {
  std::lock_guard lock(mu_);
  Duration wait = options_.max_idle_wait;
  if (!robot_.empty()) {
    // Heartbeats only within a session; without one, the next hello is due.
    if (session_id_ != 0) {
      wait = std::min(wait, last_send_ + options_.heartbeat_interval - now);
    } else if (hello_due_) {
      wait = std::min(wait, next_hello_ - now);
    }
    // Bounded by the shortest resend interval, so a package added while the
    // ReadDaemon sleeps (SendPackage does not wake it) is never resent late.
    if (options_.retransmit_interval.count() > 0) wait = std::min(wait, options_.retransmit_interval);
  }
  if (outstanding_.size() > 0) wait = std::min(wait, outstanding_.NextDeadline() - now);
  return std::max(wait, Duration(0));
}

void RobotClient::Impl::Tick(TimePoint now) {
  std::vector<client::OutstandingPackages::Resend> resends;
  std::vector<client::OutstandingPackages::Expired> expired;
  std::vector<std::uint8_t> heartbeat;
  std::vector<std::uint8_t> hello;
  std::string channel;
  std::string hello_channel;
  bool resync = false;
  bool refresh_clock = false;
  {
    std::lock_guard lock(mu_);
    if (robot_.empty()) return;
    channel = request_channel_;
    hello = DueHello(now);
    if (!hello.empty()) hello_channel = HelloChannel(robot_);
    if (resync_ && session_id_ != 0) {
      resync = true;
      resync_ = false;
    }
    // Two hosts' clocks drift apart: a fresh sample now and then keeps the
    // offset right (ClockSync ages the best one). Not before Connect's own
    // rounds have synchronised.
    refresh_clock = !resync && session_id_ != 0 && clock_sync_.synced() &&
                    options_.clock_refresh_interval > Duration::zero() &&
                    now - last_clock_query_ >= options_.clock_refresh_interval;
    if (refresh_clock) last_clock_query_ = now;  // once per interval, even when the send fails
    resends = outstanding_.TakeDue(now);
    for (const auto& r : resends) link_loss_.OnSend(r.sequence, now);
    // Every copy's ack has had time to come twice the retransmission
    // timeout after it left (never before a round trip was measured).
    if (outstanding_.smoothed_round_trip()) link_loss_.Settle(now, 2 * outstanding_.retransmit_timeout());
    stats_.messages_lost = link_loss_.lost();
    expired = outstanding_.TakeExpired(now);
    stats_.retransmissions += resends.size();
    stats_.gave_up += expired.size();
    for (const auto& e : expired) clock_packages_.erase(e.sequence);
    // Resends do not count: the server refreshes a session only on new
    // packages, so heartbeats go on while a long GOTO is re-asked about.
    if (session_id_ != 0 && now - last_send_ >= options_.heartbeat_interval) {
      heartbeat = EncodeSealed(NextRequest(now));  // no items: PAYLOAD_QUERIES, size 0
      link_loss_.OnSend(next_sequence_, now);      // acknowledged like any package
      ++next_sequence_;
      last_send_ = now;
      ++stats_.heartbeats;
      ++stats_.packages_sent;
    }
  }
  if (!hello.empty()) Publish(hello_channel, hello);
  for (const auto& r : resends) Publish(channel, r.bytes);
  if (!heartbeat.empty()) Publish(channel, heartbeat);
  if (resync) Resync();
  if (refresh_clock) SendClockSample();
  for (const auto& e : expired) {
    const std::string why = "no answer from robot about package " + std::to_string(e.sequence) + " (" +
                            (e.acked ? "acknowledged" : "never acknowledged") + ") for " +
                            std::to_string(ToSeconds(options_.give_up_after)) + " s; gave up retransmitting";
    for (CommandId id : e.unanswered) cache_->Fail(id, "id " + std::to_string(id) + ": " + why);
  }
}

Request RobotClient::Impl::NextRequest(TimePoint now) const {
  return Request{.client_id = client_id_,
                 .session_id = session_id_,
                 .sequence = next_sequence_,
                 .send_time = now,
                 .round_trip = outstanding_.reported_round_trip().value_or(Duration(0))};
}

TimePoint RobotClient::Impl::ArrivalTime(TimePoint now) const {
  // The transport's stamp is wall-clock time: it maps onto the steady clock
  // as "this long ago". A test's own clock does not run with the wall clock;
  // an age outside [0, 1 s] is a wall-clock step, not a wait.
  if (&clock_ != &steady_clock_) return now;
  const auto age = std::chrono::system_clock::now() - transport_->ReceiveTime();
  if (age < Duration::zero() || age > std::chrono::seconds(1)) return now;
  return now - std::chrono::duration_cast<Duration>(age);
}

void RobotClient::Impl::OnReplyPackage(std::span<const std::uint8_t> bytes) {
  // Protocol errors are counted; anything else is stored and rethrown to the
  // next blocking call (the ReadDaemon keeps running).
  try {
    ReplyBatch batch;
    try {
      batch = DecodeReplyBatch(bytes);  // a SESSION_UNKNOWN's signature: AcceptReplyPackage verifies it
    } catch (const ProtocolError&) {
      std::lock_guard lock(mu_);
      ++stats_.malformed_packages;
      return;
    }
    const TimePoint now = clock_.Now();
    const TimePoint arrived = ArrivalTime(now);
    bool notify = false;
    std::vector<CommandId> lost;
    bool accepted = false;
    {
      std::lock_guard lock(mu_);
      // A reply that did not decode (unknown signal): its waiter times out
      // rather than see garbage; the rest of the batch stands.
      stats_.malformed_packages += batch.malformed.size();
      if (batch.client_id != client_id_) {
        ++stats_.malformed_packages;
        return;
      }
      accepted = AcceptReplyPackage(batch, bytes, now, lost);
    }
    if (!accepted) {
      cv_.notify_all();  // a panic answered outside its session
      FailLost(lost);
      return;
    }
    std::vector<const Reply*> to_file;  // not the replies nobody waits for (SendClockSample's)
    {
      std::lock_guard lock(mu_);
      if (batch.ack_sequence > 0) {
        link_loss_.OnAck(batch.ack_sequence);  // one per copy the server received
        const auto info = outstanding_.OnAck(
            batch.ack_sequence, now,
            client::OutstandingPackages::AckTiming{
                .received = arrived,
                .server_hold =
                    std::max(Duration::zero(), SaturatingSub(batch.server_send, batch.server_receive))});
        if (info.known && info.first && clock_packages_.erase(batch.ack_sequence) != 0 &&
            !info.retransmitted) {
          // Only a never-resent package gives an unambiguous t1; t4 is the
          // socket's stamp, so a starved read thread does not skew the offset.
          if (clock_sync_.AddSample(info.first_send, batch.server_receive, batch.server_send, arrived))
            ++stats_.clock_samples;
        }
        notify = NotePanicAnswer(batch);
      }
      for (const Reply& r : batch.replies) {
        outstanding_.OnReply(r.id, now);
        const auto unwaited = std::find(unwaited_ids_.begin(), unwaited_ids_.end(), r.id);
        if (unwaited == unwaited_ids_.end()) {
          to_file.push_back(&r);
        } else {
          unwaited_ids_.erase(unwaited);  // its first copy; a duplicate is filed as ignored
        }
      }
    }
    if (notify) cv_.notify_all();
    NoteResyncReplies(batch.replies);
    std::uint64_t filed = 0, ignored = 0;
    for (const Reply* r : to_file) (cache_->Put(*r) ? filed : ignored)++;
    std::lock_guard lock(mu_);
    stats_.replies_filed += filed;
    stats_.replies_ignored += ignored;
  } catch (...) {
    std::lock_guard lock(mu_);
    daemon_error_ = std::current_exception();
  }
}

void RobotClient::Impl::FailLost(const std::vector<CommandId>& lost) {
  for (CommandId id : lost) {
    cache_->Fail(id, "id " + std::to_string(id) +
                         ": the server instance that had it restarted or forgot this client's session; "
                         "it may or may not have run, and was not sent again");
  }
  if (!lost.empty()) WakeDaemon();  // say hello again at once
}

// A signed ANNOUNCE of this client's robot from another server instance,
// while a panic waits, says the session is gone (a restart; a forged flood
// may keep the new instance's SESSION_UNKNOWN answer from reaching us). It
// is believed only for a panic that went unanswered for the retransmission
// timeout: a replay of an earlier instance's ANNOUNCE (signed, so it passes)
// must not end a live session whose server answers at once (final13: before,
// a replay every 20 us made a taken panic look refused). Nor one whose server
// answers late (gaps14: its panic-latch fsync on slow storage): the ANNOUNCE
// must be fresh by its signed server time on the synchronised clock, neither
// too old nor stamped too far ahead (the rule `robotalk watch` applies,
// FreshAnnouncementTime) and signed after this
// session's hello was answered. Instance ids are random, not ordered: the
// time orders them. An older instance announced before the live one
// answered (it stopped before that one started), so no replay of it passes;
// a newer one announces after. Unsynchronised, no ANNOUNCE is believed (the
// new instance's SESSION_UNKNOWN answer remains). The cheap checks
// (decode, instance, robot) come before the signature's, which runs outside
// mu_: a flood of forged ANNOUNCEs never holds the client's lock.
void RobotClient::Impl::OnAnnounce(std::span<const std::uint8_t> bytes) {
  // The panics unanswered for the retransmission timeout. REQUIRES: mu_.
  const auto unanswered = [this](TimePoint now) {
    std::vector<std::int64_t> sequences;
    for (const auto& [sequence, sent] : ack_waited_)
      if (now - sent >= outstanding_.retransmit_timeout()) sequences.push_back(sequence);
    return sequences;
  };
  PublicKey key;
  std::int64_t session = 0, server = 0;
  std::string robot;
  {
    std::lock_guard lock(mu_);
    if (session_id_ == 0 || !trust_ || !trust_->trusted() || unanswered(clock_.Now()).empty()) return;
    key = *trust_->trusted();
    session = session_id_;
    server = server_id_;
    robot = robot_;
  }
  Announcement heard;
  try {
    heard = DecodeAnnouncement(bytes);
  } catch (const ProtocolError&) {
    return;
  }
  if (heard.server_id == server ||
      std::none_of(heard.robots.begin(), heard.robots.end(),
                   [&](const RobotAnnouncement& r) { return r.name == robot; }) ||
      VerifyBroadcast(kAnnounceChannel, bytes, key, nullptr) != BroadcastVerdict::kAuthentic)
    return;
  std::vector<CommandId> lost;
  {
    std::lock_guard lock(mu_);
    if (session_id_ != session || server_id_ != server) return;  // the session changed meanwhile
    const TimePoint now = clock_.Now();
    if (!clock_sync_.synced()) return;
    // Replayed, or stamped ahead by a clock that is not this session's
    // server's, or of an instance older than the session: not believed.
    const std::optional<TimePoint> alive =
        FreshAnnouncementTime(now, clock_sync_.ClientTime(heard.server_time));
    if (!alive || *alive <= session_opened_at_) return;
    const std::vector<std::int64_t> sequences = unanswered(now);
    if (sequences.empty()) return;
    for (const std::int64_t sequence : sequences) {
      panic_answers_.try_emplace(
          sequence, PanicAnswer{.refusal = "the server restarted (its signed ANNOUNCE names instance " +
                                           Hex64(static_cast<std::uint64_t>(heard.server_id)) +
                                           ") and has no session of this client",
                                .session_unknown = true});
    }
    lost = LoseSession(now);
  }
  cv_.notify_all();  // the waiting panic: sent again in a new session
  FailLost(lost);
}

}  // namespace robotalk
