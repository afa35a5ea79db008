#include "robot_service.h"

#include "robot_service_helpers.h"

#include "robotalk/channels.h"
#include "robotalk/config_codec.h"
#include "robotalk/error.h"
#include "robotalk/protocol_codec.h"

#include <cinttypes>
#include <cmath>
#include <cstdio>

namespace robotalk {
using service_detail::AppendPose;
using service_detail::MakeReply;

RobotService::RobotService(std::string name, std::string driver_name, std::unique_ptr<Driver> driver,
                           const Clock& clock, RobotServiceOptions options)
    : name_(std::move(name)),
      driver_name_(std::move(driver_name)),
      driver_(std::move(driver)),
      clock_(clock),
      options_(options),
      kinematics_(driver_->model()) {
  encoded_config_ = EncodeConfig(model());
  config_hash_ = ConfigHash(model());
  const RobotModel& m = model();
  state_.position = Eigen::VectorXd::Zero(m.num_dofs());
  state_.velocity = Eigen::VectorXd::Zero(m.num_dofs());
  state_.effort = Eigen::VectorXd::Zero(m.num_dofs());
  for (const RootLink& r : m.roots()) state_.root_poses.push_back(r.pose_in_world);
  due_.reserve(256);
  completions_.reserve(64);
  produced_.reserve(256);
}

RobotService::~RobotService() { Stop(); }

void RobotService::Start() {
  std::lock_guard lock(mutex_);
  if (running_) return;
  running_ = true;
  daemon_ = std::thread([this] { DaemonLoop(); });
}

void RobotService::Stop() {
  {
    std::lock_guard lock(mutex_);
    running_ = false;
  }
  wake_.notify_all();
  if (!daemon_.joinable()) return;
  daemon_.join();
  // The daemon is gone, so this thread may act as it: run what the server
  // itself queued last (the shutdown STOP), so no robot is left moving.
  RunOnce(clock_.Now());
}

void RobotService::DaemonLoop() {
  std::unique_lock lock(mutex_);
  while (running_) {
    lock.unlock();
    const TimePoint next = RunOnce(clock_.Now());
    lock.lock();
    // Absolute deadline: the next start time or driver period, whichever is first.
    wake_.wait_until(lock, next, [this] { return wake_flag_ || !running_; });
    wake_flag_ = false;
  }
}

// --- ServerDaemon side -------------------------------------------------------

Session& RobotService::SessionFor(std::int64_t client_id, TimePoint now) {
  auto it = sessions_.find(client_id);
  if (it == sessions_.end()) it = sessions_.emplace(client_id, Session(client_id, now)).first;
  return it->second;
}

ImmediateAnswer RobotService::HandlePackage(const robotalk_msgs::package_t& package, TimePoint received) {
  const auto& h = package.header;
  ImmediateAnswer answer;
  answer.package.protocol_version = kProtocolVersion;
  answer.package.client_id = h.client_id;
  answer.package.ack_sequence = h.sequence;
  answer.package.server_receive_us = ToWireMicros(received);
  std::vector<Reply> immediate;

  std::lock_guard lock(mutex_);
  Session& session = SessionFor(h.client_id, received);
  session.last_heard = received;

  if (!session.seen.Observe(h.sequence)) {
    // A retransmission or a duplicate: never execute again; re-send what is known.
    immediate = session.replies.RepliesFor(h.sequence);
  } else {
    std::vector<CommandId> ids;
    for (const auto& q : package.queries) ids.push_back(q.id);
    for (const auto& c : package.commands) ids.push_back(c.id);
    // The playback delay reply (id = playback id) may come with any of its packages.
    const bool playback = h.mode == robotalk_msgs::package_header_t::MODE_PLAYBACK;
    if (playback) ids.push_back(h.playback_id);
    session.replies.RecordPackage(h.sequence, ids);

    if (h.panic) {
      PanicNow(h.client_id, received);
      for (CommandId id : ids) {
        immediate.push_back(
            MakeReply(id, Signal::kPanic, "the package carried the panic flag; not executed", received));
      }
    } else if (playback) {
      EnqueuePlayback(session, package, received, immediate);
    } else {
      for (const auto& q : package.queries)
        EnqueueQuery(session, q, received, immediate, answer.publish_config);
      for (const auto& c : package.commands) EnqueueCommand(session, c, received, immediate);
    }
    for (const Reply& r : immediate) session.replies.RecordReply(r);
  }
  for (const Reply& r : immediate) answer.package.replies.push_back(ToWire(r));
  answer.package.num_replies = static_cast<std::int32_t>(answer.package.replies.size());
  return answer;
}

ImmediateAnswer RobotService::RefusePackage(const robotalk_msgs::package_t& package, TimePoint received,
                                            const std::string& reason) {
  ImmediateAnswer answer;
  const auto& h = package.header;
  answer.send = h.client_id != 0;
  answer.package.protocol_version = kProtocolVersion;
  answer.package.client_id = h.client_id;
  answer.package.ack_sequence = h.sequence > 0 ? h.sequence : 0;
  answer.package.server_receive_us = ToWireMicros(received);
  auto refuse = [&](CommandId id) {
    answer.package.replies.push_back(ToWire(MakeReply(id, Signal::kError, reason, received)));
  };
  for (const auto& q : package.queries) refuse(q.id);
  for (const auto& c : package.commands) refuse(c.id);
  answer.package.num_replies = static_cast<std::int32_t>(answer.package.replies.size());
  if (h.client_id != 0 && h.sequence > 0) {
    // Remember it, so a retransmission of the same bad package gets the same answer.
    std::lock_guard lock(mutex_);
    Session& session = SessionFor(h.client_id, received);
    session.last_heard = received;
    if (session.seen.Observe(h.sequence)) {
      std::vector<CommandId> ids;
      for (const auto& r : answer.package.replies) ids.push_back(r.id);
      session.replies.RecordPackage(h.sequence, ids);
      for (const auto& r : answer.package.replies) session.replies.RecordReply(FromWire(r));
    }
  }
  return answer;
}

void RobotService::EnqueueQuery(Session& s, const robotalk_msgs::query_t& wire, TimePoint now,
                                std::vector<Reply>& immediate, bool& publish_config) {
  Query q;
  try {
    q = FromWire(wire);
  } catch (const ProtocolError& e) {
    immediate.push_back(MakeReply(wire.id, Signal::kError, e.what(), now));
    return;
  }
  if (auto bad = CheckQuery(model(), q)) {
    immediate.push_back(MakeReply(q.id, Signal::kError, *bad, now));
    return;
  }
  if (q.type == QueryType::kClock) {
    immediate.push_back(MakeReply(q.id, Signal::kSuccess, "", now));
    return;
  }
  if (q.type == QueryType::kStateStream || q.type == QueryType::kStateStreamCancel) {
    if (q.type == QueryType::kStateStream) {
      stream_requests_[s.client_id] = q.period;
    } else {
      stream_requests_.erase(s.client_id);
    }
    UpdateStream(now);
    Reply r =
        MakeReply(q.id, Signal::kSuccess,
                  stream_period_.count() == 0 ? "no state stream"
                                              : "state every " + std::to_string(ToSeconds(stream_period_)) +
                                                    " s on ROBOTALK/" + name_ + "/STATE",
                  now);
    r.values = {ToSeconds(stream_period_)};
    immediate.push_back(std::move(r));
    return;
  }
  if (q.type == QueryType::kConfig) {
    publish_config = true;
    immediate.push_back(MakeReply(q.id, Signal::kSuccess, Hex64(config_hash_), now));
    return;
  }
  if (s.commands.size() >= options_.max_queue) {
    immediate.push_back(MakeReply(q.id, Signal::kError,
                                  "queue of client " + Hex64(static_cast<std::uint64_t>(s.client_id)) +
                                      " is full (" + std::to_string(options_.max_queue) +
                                      " items); query not queued",
                                  now));
    return;
  }
  QueuedItem item;
  item.arrival = ++arrivals_;
  item.client_id = s.client_id;
  item.is_query = true;
  item.query = q.type;
  item.command.id = q.id;
  if (!q.target.empty()) {
    switch (q.type) {
      case QueryType::kJointState:
        item.query_target = *model().FindJoint(q.target);
        break;
      case QueryType::kLinkPoses:
        item.query_target = *model().FindLink(q.target);
        break;
      case QueryType::kFramePoses:
        item.query_target = *model().FindFrame(q.target);
        break;
      default:
        break;
    }
  }
  s.commands.Push(std::move(item));
  wake_flag_ = true;
  wake_.notify_one();
}

std::optional<QueuedItem> RobotService::PrepareCommand(Session& s, const robotalk_msgs::command_t& wire,
                                                       TimePoint now, std::vector<Reply>& immediate,
                                                       bool playback) {
  Command c;
  try {
    c = FromWire(wire, playback ? robotalk_msgs::package_header_t::MODE_PLAYBACK
                                : robotalk_msgs::package_header_t::MODE_DIRECT);
  } catch (const ProtocolError& e) {
    immediate.push_back(MakeReply(wire.id, Signal::kError, e.what(), now));
    return std::nullopt;
  }
  if (c.type == CommandType::kPanicReset) {
    Signal signal = Signal::kSuccess;
    if (auto bad = CheckCommand(model(), c, &signal)) {
      immediate.push_back(MakeReply(c.id, signal, *bad, now));
    } else if (panic_.exchange(false)) {
      resume_requested_ = true;
      wake_flag_ = true;
      wake_.notify_one();
      std::fprintf(stderr, "robotalk-server: robot '%s': panic reset by client %s\n", name_.c_str(),
                   Hex64(static_cast<std::uint64_t>(s.client_id)).c_str());
      immediate.push_back(MakeReply(c.id, Signal::kSuccess, "panic reset", now));
    } else {
      immediate.push_back(MakeReply(c.id, Signal::kSuccess, "the robot was not in panic", now));
    }
    return std::nullopt;
  }
  if (panic_) {
    immediate.push_back(MakeReply(
        c.id, Signal::kPanic, "robot '" + name_ + "' is in panic; nothing executes until PANIC_RESET", now));
    return std::nullopt;
  }
  Signal signal = Signal::kError;
  if (auto bad = CheckCommand(model(), c, &signal)) {
    immediate.push_back(MakeReply(c.id, signal, *bad, now));
    return std::nullopt;
  }
  // A playback frame's start time is its offset from the sequence start.
  const Duration ahead = c.start_time.is_after() ? *c.start_time.offset()
                         : c.start_time.is_at()  ? *c.start_time.time() - now
                                                 : Duration(0);
  if (ahead > options_.max_future) {
    immediate.push_back(
        MakeReply(c.id, Signal::kError,
                  std::string(ToString(c.type)) + ": start time is " + std::to_string(ToSeconds(ahead)) +
                      " s ahead" + (playback ? " of the sequence start" : " of the server clock") +
                      "; the limit is " + std::to_string(ToSeconds(options_.max_future)) + " s",
                  now));
    return std::nullopt;
  }
  size_t queued = s.commands.size();
  for (const auto& [id, seq] : s.playbacks) queued += seq.frames.size();
  if (queued >= options_.max_queue) {
    immediate.push_back(MakeReply(c.id, Signal::kError,
                                  "queue of client " + Hex64(static_cast<std::uint64_t>(s.client_id)) +
                                      " is full (" + std::to_string(options_.max_queue) +
                                      " items); command not queued",
                                  now));
    return std::nullopt;
  }
  QueuedItem item;
  item.arrival = ++arrivals_;
  item.client_id = s.client_id;
  item.has_start_time = !c.start_time.is_now();
  if (c.start_time.is_at()) item.start = *c.start_time.time();
  if (c.start_time.is_after())
    item.start = TimePoint(*c.start_time.offset());  // read as an offset in _modes.cpp
  item.command.id = c.id;
  item.command.type = c.type;
  if (c.type == CommandType::kFrameSetPoint) {
    item.command.target = *model().FindFrame(c.target);
  } else if (!c.target.empty()) {
    item.command.target = *model().FindJoint(c.target);
  }
  // CheckCommand bounds the count: at most 6 dofs, 7 pose values, 3 base values.
  item.command.num_values = static_cast<int>(c.values.size());
  std::copy(c.values.begin(), c.values.end(), item.command.values.begin());
  return item;
}

void RobotService::EnqueueCommand(Session& s, const robotalk_msgs::command_t& wire, TimePoint now,
                                  std::vector<Reply>& immediate) {
  std::optional<QueuedItem> item = PrepareCommand(s, wire, now, immediate, /*playback=*/false);
  if (!item) return;
  s.commands.Push(std::move(*item));
  wake_flag_ = true;
  wake_.notify_one();
}

void RobotService::PanicNow(std::int64_t client_id, TimePoint now) {
  const bool first = !panic_.exchange(true);
  std::fprintf(stderr, "robotalk-server: robot '%s': PANIC from client %s%s\n", name_.c_str(),
               Hex64(static_cast<std::uint64_t>(client_id)).c_str(), first ? "" : " (already in panic)");
  std::vector<QueuedItem> flushed;
  for (auto& [id, session] : sessions_) {
    session.commands.Flush(flushed);
    for (auto& [pid, seq] : session.playbacks) {
      for (QueuedItem& frame : seq.frames) flushed.push_back(std::move(frame));
    }
    session.playbacks.clear();
  }
  server_queue_.clear();
  for (const QueuedItem& item : flushed) {
    Deliver(item.client_id,
            MakeReply(item.command.id, Signal::kInterrupted,
                      "flushed by panic from client " + Hex64(static_cast<std::uint64_t>(client_id)), now));
  }
  halt_requested_ = true;
  wake_flag_ = true;
  wake_.notify_one();
  if (!flushed.empty() && replies_ready_) replies_ready_();
}

void RobotService::Deliver(std::int64_t client_id, Reply reply) {
  auto it = sessions_.find(client_id);
  if (it == sessions_.end()) return;  // the server's own STOP, or an expired client
  it->second.replies.RecordReply(reply);
  it->second.return_queue.push_back(std::move(reply));
}

void RobotService::TakeReplies(std::vector<OutgoingReplies>& out) {
  std::lock_guard lock(mutex_);
  for (auto& [id, session] : sessions_) {
    if (session.return_queue.empty()) continue;
    out.push_back(OutgoingReplies{id, std::move(session.return_queue)});
    session.return_queue.clear();
  }
}

std::vector<ExpiredSession> RobotService::ExpireSessions(TimePoint now) {
  std::vector<ExpiredSession> expired;
  bool stop = false;
  {
    std::lock_guard lock(mutex_);
    for (auto it = sessions_.begin(); it != sessions_.end();) {
      if (now - it->second.last_heard <= options_.session_timeout) {
        ++it;
        continue;
      }
      expired.push_back({it->first, it->second.commands.size(), it->second.moved_robot});
      stop = stop || it->second.moved_robot;
      stream_requests_.erase(it->first);
      it = sessions_.erase(it);
    }
    if (!expired.empty()) UpdateStream(now);
  }
  if (stop) QueueStop("a client that moved the robot vanished", /*only_if_moving=*/true);
  return expired;
}

void RobotService::StopRobot(const std::string& reason) { QueueStop(reason, /*only_if_moving=*/false); }

void RobotService::QueueStop(const std::string& reason, bool only_if_moving) {
  std::lock_guard lock(mutex_);
  std::fprintf(stderr, "robotalk-server: robot '%s': STOP%s (%s)\n", name_.c_str(),
               only_if_moving ? " if moving" : "", reason.c_str());
  QueuedItem stop;
  stop.arrival = ++arrivals_;
  stop.command.type = CommandType::kStop;
  stop.only_if_moving = only_if_moving;
  server_queue_.push_back(stop);
  wake_flag_ = true;
  wake_.notify_one();
}

robotalk_msgs::robot_info_t RobotService::Info() const {
  robotalk_msgs::robot_info_t info{};
  info.name = name_;
  info.driver = driver_name_;
  info.config_hash = static_cast<std::int64_t>(config_hash_);
  info.total_dofs = model().num_dofs();
  info.base_type = static_cast<std::int8_t>(model().roots().front().base);
  info.panic = panic_.load();
  std::lock_guard lock(mutex_);
  info.num_clients = static_cast<std::int32_t>(sessions_.size());
  return info;
}

// --- RobotDaemon side --------------------------------------------------------

TimePoint RobotService::RunOnce(TimePoint now) {
  bool halt = false, resume = false;
  due_.clear();
  Duration stream_period{0};
  TimePoint next_sample{};
  std::uint64_t stream_generation = 0;
  {
    std::lock_guard lock(mutex_);
    stream_period = stream_period_;
    next_sample = next_sample_;
    stream_generation = stream_generation_;
    halt = std::exchange(halt_requested_, false);
    resume = std::exchange(resume_requested_, false);
    for (QueuedItem& item : server_queue_) due_.push_back(std::move(item));
    server_queue_.clear();
    // Every due item over all clients, earliest start first, ties in arrival order.
    for (;;) {
      Session* first = nullptr;
      for (auto& [id, session] : sessions_) {
        if (session.commands.empty() || session.commands.Top().start > now) continue;
        if (!first || session.commands.Top().RunsBefore(first->commands.Top())) first = &session;
      }
      if (!first) break;
      due_.push_back(first->commands.Pop());
    }
  }

  completions_.clear();
  produced_.clear();
  if (halt) driver_->Halt(completions_);
  if (resume) driver_->Resume();
  for (const QueuedItem& item : due_) Execute(item, now);
  if (now >= next_update_) {
    driver_->Update(now, completions_);
    const Duration period = driver_->period();
    next_update_ = next_update_ == TimePoint::min() ? now + period : next_update_ + period;
    if (next_update_ <= now) next_update_ = now + period;  // overran: skip, don't burst
  }
  // Broadcast (paper §V-D): the state query re-inserts itself one period
  // later. Deadlines are absolute (t0 + k·period), so the stream never
  // drifts; samples missed while the daemon was late are skipped, not burst.
  sampled_.clear();
  if (stream_period.count() > 0 && now >= next_sample) {
    SampleState(now, stream_period);
    next_sample += stream_period * ((now - next_sample) / stream_period + 1);
  }
  for (const Completion& c : completions_) {
    auto owner = in_progress_.find(c.id);
    if (owner == in_progress_.end()) continue;
    Reply r = MakeReply(owner->second.client_command_id, c.signal, c.message, owner->second.started);
    r.lateness = owner->second.lateness;
    produced_.push_back({owner->second.client_id, std::move(r)});
    in_progress_.erase(owner);
  }

  TimePoint next = next_update_;
  {
    std::lock_guard lock(mutex_);
    for (const QueuedItem& item : due_) {
      if (item.is_query) continue;
      if (item.command.type == CommandType::kStop) {
        for (auto& [id, session] : sessions_) session.moved_robot = false;
      } else if (auto s = sessions_.find(item.client_id); s != sessions_.end()) {
        s->second.moved_robot = true;
      }
    }
    for (Produced& p : produced_) Deliver(p.client_id, std::move(p.reply));
    for (auto& m : sampled_) state_outbox_.push_back(std::move(m));
    if (stream_generation == stream_generation_ && stream_period_.count() > 0) {
      next_sample_ = next_sample;
      next = std::min(next, next_sample_);
    } else if (stream_period_.count() > 0) {
      next = now;  // the stream changed meanwhile: look again at once
    }
    for (auto& [id, session] : sessions_) {
      if (!session.commands.empty() && session.commands.Top().start < next)
        next = session.commands.Top().start;
    }
    if (!server_queue_.empty() || halt_requested_ || resume_requested_) next = now;
  }
  if ((!produced_.empty() || !sampled_.empty()) && replies_ready_) replies_ready_();
  return next;
}

void RobotService::Execute(const QueuedItem& item, TimePoint now) {
  Reply r;
  r.id = item.command.id;
  r.exec_time = now;
  if (item.has_start_time && now > item.start) r.lateness = now - item.start;
  if (item.is_query) {
    AnswerQuery(item, r);
    produced_.push_back({item.client_id, std::move(r)});
    return;
  }
  if (item.only_if_moving) {
    // The watchdog's STOP: a set-point that already arrived needs none.
    driver_->ReadState(state_);
    if (!state_.moving) return;
  }
  if (panic_ && item.command.type != CommandType::kStop) {
    r.signal = Signal::kInterrupted;
    r.message = "the robot entered panic before the command ran";
    produced_.push_back({item.client_id, std::move(r)});
    return;
  }
  DriverCommand command = item.command;
  command.id = next_driver_id_++;
  const DriverResult result = driver_->Execute(command, now, completions_);
  if (options_.log_executions) {
    std::fprintf(stderr, "robotalk-server: robot '%s': executed client %s command %" PRId64 " %s -> %s\n",
                 name_.c_str(), Hex64(static_cast<std::uint64_t>(item.client_id)).c_str(), item.command.id,
                 ToString(item.command.type),
                 result.in_progress ? "in progress" : std::string(ToString(result.signal)).c_str());
  }
  if (result.in_progress) {
    in_progress_[command.id] = Owner{item.client_id, item.command.id, now, r.lateness};
    return;
  }
  r.signal = result.signal;
  r.message = result.message;
  produced_.push_back({item.client_id, std::move(r)});
}

void RobotService::AnswerQuery(const QueuedItem& item, Reply& reply) {
  const RobotModel& m = model();
  try {
    driver_->ReadState(state_);
    auto& v = reply.values;
    switch (item.query) {
      case QueryType::kJointState: {
        int first = 0, count = m.num_dofs();
        if (item.query_target >= 0) {
          first = m.dof_offset(item.query_target);
          count = static_cast<int>(m.joint(item.query_target).dofs.size());
        }
        for (const Eigen::VectorXd* vec : {&state_.position, &state_.velocity, &state_.effort}) {
          v.insert(v.end(), vec->data() + first, vec->data() + first + count);
        }
        break;
      }
      case QueryType::kLinkPoses:
      case QueryType::kFramePoses: {
        std::vector<Eigen::Isometry3d> roots;
        roots.reserve(state_.root_poses.size());
        for (const Pose& p : state_.root_poses) roots.push_back(p.ToIsometry());
        kinematics_.Update(state_.position, roots);
        const bool links = item.query == QueryType::kLinkPoses;
        const int n = static_cast<int>(links ? m.links().size() : m.frames().size());
        for (int i = 0; i < n; ++i) {
          if (item.query_target >= 0 && i != item.query_target) continue;
          AppendPose(links ? kinematics_.link_pose(i) : kinematics_.frame_pose(i), v);
        }
        break;
      }
      case QueryType::kBasePose: {
        const Eigen::Isometry3d base = state_.root_poses.front().ToIsometry();
        const double yaw = std::atan2(base.linear()(1, 0), base.linear()(0, 0));
        v = {base.translation().x(), base.translation().y(), yaw, state_.base_v, state_.base_omega};
        break;
      }
      default:
        reply.signal = Signal::kError;
        reply.message = std::string(ToString(item.query)) + " is answered on receipt, not queued";
        return;
    }
    reply.signal = Signal::kSuccess;
  } catch (const std::exception& e) {
    reply.signal = Signal::kError;
    reply.message = std::string(ToString(item.query)) + ": " + e.what();
    reply.values.clear();
  }
}

}  // namespace robotalk
