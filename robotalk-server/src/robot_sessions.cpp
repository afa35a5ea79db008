#include "robot_sessions.h"

#include "robot_sessions_text.h"
#include "robotalk/channels.h"
#include "robotalk/request.h"
#include "speed_ramp.h"
#include "trajectory_tracker.h"

#include <algorithm>

namespace robotalk {

using namespace sessions_text;

std::size_t QueuedItemBytes() {
  // Waiting: the item in its client's heap or in a playback buffer (a vector: up to
  // twice its size in capacity), a buffered frame's estimator entry (offset,
  // arrival, optional delay, the server's lag: 5 durations; a vector, twice
  // in capacity), and its timed-servo entry (a hash-map node).
  constexpr std::size_t kEstimatorFrame = 2 * 5 * sizeof(Duration);
  constexpr std::size_t kTimedServo =
      sizeof(std::pair<const CommandId, std::pair<TimePoint, int>>) + 3 * sizeof(void*);
  constexpr std::size_t kWaiting = 2 * sizeof(PlaybackSequence::Frame) + kEstimatorFrame + kTimedServo;
  return std::max({kWaiting, TrajectoryTracker::kHeldWaypointBytes, SpeedRamp::kHeldFrameBytes});
}

RobotSessions::RobotSessions(RobotDaemon& daemon, std::uint64_t config_hash, SessionOptions options,
                             SessionTable& table)
    : RobotSessions(daemon, config_hash, options, nullptr, &table) {}

RobotSessions::RobotSessions(RobotDaemon& daemon, std::uint64_t config_hash, SessionOptions options)
    : RobotSessions(daemon, config_hash, options, std::make_unique<SessionTable>(0, SessionTableOptions{}),
                    nullptr) {}

RobotSessions::RobotSessions(RobotDaemon& daemon, std::uint64_t config_hash, SessionOptions options,
                             std::unique_ptr<SessionTable> own, SessionTable* table)
    : daemon_(daemon),
      robot_(daemon.robot_name()),
      config_hash_(config_hash),
      options_(options),
      own_table_(std::move(own)),
      table_(table != nullptr ? *table : *own_table_),
      robot_id_(table_.AddRobot(robot_, options.replies)),
      joint_owner_(daemon.model().joints().size(), 0) {}

Session& RobotSessions::SessionFor(std::int64_t client_id, TimePoint now) {
  return table_.FindOrOpen(robot_id_, client_id, now);
}

std::size_t RobotSessions::Waiting(const Session& s) const {
  return daemon_.queued(s.client_id) + s.buffered_frames();
}

std::string RobotSessions::QueueRefusal(const Session& s) {
  if (!count_.known) {
    count_.known = true;
    count_.own = Waiting(s);
    count_.total = daemon_.queued_total();
    for (const auto& [id, session] : table_.live(robot_id_)) count_.total += session->buffered_frames();
  }
  // Built only for a refusal: admission is the receive path.
  const auto has = [&] {
    return Client(s.client_id) + " has " + std::to_string(count_.own) + " commands queued on robot '" +
           robot_ + "'; the limit is ";
  };
  if (count_.own >= options_.max_queue) {
    return has() + std::to_string(options_.max_queue) + " (--max-queue)";
  }
  // Half the robot's bound is the clients' guaranteed shares; past its own, a
  // client draws on the other half only while it has room (header).
  const std::size_t share =
      options_.max_robot_queue / (2 * std::max<std::size_t>(options_.max_sessions_per_robot, 1));
  if (count_.own >= share && count_.total >= options_.max_robot_queue / 2) {
    return has() + std::to_string(share) + " while the robot's queues are full (" +
           std::to_string(count_.total) + " commands of all clients; each client may always queue " +
           std::to_string(share) + ", the robot holds at most " + std::to_string(options_.max_robot_queue) +
           ")";
  }
  ++count_.own;
  ++count_.total;
  return "";
}

RobotSessions::SessionMemory RobotSessions::memory(std::int64_t client_id) const {
  SessionMemory m;
  const Session* found = table_.Find(robot_id_, client_id);
  if (found == nullptr) return m;
  const Session& s = *found;
  m.reply_cache = s.replies.bytes();
  m.playbacks = s.playback_bytes();
  m.waiting = Waiting(s);
  m.waiting_bytes = m.waiting * QueuedItemBytes();
  m.unfinished_playbacks = s.playbacks.size();
  m.timed_servos = s.timed_servos.size();
  return m;
}

std::vector<Reply> RobotSessions::Retransmitted(const Session& s, const Request& r, TimePoint now) const {
  if (s.replies.HasPackage(r.sequence)) return s.replies.RepliesFor(r.sequence);
  // Older than the reply cache: its items still waiting are answered when
  // they end; the others get an answer that says what is known.
  std::vector<CommandId> ids = r.item_ids();
  if (r.mode == RequestMode::kPlayback) ids.push_back(r.playback.id);
  std::vector<Reply> out;
  for (CommandId id : ids) {
    const std::optional<std::optional<Reply>> known = s.replies.Lookup(id);
    if (known && *known) out.push_back(**known);
    if (known) continue;
    const ReplyCache::Limits& limits = s.replies.limits();
    out.push_back(
        MakeReply(id, Signal::kError,
                  "package " + std::to_string(r.sequence) +
                      " was seen before (or is too old to tell) and does not run again; its replies "
                      "are older than what this session keeps (its latest " +
                      std::to_string(limits.max_packages) + " packages, " + KiB(limits.max_bytes) +
                      "): its outcome is unknown here (read the robot's state)",
                  now));
  }
  return out;
}

ImmediateAnswer RobotSessions::Handle(const Request& r, TimePoint now, TimePoint arrived) {
  DecidePlaybacks(now);  // a sequence whose wait for a second copy ended starts first
  // What measures the link reads `arrived`; what decides whether and when
  // something runs, or whether the session lives, reads `now`: a package
  // that waited in the socket's buffer must not be judged earlier than it
  // could act (an expiry, a start time, a session's silence).
  // A session the robot has not served (all its packages refused: rights,
  // the robot full) holds nothing on it: any new package keeps it. A served
  // one is kept only by packages it admits (below): a client that moved the
  // robot and then sends only refused packages is stopped when it expires.
  if (Session* s = table_.Find(robot_id_, r.client_id);
      s != nullptr && !s->active && s->seen.Check(r.sequence) == SequenceWindow::Verdict::kNew) {
    s->last_heard = now;
  }
  if (!r.header_error.empty()) return Refuse(r, now, arrived);
  ImmediateAnswer answer;
  answer.batch.client_id = r.client_id;
  answer.batch.ack_sequence = r.sequence;
  answer.batch.server_receive = arrived;  // the client's clock sample (t2): the link's, not our lag
  std::vector<Reply>& immediate = answer.batch.replies;
  count_.known = false;
  // The panic flag is acted on for every admitted package with a sound
  // header, whatever the session bookkeeping below decides about its items
  // (a duplicate was acted on when first seen): the answer says so.
  if (r.panic) answer.batch.panic = PanicStatus::kTaken;

  const auto refuse_all = [&](const std::string& why) {
    ++refused_packages_;
    if (r.panic) Panic(r.client_id, now, r.sender);
    for (CommandId id : r.item_ids()) immediate.push_back(MakeReply(id, Signal::kError, why, now));
    return answer;
  };
  if (Session* known = table_.Find(robot_id_, r.client_id);
      (known == nullptr || !known->active) && table_.active(robot_id_) >= options_.max_sessions_per_robot) {
    // Recorded in the session's window like any package, so that its replay
    // is a duplicate, answered from the cache and never acted on again (its
    // panic included), and does not keep the session alive.
    if (known != nullptr) {
      const SequenceWindow::Verdict seen = known->seen.Observe(r.sequence);
      if (seen == SequenceWindow::Verdict::kDuplicate) {
        immediate = Retransmitted(*known, r, now);
        return answer;
      }
      if (seen == SequenceWindow::Verdict::kNew) known->replies.RecordPackage(r.sequence, r.item_ids());
    }
    refuse_all("robot '" + robot_ + "' serves " + std::to_string(options_.max_sessions_per_robot) +
               " clients already (the --max-sessions-per-robot bound); try again later");
    for (Reply& reply : immediate) {
      Bound(reply);
      if (known != nullptr) known->replies.RecordReply(reply);
    }
    return answer;
  }
  Session& session = SessionFor(r.client_id, now);
  if (!session.active) session.link = LinkHealth(options_.link);
  session.active = true;
  session.who = r.sender.empty() ? Client(r.client_id) : r.sender;
  const SequenceWindow::Verdict seen = session.seen.Observe(r.sequence);
  bool resent = false;  // a retransmission whose first copy was lost (link_health.h)
  if (seen == SequenceWindow::Verdict::kNew)
    resent = session.link.OnPackage(r.sequence, /*duplicate=*/false, r.send_time, arrived, r.round_trip);
  if (seen == SequenceWindow::Verdict::kTooManyGaps) {
    // A client numbers its packages 1, 2, 3...: a jump that leaves this many
    // numbers unreceived is not one of its packages (sequence_window.h).
    return refuse_all("package sequence " + std::to_string(r.sequence) + " jumps ahead of " +
                      std::to_string(session.seen.highest()) + " and would leave more than " +
                      std::to_string(SequenceWindow::kMaxUnseen) +
                      " sequence numbers of this client never received; refused");
  }
  if (seen == SequenceWindow::Verdict::kDuplicate) {
    // It does not refresh the session (a replay must not keep it alive).
    immediate = AnswerCopy(session, r, now, arrived);
    return answer;
  }
  session.last_heard = now;  // only a new, well-formed package refreshes the session
  std::vector<CommandId> ids = r.item_ids();
  // The playback delay reply (id = playback id) may come with any of its packages.
  const bool playback = r.mode == RequestMode::kPlayback;
  if (playback) ids.push_back(r.playback.id);
  session.replies.RecordPackage(r.sequence, ids);

  for (const MalformedItem& m : r.malformed)
    immediate.push_back(MakeReply(m.id, Signal::kError, m.reason, now));
  if (r.panic) {
    Panic(r.client_id, now, r.sender);
    for (CommandId id : r.item_ids()) {
      immediate.push_back(
          MakeReply(id, Signal::kPanic, "the package carried the panic flag; not executed", now));
    }
  } else if (playback) {
    AdmitPlayback(session, r, now, arrived, immediate);
  } else {
    for (const Query& q : r.queries) AdmitQuery(session, q, now, immediate, answer.publish_config);
    for (const Command& c : r.commands) {
      auto item = Admit(session, c, now, immediate, /*playback=*/false, r.max_late, r.interpolation);
      if (item && !Superseded(session, *item, now, immediate)) daemon_.Submit(std::move(*item));
    }
  }
  // Playback's start reads the one-way delays: a retransmission's arrival −
  // send time is the client's resend wait + a delay (issue 23: one lost
  // connect-time package on a WAN tripped the adaptive start's gate).
  // Recorded after its items: a sequence's first frame reads the history of
  // the packages before it and counts its own delay once, as a frame. On
  // `now`, not `arrived`: a frame can play only once handled, so this
  // server's own lag (a pause after each package, the paper's Fig. 11
  // congestion) is part of the delay the start must cover (with `arrived`
  // the gate missed it: ServerClientTest.PlaybackKeepsTheInterFrameTiming-
  // UnderCongestion, frames 0.4 s late). The lag (now − arrived) is kept
  // beside it: a queue beyond the adaptive start's gate is followed only
  // where it was the link's, not this server's (follow_queue).
  if (r.send_time != TimePoint{} && (!resent || options_.playback_resent_delays))
    session.delays.Add(r.send_time, now, arrived);
  else if (r.send_time != TimePoint{})
    session.delays.AddCopy(r.send_time, now);  // a retransmission: only that the next package met it
  for (Reply& reply : immediate) {
    Bound(reply);
    session.replies.RecordReply(reply);
  }
  return answer;
}

void RobotSessions::Bound(Reply& reply) const {
  if (reply.message.size() <= options_.max_message_bytes) return;
  reply.message.resize(options_.max_message_bytes);
  reply.message += "... (truncated)";
}

ImmediateAnswer RobotSessions::Resend(const Request& r, TimePoint now, TimePoint arrived) {
  ImmediateAnswer answer;
  answer.batch.client_id = r.client_id;
  answer.batch.ack_sequence = r.sequence;
  answer.batch.server_receive = arrived;
  if (Session* s = table_.Find(robot_id_, r.client_id))
    answer.batch.replies = AnswerCopy(*s, r, now, arrived);
  return answer;
}

std::vector<Reply> RobotSessions::AnswerCopy(Session& s, const Request& r, TimePoint now, TimePoint arrived) {
  s.link.OnPackage(r.sequence, /*duplicate=*/true, r.send_time, arrived, r.round_trip);
  // On a FIFO link the package after this copy waited behind it (playback's
  // start, "The copies" in playback_estimator.h).
  if (r.send_time != TimePoint{}) s.delays.AddCopy(r.send_time, now);
  std::vector<Reply> replies = Retransmitted(s, r, now);
  OnPlaybackCopy(s, r, now, replies);  // frame 0's second copy: a waiting sequence starts
  return replies;
}

ImmediateAnswer RobotSessions::Refuse(const Request& r, TimePoint now, TimePoint arrived) {
  ImmediateAnswer answer;
  answer.send = r.client_id != 0;
  answer.batch.client_id = r.client_id;
  answer.batch.ack_sequence = r.sequence > 0 ? r.sequence : 0;
  answer.batch.server_receive = arrived;
  const std::vector<CommandId> ids = r.item_ids();
  ++refused_packages_;
  if (r.panic) {
    answer.batch.panic = PanicStatus::kRefused;
    answer.batch.panic_refusal = r.header_error;
  }
  for (CommandId id : ids) {
    answer.batch.replies.push_back(MakeReply(id, Signal::kError, r.header_error, now));
    Bound(answer.batch.replies.back());
  }
  // Remember it in an existing session, so a retransmission of the same bad
  // package gets the same answer; a refused package neither opens nor
  // refreshes a session.
  if (Session* s = table_.Find(robot_id_, r.client_id); s != nullptr && r.sequence > 0) {
    Session& session = *s;
    if (session.seen.Observe(r.sequence) == SequenceWindow::Verdict::kNew) {
      session.replies.RecordPackage(r.sequence, ids);
      for (const Reply& reply : answer.batch.replies) session.replies.RecordReply(reply);
    }
  }
  return answer;
}

std::optional<QueuedItem> RobotSessions::Admit(Session& s, const Command& c, TimePoint now,
                                               std::vector<Reply>& immediate, bool playback,
                                               Duration max_late, Interpolation interpolation) {
  const RobotModel& model = daemon_.model();
  if (c.type == CommandType::kPanicReset) {
    if (auto bad = CheckCommand(model, c, options_.limits)) {
      immediate.push_back(MakeReply(c.id, bad->signal, bad->message, now));
    } else if (daemon_.ResetPanic()) {
      log_.push_back("robot '" + robot_ + "': panic reset by " + s.who);
      immediate.push_back(MakeReply(c.id, Signal::kSuccess, "panic reset", now));
    } else {
      immediate.push_back(MakeReply(c.id, Signal::kSuccess, "the robot was not in panic", now));
    }
    return std::nullopt;
  }
  if (daemon_.in_panic()) {
    const std::string fault = daemon_.fault();
    immediate.push_back(MakeReply(c.id, Signal::kPanic,
                                  "robot '" + robot_ + "' is in panic" +
                                      (fault.empty() ? "" : " (" + fault + ")") +
                                      "; nothing executes until PANIC_RESET",
                                  now));
    return std::nullopt;
  }
  if (auto bad = CheckCommand(model, c, options_.limits)) {
    immediate.push_back(MakeReply(c.id, bad->signal, bad->message, now));
    return std::nullopt;
  }
  // A playback frame's start time is its offset from the sequence start.
  // A playback frame starts after an offset from the sequence start; a
  // direct or delay command at a server-clock time (the codec checked the
  // kind against the package mode).
  const Duration ahead = c.start_time.is_after() ? *c.start_time.offset()
                         : c.start_time.is_at()  ? SaturatingSub(*c.start_time.time(), now)
                                                 : Duration(0);
  // A STOP due now or in the past runs at once, whatever its clock or the
  // client's queue: "a STOP always runs, however late" (it empties what it
  // stops, so it cannot grow the queue). Not a playback frame: its offset
  // counts from a start not yet decided, and its buffer has its own bound.
  const bool stop_now = !playback && Traits(c.type).kind == CommandKind::kStop && ahead <= Duration(0);
  bool run_now = false;
  // As far behind as the limit ahead: a clock that wrong is a bug to report,
  // not a command to run late (and its lateness must stay in range); a STOP
  // runs now, and the server's log says the clock was wrong.
  if (c.start_time.is_at() && ahead < -options_.max_future && stop_now) {
    log_.push_back("robot '" + robot_ + "': " + s.who + "'s STOP " + std::to_string(c.id) + " was due " +
                   Seconds(SaturatingSub(now, *c.start_time.time())) +
                   " in the past of the server clock (is the client's clock synchronised?); run now");
    run_now = true;
  } else if (c.start_time.is_at() && ahead < -options_.max_future) {
    immediate.push_back(MakeReply(c.id, Signal::kError,
                                  std::string(ToString(c.type)) + ": start time is " +
                                      Seconds(SaturatingSub(now, *c.start_time.time())) +
                                      " in the past of the server clock; the limit is " +
                                      Seconds(options_.max_future) + " (is the client's clock synchronised?)",
                                  now));
    return std::nullopt;
  }
  if (ahead > options_.max_future) {
    immediate.push_back(MakeReply(c.id, Signal::kError,
                                  std::string(ToString(c.type)) + ": start time is " + Seconds(ahead) +
                                      " ahead" +
                                      (playback ? " of the sequence start" : " of the server clock") +
                                      "; the limit is " + Seconds(options_.max_future),
                                  now));
    return std::nullopt;
  }
  if (std::string full = stop_now ? std::string() : QueueRefusal(s); !full.empty()) {
    immediate.push_back(MakeReply(c.id, Signal::kError, std::move(full) + "; command not queued", now));
    return std::nullopt;
  }
  QueuedItem item;
  item.client_id = s.client_id;
  item.has_start_time = !c.start_time.is_now() && !run_now;
  if (c.start_time.is_at() && !run_now) item.start = *c.start_time.time();
  item.received = now;
  item.max_late = EffectiveMaxLate(c.type, item.has_start_time, max_late, options_.max_late);
  item.command.id = c.id;
  item.command.type = c.type;
  switch (Traits(c.type).target) {  // CheckCommand found it
    case CommandTarget::kJoint:
      item.command.target = *model.FindJoint(c.target);
      break;
    case CommandTarget::kFrame:
      item.command.target = *model.FindFrame(c.target);
      break;
    case CommandTarget::kBase:
    case CommandTarget::kRobot:
      break;
  }
  // CheckCommand bounds the count: at most 6 dofs, 7 pose values, 3 base values.
  item.command.num_values = static_cast<int>(c.values.size());
  std::copy(c.values.begin(), c.values.end(), item.command.values.begin());
  // A waypoint's rates: CheckCommand bounds them to one per dof (a joint's
  // at most 6) or 6 for a frame.
  item.num_velocities = static_cast<int>(c.velocities.size());
  std::copy(c.velocities.begin(), c.velocities.end(), item.velocities.begin());
  item.num_accelerations = static_cast<int>(c.accelerations.size());
  std::copy(c.accelerations.begin(), c.accelerations.end(), item.accelerations.begin());
  item.interpolation = interpolation;
  return item;
}

void RobotSessions::Panic(std::int64_t client_id, TimePoint now, const std::string& sender) {
  const bool first = !daemon_.in_panic();
  const std::string who = sender.empty() ? Client(client_id) : sender;
  log_.push_back("robot '" + robot_ + "': PANIC from " + who + (first ? "" : " (already in panic)"));
  flushed_.clear();
  daemon_.Panic(flushed_);
  for (const auto& [id, s] : table_.live(robot_id_))
    EndPlaybacks(*s, Session::Ended::kPanic, "panic from " + who, now);
  for (const QueuedItem& item : flushed_) {
    if (item.client_id == 0) continue;
    Deliver(item.client_id,
            MakeReply(item.command.id, Signal::kInterrupted, "flushed by panic from " + who, now));
  }
}

void RobotSessions::EndPlaybacks(Session& s, Session::Ended ended, const std::string& why, TimePoint now) {
  std::vector<std::int64_t> ids;
  for (auto& [pid, seq] : s.playbacks) {
    for (PlaybackSequence::Frame& frame : seq.frames) flushed_.push_back(std::move(frame.item));
    if (!seq.start) {  // its delay reply was never sent: it never will be
      Deliver(s.client_id,
              MakeReply(pid, Signal::kInterrupted,
                        "PLAYBACK " + std::to_string(pid) + ": ended by " + why + " before it started", now));
    }
    ids.push_back(pid);
  }
  for (std::int64_t pid : ids) s.EndPlayback(pid, ended);
}

void RobotSessions::Deliver(std::int64_t client_id, Reply reply) {
  Session* s = table_.Find(robot_id_, client_id);
  if (s == nullptr) return;           // an expired client
  NoteServoAnswer(client_id, reply);  // also a flushed one's: its entry is freed
  const bool expired = IsExpiryReply(reply);
  if (expired) ++expired_commands_;
  s->link.OnReply(reply.lateness, expired, reply.exec_time);
  s->replies.RecordReply(reply);
  pending_[client_id].push_back(std::move(reply));
}

void RobotSessions::File(DaemonOutput& output, std::vector<ReplyBatch>& to_send) {
  for (const DaemonOutput::Executed& e : output.executed) Own(e);
  for (DaemonOutput::Answer& a : output.replies) Deliver(a.client_id, std::move(a.reply));
  for (auto& line : output.log) log_.push_back(std::move(line));
  for (auto& [client, replies] : pending_) {
    if (replies.empty()) continue;
    ReplyBatch batch;
    batch.client_id = client;
    batch.replies = std::move(replies);
    to_send.push_back(std::move(batch));
  }
  pending_.clear();
}

namespace {
// The actuator a servo command drives, as a key: a joint's index, a control
// frame's (offset), the base (-1); nullopt for tasks and whole-robot commands.
std::optional<int> ServoActuator(const DriverCommand& c) {
  const CommandTraits& t = Traits(c.type);
  if (t.kind != CommandKind::kServo) return std::nullopt;
  switch (t.target) {
    case CommandTarget::kJoint:
      return c.target;
    case CommandTarget::kFrame:
      return 1'000'000 + c.target;
    case CommandTarget::kBase:
      return -1;
    case CommandTarget::kRobot:
      break;
  }
  return std::nullopt;
}
}  // namespace

// Issue 9 ("stale set-points ran after newer ones") and the soak: a delay or
// playback frame lost twice reached the server after later frames had run,
// and ran at once, moving the robot back in time. Such a command is answered
// INTERRUPTED instead. (A window remains between a later command running and
// its reply being filed here; the RobotDaemon's scheduler orders whatever is
// queued at the same time.)
bool RobotSessions::Superseded(Session& s, const QueuedItem& item, TimePoint now,
                               std::vector<Reply>& immediate) {
  const std::optional<int> actuator = ServoActuator(item.command);
  if (!actuator || !item.has_start_time) return false;
  if (const auto it = s.latest_servo_start.find(*actuator);
      it != s.latest_servo_start.end() && item.start < it->second) {
    immediate.push_back(
        MakeReply(item.command.id, Signal::kInterrupted,
                  std::string(ToString(item.command.type)) +
                      ": superseded: a command of this client on the same actuator starting " +
                      Seconds(it->second - item.start) + " later has already run; not executed",
                  now));
    return true;
  }
  s.timed_servos[item.command.id] = {item.start, *actuator};
  return false;
}

void RobotSessions::NoteServoAnswer(std::int64_t client_id, const Reply& reply) {
  Session* session = table_.Find(robot_id_, client_id);
  if (session == nullptr) return;
  Session& s = *session;
  const auto it = s.timed_servos.find(reply.id);
  if (it == s.timed_servos.end()) return;
  if (reply.signal == Signal::kSuccess || reply.signal == Signal::kModified) {
    TimePoint& latest = s.latest_servo_start.try_emplace(it->second.second, it->second.first).first->second;
    latest = std::max(latest, it->second.first);
  }
  s.timed_servos.erase(it);
}

void RobotSessions::Own(const DaemonOutput::Executed& e) {
  const RobotModel& model = daemon_.model();
  const CommandTraits& traits = Traits(e.type);
  if (traits.kind == CommandKind::kStop) {  // the whole robot is at rest: nobody owns anything
    std::fill(joint_owner_.begin(), joint_owner_.end(), 0);
    base_owner_ = 0;
    motion_owner_ = 0;
    return;
  }
  // What the command moves becomes its client's. A command the RobotDaemon
  // took just before the watchdog expired its client was not covered by the
  // watchdog's stop: it is stopped now and nobody owns it. (The vector is
  // only filled in that rare case: this is every executed command's path.)
  const bool vanished = table_.Find(robot_id_, e.client_id) == nullptr;
  std::vector<int> to_stop;
  const auto take = [&](int j) {
    if (vanished) {
      to_stop.push_back(j);
    } else {
      joint_owner_[static_cast<std::size_t>(j)] = e.client_id;
    }
  };
  bool base = false;
  switch (traits.target) {
    case CommandTarget::kJoint:
      take(e.target);
      break;
    case CommandTarget::kFrame:  // the joints on the frame's chain
      for (int j : model.frame_chain(e.target)) {
        if (!model.joint(j).dofs.empty()) take(j);
      }
      break;
    case CommandTarget::kBase:
      base = true;
      break;
    case CommandTarget::kRobot:
      return;
  }
  if (!vanished) {
    motion_owner_ = e.client_id;
    if (base) base_owner_ = e.client_id;
  } else if (base || !to_stop.empty()) {
    daemon_.QueueStopOnly(std::move(to_stop), base);
  }
}

std::vector<ExpiredSession> RobotSessions::Expire(TimePoint now) {
  CheckLinks(now);
  std::vector<ExpiredSession> expired;
  for (Session& s : table_.Expire(robot_id_, now, options_.session_timeout)) {
    const std::int64_t client = s.client_id;
    pending_.erase(client);
    if (!s.active) continue;  // the robot never served it: nothing of it to stop
    flushed_.clear();
    daemon_.FlushClient(client, flushed_);
    const std::size_t dropped = flushed_.size() + s.buffered_frames();
    expired.push_back({client, dropped, StopOwned(client, Client(client) + " vanished")});
    daemon_.SetStream(client, Duration(0));
  }
  return expired;
}

std::vector<std::string> RobotSessions::TakeLog() { return std::exchange(log_, {}); }

}  // namespace robotalk
