#include "server_daemon.h"

#include "daemon_pump.h"

#include "robotalk/broadcast_signature.h"
#include "robotalk/channels.h"
#include "robotalk/config_message.h"
#include "robotalk/error.h"
#include "robotalk/request.h"
#include "state_encoding.h"

#include <poll.h>
#include <pthread.h>
#include <sched.h>
#include <sys/eventfd.h>
#include <unistd.h>

#include <cstdio>
#include <exception>
#include <random>

namespace robotalk {
namespace {

constexpr std::size_t kMaxBatchBytes = 30000;  // split reply packages well under LCM's 64 KB

}  // namespace

ServerDaemon::ServerDaemon(Transport& transport, const Clock& clock, ServerDaemonOptions options)
    : transport_(transport),
      clock_(clock),
      options_(options),
      faults_(options.reply_drop_probability, options.reply_duplicate_probability, options.fault_seed),
      latch_(options.panic_latch_path),
      log_limiter_(LogLimiterOptions{.lines_per_second = options.log_lines_per_second,
                                     .repeat_window = options.log_repeat_window}),
      congestion_rng_(options.fault_seed) {
  latched_at_start_ = latch_.Load();  // throws naming the file
  event_fd_ = eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC);
  if (event_fd_ < 0) throw Error("ServerDaemon: eventfd failed");
  server_id_ = options_.server_id;
  if (server_id_ == 0) {
    std::random_device rd;
    server_id_ = static_cast<std::int64_t>((static_cast<std::uint64_t>(rd()) << 32) ^ rd());
  }
  table_ = std::make_unique<SessionTable>(server_id_, options_.sessions);
  if (table_->keyed()) signer_.emplace(*options_.sessions.identity, *table_->instance_nonce());
  const auto subscribe = [this] {
    hello_subscription_ = transport_.Subscribe(
        kAnyHelloChannelRegex,
        [this](const std::string& channel, std::span<const std::uint8_t> bytes) { OnHello(channel, bytes); });
    subscription_ = transport_.Subscribe(
        kAnyRequestChannelRegex, [this](const std::string& channel, std::span<const std::uint8_t> bytes) {
          OnRequest(channel, bytes);
        });
    announce_subscription_ = transport_.Subscribe(
        kAnnounceChannel,
        [this](const std::string&, std::span<const std::uint8_t> bytes) { OnAnnounce(bytes); });
  };
  if (options_.fifo_priority <= 0) {
    subscribe();
    return;
  }
  // LCM starts a subscription's receive thread on the subscribing thread, and
  // a new thread inherits its creator's policy: subscribing from a thread at
  // the ServerDaemon's SCHED_FIFO priority puts LCM's receive threads there
  // too. Equal FIFO priorities do not preempt each other, so under load the
  // receive thread reads every waiting datagram before the ServerDaemon runs
  // and handles them in one wake-up, instead of a thread switch per package.
  std::exception_ptr error;
  std::thread([&] {
    sched_param param{};
    param.sched_priority = options_.fifo_priority;
    pthread_setschedparam(pthread_self(), SCHED_FIFO, &param);  // not permitted: as before
    try {
      subscribe();
    } catch (...) {
      error = std::current_exception();
    }
  }).join();
  if (error) std::rethrow_exception(error);
}

ServerDaemon::~ServerDaemon() {
  Stop();
  log_limiter_.Flush(clock_.Now(), log_pending_);  // what repeated since its last summary
  WriteLog();
  subscription_.reset();
  hello_subscription_.reset();
  announce_subscription_.reset();
  if (event_fd_ >= 0) close(event_fd_);
}

void ServerDaemon::AddRobot(RobotDaemon& daemon, SessionOptions options) {
  const std::string& name = daemon.robot_name();
  if (const std::string why = RobotNameProblem(name); !why.empty()) {
    throw Error("ServerDaemon: robot name '" + name + "': " + why);
  }
  if (robots_.count(name)) throw Error("ServerDaemon: robot name '" + name + "' is given twice");
  Robot robot{&daemon, nullptr, EncodeConfig(daemon.model()), ConfigHash(daemon.model()), {}};
  options.counters = [this] {
    auto table = table_->counters().Table();
    table.emplace_back("malformed", static_cast<double>(malformed_));
    table.emplace_back("unknown_unanswered", static_cast<double>(unknown_unanswered_));
    return table;
  };
  robot.sessions = std::make_unique<RobotSessions>(daemon, robot.config_hash, options, *table_);
  if (signer_) signer_->Sign(ConfigChannel(name), robot.encoded_config);  // once: it never changes
  daemon.Preallocate(robot.output);
  daemon.set_output_ready_callback([this] { Wake(); });
  if (auto it = latched_at_start_.find(name); it != latched_at_start_.end()) {
    // A panic outlives the server: the robot starts held, as it was left.
    std::vector<QueuedItem> none;
    daemon.Panic(none,
                 "panic latched before this server started (in " + latch_.path() + ": " + it->second + ")");
    Log("robot '" + name + "': starts in PANIC, latched in " + latch_.path() + " (" + it->second +
        "); PANIC_RESET to resume");
  }
  robots_.emplace(name, std::move(robot));
  ++serving_;
}

// The one place the panic latch file is written (Drain calls it, after the
// RobotDaemon's output is taken and before anything is sent).
void ServerDaemon::Persist(Robot& robot) {
  const std::string& name = robot.daemon->robot_name();
  const bool panic = robot.daemon->in_panic();
  if (panic == latch_.latched(name)) return;
  try {
    if (panic) {
      const std::string fault = robot.daemon->fault();
      latch_.Set(name, fault.empty() ? "PANIC from a client" : fault);
    } else {
      latch_.Clear(name);
    }
  } catch (const Error& e) {
    Log("robot '" + name + "': " + e.what() + " -- the panic will NOT survive a restart");
  }
}

std::vector<std::string> ServerDaemon::robot_names() const {
  std::vector<std::string> out;
  for (const auto& [name, robot] : robots_) out.push_back(name);
  return out;
}

std::string ServerDaemon::refused(const std::string& robot) const {
  auto it = robots_.find(robot);
  return it == robots_.end() ? std::string() : it->second.refused;
}

std::vector<std::string> ServerDaemon::refusals() const {
  std::lock_guard lock(refusals_mu_);
  return refusals_;
}

// One robot, one server: two servers serving one robot name would both
// execute every command. The server that starts later decides, during its
// start-up window: it refuses a robot that a server serving for longer
// announces (equal uptimes: the larger id refuses), stops it if it moved,
// and leaves every package to the other. After the window an ANNOUNCE never
// changes what this server serves: anyone on the LAN can send one (issue 19:
// a single forged datagram disabled a robot until the server restarted), and
// the rule has already been applied by whichever server came later.
void ServerDaemon::OnAnnounce(std::span<const std::uint8_t> bytes) {
  Announcement a;
  try {
    a = DecodeAnnouncement(bytes);
  } catch (const ProtocolError&) {
    return;  // not ours to judge; clients ignore it too
  }
  if (a.server_id == server_id_ || options_.allow_duplicate_robots) return;
  const Duration mine = started_ == TimePoint::min() ? Duration(0) : clock_.Now() - started_;
  const bool starting = mine < options_.startup_window;
  const bool other_wins = a.uptime > mine + std::chrono::milliseconds(1) ||
                          (a.uptime >= mine - std::chrono::milliseconds(1) && a.server_id < server_id_);
  for (const RobotAnnouncement& r : a.robots) {
    auto it = robots_.find(r.name);
    if (it == robots_.end() || !it->second.refused.empty()) continue;
    const std::string other = "server " + Hex64(static_cast<std::uint64_t>(a.server_id)) +
                              (a.url_hint.empty() ? "" : " (" + a.url_hint + ")");
    if (!starting) {
      LogConflict(it->second, other, mine);
    } else if (!other_wins) {
      Log("robot '" + r.name + "': " + other +
          " also announces it; it started after this server and gives way");
    } else {
      Refuse(it->second, "robot '" + r.name + "' is served by " + other + "; this server (" +
                             Hex64(static_cast<std::uint64_t>(server_id_)) +
                             ") refuses it: run one server per robot name (or --allow-duplicate-robots)");
    }
  }
}

void ServerDaemon::Refuse(Robot& robot, const std::string& why) {
  robot.refused = why;
  robot.daemon->QueueStop(/*only_if_moving=*/true);
  --serving_;
  {
    std::lock_guard lock(refusals_mu_);
    refusals_.push_back(why);
  }
  std::string still;
  for (const auto& [name, r] : robots_) {
    if (r.refused.empty()) still += (still.empty() ? "'" : ", '") + name + "'";
  }
  Log("ERROR: " + why + "; " +
      (still.empty() ? std::string("this server serves no robot now") : "still serving " + still));
}

// A conflict after the start-up window: said, at most once per robot per
// 10 s (a flood of forged ANNOUNCEs must not flood the log), nothing else.
void ServerDaemon::LogConflict(Robot& robot, const std::string& other, Duration served) {
  const TimePoint now = clock_.Now();
  if (now < robot.next_conflict_log) {
    ++robot.conflicts_unlogged;
    return;
  }
  robot.next_conflict_log = now + std::chrono::seconds(10);
  char seconds[32];
  std::snprintf(seconds, sizeof seconds, "%.0f s", ToSeconds(served));
  Log("robot '" + robot.daemon->robot_name() + "': " + other + " also announces it; this server (" +
      Hex64(static_cast<std::uint64_t>(server_id_)) + ") has served it for " + seconds +
      " and keeps serving it (one robot, one server is decided when a server starts: a server started "
      "with --allow-duplicate-robots, or a forged ANNOUNCE)" +
      (robot.conflicts_unlogged > 0
           ? "; " + std::to_string(robot.conflicts_unlogged) + " more such ANNOUNCEs since the last line"
           : std::string()));
  robot.conflicts_unlogged = 0;
}

void ServerDaemon::Start() {
  if (running_.exchange(true)) return;
  // What AddRobot said (a robot that starts in panic) before the thread
  // starts: Server prints "serving robot" after this, so a reader waiting for
  // that line already has these.
  WriteLog();
  thread_ = std::thread([this] {
    ApplyPriority();
    while (running_) RunOnce(std::chrono::milliseconds(50));
  });
}

void ServerDaemon::ApplyPriority() {
  if (options_.fifo_priority <= 0) return;
  sched_param param{};
  param.sched_priority = options_.fifo_priority;
  const bool fifo = pthread_setschedparam(pthread_self(), SCHED_FIFO, &param) == 0;
  Log(fifo ? "ServerDaemon thread: SCHED_FIFO priority " + std::to_string(param.sched_priority)
           : std::string("ServerDaemon thread: SCHED_OTHER (SCHED_FIFO not permitted)"));
}

void ServerDaemon::Stop() {
  if (!running_.exchange(false)) return;
  Wake();
  if (thread_.joinable()) thread_.join();
}

void ServerDaemon::Wake() {
  const std::uint64_t one = 1;
  [[maybe_unused]] ssize_t n = write(event_fd_, &one, sizeof one);
}

void ServerDaemon::RunOnce(Duration timeout) {
  pollfd fds[2] = {{transport_.fileno(), POLLIN, 0}, {event_fd_, POLLIN, 0}};
  // A playback sequence waiting for its frame 0's second copy starts when its wait ends.
  for (auto& [name, robot] : robots_) {
    if (const std::optional<TimePoint> next = robot.sessions->NextPlaybackDecision())
      timeout = std::clamp(*next - clock_.Now(), Duration(0), timeout);
  }
  const int timeout_ms = static_cast<int>(
      std::chrono::duration_cast<std::chrono::milliseconds>(timeout + std::chrono::microseconds(999))
          .count());
  const int ready = fds[0].fd >= 0 ? poll(fds, 2, timeout_ms) : poll(fds + 1, 1, timeout_ms);
  if (ready > 0 && (fds[1].revents & POLLIN)) {
    std::uint64_t count;
    [[maybe_unused]] ssize_t n = read(event_fd_, &count, sizeof count);
  }
  try {
    transport_.HandleFor(Duration(0));
  } catch (const std::exception& e) {
    Log(std::string("transport: ") + e.what());
  }
  Flush();
  const TimePoint now = clock_.Now();
  for (auto& [name, robot] : robots_)
    if (robot.sessions->DecidePlaybacks(now)) Drain(robot);
  if (started_ == TimePoint::min()) started_ = now;
  if (now >= next_watchdog_) {
    Watchdogs(now);
    next_watchdog_ = now + options_.watchdog_period;
  }
  if (now >= next_announce_) {
    Announce(now);
    next_announce_ = now + options_.announce_period;
  }
  log_limiter_.Tick(now, log_pending_);
  WriteLog();
}

void ServerDaemon::Flush() {
  for (auto& [name, robot] : robots_) {
    robot.daemon->FinishPanic();
    Drain(robot);
  }
  WriteLog();
}

TimePoint ServerDaemon::ArrivalTime(TimePoint now) const {
  // The stamp is wall-clock time: it maps onto the server's steady clock as
  // "this long ago" (as the client's RobotClient::Impl::ArrivalTime).
  if (dynamic_cast<const SteadyClock*>(&clock_) == nullptr) return now;
  const auto age = std::chrono::system_clock::now() - transport_.ReceiveTime();
  if (age < Duration::zero() || age > std::chrono::seconds(1)) return now;
  return now - std::chrono::duration_cast<Duration>(age);
}

// A transport handler: never throws for bad input (the transport would
// rethrow it out of RunOnce and end the loop's iteration).
void ServerDaemon::OnRequest(const std::string& channel, std::span<const std::uint8_t> bytes) {
  // Two times (issue 23): `received`, when it is handled, judges what runs
  // and what expires (start times, --max-late, the session table's and the
  // sessions' liveness, playback's delays: a frame plays only once handled);
  // `arrived`, when it reached the socket, measures the link (link health's
  // transits, the clock sample's t2), so that this thread's own lag under
  // load is not the network's.
  const TimePoint received = clock_.Now();
  const TimePoint arrived = ArrivalTime(received);
  const std::optional<std::string> robot_name = RobotOfRequestChannel(channel);
  if (!robot_name) return;
  auto it = robots_.find(*robot_name);
  if (it == robots_.end()) return;  // another server's robot
  Robot& robot = it->second;
  if (!robot.refused.empty()) return;  // the other server answers
  Request request;
  try {
    request = DecodeRequest(bytes);
  } catch (const ProtocolError& e) {
    // Undecodable bytes carry no trustworthy client id to answer: count and log.
    ++malformed_;
    Log("robot '" + *robot_name + "': dropped a malformed package on " + channel + ": " + e.what());
    return;
  }
  if (!Gate(robot, *robot_name, request, bytes, received, arrived)) return;
  ImmediateAnswer answer = robot.sessions->Handle(request, received, arrived);
  if (!request.header_error.empty()) {
    Log("robot '" + *robot_name + "': refused package from client " +
        Hex64(static_cast<std::uint64_t>(request.client_id)) + ": " + request.header_error);
  }
  if (answer.publish_config) transport_.Publish(ConfigChannel(*robot_name), robot.encoded_config);
  // The panic (or its reset) on disk, then the acknowledgement, then what the
  // RobotDaemon has (without waiting for its lock: RunOnce's Flush waits).
  Drain(robot, /*wait=*/false, answer.send ? &answer.batch : nullptr);
  if (robot.daemon->FinishPanic()) Drain(robot, /*wait=*/false);  // a panic's flushed items, at once
  if (options_.congestion_max_pause.count() > 0) {
    // The paper's congestion injector (§VI-B): a random pause after each
    // received package, during which nothing else is received.
    std::uniform_real_distribution<double> pause(0.0, ToSeconds(options_.congestion_max_pause));
    std::this_thread::sleep_for(FromSeconds(pause(congestion_rng_)));
  }
}

bool ServerDaemon::Gate(Robot& robot, const std::string& name, Request& request,
                        std::span<const std::uint8_t> bytes, TimePoint received, TimePoint arrived) {
  const SessionTable::Admission admission =
      table_->Admit(robot.sessions->robot_id(), request, bytes, received);
  if (table_->keyed()) request.sender = admission.who;
  switch (admission.verdict) {
    case SessionTable::Verdict::kAccepted:
      return true;
    case SessionTable::Verdict::kNoRights:
      request.header_error = admission.why;  // every item is answered ERROR, nothing runs
      Log("robot '" + name + "': refused " + admission.who + ": " + admission.why);
      return true;
    case SessionTable::Verdict::kDuplicate: {
      ImmediateAnswer answer = robot.sessions->Resend(request, received, arrived);
      if (request.panic) {
        // As the first copy was answered: its header and the key's rights are unchanged.
        answer.batch.panic_refusal = request.header_error.empty() ? admission.why : request.header_error;
        answer.batch.panic = answer.batch.panic_refusal.empty() ? PanicStatus::kTaken : PanicStatus::kRefused;
      }
      Send(name, answer.batch);
      return false;
    }
    case SessionTable::Verdict::kRefused:
      Log("robot '" + name + "': dropped a package of " + admission.who + ": " + admission.why);
      return false;
    case SessionTable::Verdict::kUnknownSession:
      break;
  }
  ReplyBatch unknown;
  const bool raised = request.panic && !table_->keyed();
  if (raised) {
    // Open mode: a panic is honoured from anyone, in a session or not (a
    // client whose server restarted must still be able to stop the robot).
    robot.sessions->RaisePanic(request.client_id, received);
    robot.daemon->FinishPanic();
    unknown.panic = PanicStatus::kTaken;
  } else if (request.panic) {
    unknown.panic = PanicStatus::kRefused;
    unknown.panic_refusal =
        "keyed mode: a panic is taken only in an authenticated session, and this server instance has no "
        "session " +
        std::to_string(request.session_id) + "; say hello and send it again";
    Log("robot '" + name + "': refused a panic of " + admission.who + " outside any session");
  }
  const bool answer = request.client_id != 0;
  if (answer && signer_ && !raised) {
    // Keyed: the answer costs a signature; within the budget only (see
    // ServerDaemonOptions::unknown_answers_per_second).
    AnswerBudget& budget = request.panic ? unknown_panic_budget_ : unknown_budget_;
    if (!budget.Take(received, options_.unknown_answers_per_second)) {
      ++unknown_unanswered_;
      Log("keyed mode: packages naming no session of this server left unanswered past the budget of " +
          std::to_string(options_.unknown_answers_per_second) + " signed answers a second (a flood?)");
      return false;
    }
  }
  unknown.client_id = request.client_id;
  unknown.session_id = request.session_id;
  unknown.session_status = SessionStatus::kUnknown;
  unknown.ack_sequence = request.sequence > 0 ? request.sequence : 0;
  unknown.server_receive = arrived;
  if (raised) {
    Drain(robot, /*wait=*/true, answer ? &unknown : nullptr);  // on disk before TAKEN is sent
  } else if (answer) {
    Send(name, unknown);
  }
  return false;
}

void ServerDaemon::OnHello(const std::string& channel, std::span<const std::uint8_t> bytes) {
  const TimePoint received = clock_.Now();
  const std::optional<std::string> robot_name = RobotOfHelloChannel(channel);
  if (!robot_name) return;
  auto it = robots_.find(*robot_name);
  if (it == robots_.end() || !it->second.refused.empty()) return;
  Hello hello;
  try {
    hello = DecodeHello(bytes);
  } catch (const ProtocolError& e) {
    ++malformed_;
    Log("robot '" + *robot_name + "': dropped a malformed hello: " + e.what());
    return;
  }
  const HelloAnswer answer = table_->Answer(it->second.sessions->robot_id(), hello, received);
  if (answer.session_id == 0) {
    Log("robot '" + *robot_name + "': refused a hello of client " +
        Hex64(static_cast<std::uint64_t>(hello.body.client_id)) + ": " + answer.refusal);
  }
  transport_.Publish(HelloAnswerChannel(*robot_name, hello.body.client_id), EncodeHelloAnswer(answer));
}

// The ServerDaemon's half of the pump (daemon_pump.h): the RobotDaemon's
// output filed, the panic state on disk, then `ack` (the answer to the
// package just handled), the state samples and the replies sent.
void ServerDaemon::Drain(Robot& robot, bool wait, ReplyBatch* ack) {
  PumpOutput(*robot.daemon, *robot.sessions, robot.output, to_send_, wait);
  Persist(robot);  // a driver fault latched by the RobotDaemon; a panic or reset just handled
  if (!robot.output.audit.empty()) {
    // soak.md: an audit line is on stderr before its reply leaves, so a
    // reply never exists without its line (a server killed in between).
    for (std::string& line : robot.output.audit) log_pending_.push_back(std::move(line));  // never limited
    WriteLog();
  }
  const std::string& name = robot.daemon->robot_name();
  if (ack) Send(name, *ack);
  for (std::size_t i = 0; i < robot.output.num_samples; ++i) {
    StateSample sample = ToStateSample(name, robot.config_hash, robot.output.samples[i]);
    sample.link = robot.sessions->MotionLink();  // the motion owner's link health (issue 23)
    std::vector<std::uint8_t> bytes = EncodeStateSample(sample);
    const std::string channel = StateChannel(name);
    if (signer_) signer_->Sign(channel, bytes);  // keyed: readers verify the server key (issue 19)
    transport_.Publish(channel, bytes);
  }
  for (ReplyBatch& batch : to_send_) Send(name, batch);
  for (const std::string& line : robot.sessions->TakeLog()) Log(line);
}

void ServerDaemon::Send(const std::string& robot, ReplyBatch& batch) {
  const std::string channel = ReplyChannel(robot, batch.client_id);
  batch.server_id = server_id_;
  if (batch.session_id == 0) {
    batch.session_id = table_->LiveSession(robots_.at(robot).sessions->robot_id(), batch.client_id);
  }
  const auto publish = [&](ReplyBatch& part) {
    part.server_send = clock_.Now();
    std::vector<std::uint8_t> bytes = EncodeReplyBatch(part);
    if (part.session_status == SessionStatus::kOk) {
      if (!table_->Seal(part.session_id, bytes)) return;  // its session closed: the client said hello again
    } else if (signer_) {
      // Keyed: no session key to seal with, so the server key signs it; a
      // keyed client believes no other (a fake server's would end its sessions).
      signer_->Sign(channel, bytes);
    }
    for (int copies = faults_.Copies(); copies > 0; --copies) transport_.Publish(channel, bytes);
  };
  // Split long batches so each package stays well under LCM's 64 KB.
  std::size_t bytes = 0;
  std::vector<Reply> replies = std::move(batch.replies);
  ReplyBatch part = batch;  // the header fields
  part.replies.clear();
  for (Reply& r : replies) {
    bytes += 64 + r.message.size() + 8 * r.values.size();
    part.replies.push_back(std::move(r));
    if (bytes > kMaxBatchBytes) {
      publish(part);
      part.replies.clear();
      bytes = 0;
      // The ack (and the panic's answer) is the received copy's: in the
      // first part only, so that a client counting acks against the copies
      // it sent (LinkLoss) never takes a part for a copy.
      part.ack_sequence = 0;
      part.panic = PanicStatus::kNone;
      part.panic_refusal.clear();
    }
  }
  if (!part.replies.empty() || part.ack_sequence != 0 || part.session_status != SessionStatus::kOk) {
    publish(part);
  }
}

void ServerDaemon::Watchdogs(TimePoint now) {
  for (auto& [name, robot] : robots_) {
    if (robot.daemon->CheckOverrun(now)) Drain(robot);
    // The one expiry (SessionTable::Expire): a package of an expired session
    // is never executed again.
    for (const ExpiredSession& e : robot.sessions->Expire(now)) {
      // Quiet for the ordinary case: a short-lived client (the CLI) that is done.
      if (e.dropped_commands == 0 && !e.moved_robot) continue;
      Log("robot '" + name + "': client " + Hex64(static_cast<std::uint64_t>(e.client_id)) +
          " went silent; " + std::to_string(e.dropped_commands) + " queued commands dropped");
    }
  }
}

void ServerDaemon::Announce(TimePoint now) {
  Announcement a;
  a.server_id = server_id_;
  a.server_time = now;
  a.uptime = started_ == TimePoint::min() ? Duration(0) : now - started_;
  a.url_hint = transport_.url();
  a.traffic_layout = options_.traffic_layout;
  a.keyed = table_->keyed();
  for (const auto& [name, robot] : robots_) {
    if (!robot.refused.empty()) continue;
    const RobotModel& m = robot.daemon->model();
    a.robots.push_back({name, robot.daemon->driver_name(), robot.config_hash, m.num_dofs(),
                        m.roots().front().base, robot.daemon->in_panic(),
                        static_cast<int>(robot.sessions->num_sessions())});
  }
  std::vector<std::uint8_t> bytes = EncodeAnnouncement(a);
  if (signer_) signer_->Sign(kAnnounceChannel, bytes);
  transport_.Publish(kAnnounceChannel, bytes);
}

void ServerDaemon::Log(const std::string& line) { log_limiter_.Add(line, clock_.Now(), log_pending_); }

void ServerDaemon::WriteLog() {
  // Waits for stderr, but never longer than LogWriter::kMaxWait (a stderr
  // that takes nothing would stop the panics and the watchdogs).
  if (!log_pending_.empty()) log_writer_.Write(log_pending_);
}

}  // namespace robotalk
