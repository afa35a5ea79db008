#include "robot_daemon.h"

#include "expiry.h"
#include "planner_answers.h"

#include "robotalk/signal.h"

#include <algorithm>
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <utility>

namespace robotalk {
namespace {

// Zero joints, the roots where the model puts them: sized for the model, so
// later reads and copies do not allocate.
RobotState InitialState(const RobotModel& m) {
  RobotState s;
  for (Eigen::VectorXd* v : {&s.position, &s.velocity, &s.effort}) *v = Eigen::VectorXd::Zero(m.num_dofs());
  for (const RootLink& r : m.roots()) s.root_poses.push_back(r.pose_in_world);
  return s;
}

}  // namespace

RobotDaemon::RobotDaemon(std::string robot_name, std::string driver_name, std::unique_ptr<Driver> driver,
                         const Clock& clock, RobotDaemonOptions options)
    : robot_name_(std::move(robot_name)),
      driver_name_(std::move(driver_name)),
      driver_(std::move(driver)),
      clock_(clock),
      options_(options),
      waiter_(clock, DeadlineOptions{.precise = options.precise_timing,
                                     .final_spin = options.final_spin,
                                     .spin_share = options.spin_share,
                                     .fifo_priority = options.fifo_priority}),
      woken_([this] { return wake_flag_ || !running_ || flush_deferred_.load(); }),
      tracker_(driver_->model(),
               TrackerOptions{.acceleration_limit = options.max_acceleration, .period = driver_->period()}),
      ramp_(SpeedRampOptions{.linear_acceleration = options.base_linear_acceleration,
                             .angular_acceleration = options.base_angular_acceleration,
                             .period = driver_->period(),
                             .mobile = driver_->model().roots().front().base != BaseType::kFixed,
                             .robot = driver_->model().name()}),
      kinematics_(driver_->model()),
      snapshot_(driver_->model(), InitialState(driver_->model()), clock, panic_) {
  const RobotModel& m = model();
  state_ = InitialState(m);
  for (const RootLink& r : m.roots()) roots_.push_back(r.pose_in_world.ToIsometry());
  for (Eigen::VectorXd* v : {&sample_.position, &sample_.velocity, &sample_.effort})
    *v = Eigen::VectorXd::Zero(m.num_dofs());
  sample_.frame_poses.assign(7 * m.frames().size(), 0.0);
  due_.reserve(256);
  waypoints_.reserve(256);
  arrived_waypoints_.reserve(256);
  tracked_.reserve(256);
  speed_frames_.reserve(256);
  ramped_.reserve(256);
  held_.reserve(64);
  held_now_.reserve(64);
  completions_.reserve(64);
  produced_.replies.reserve(256);
  produced_.executed.reserve(256);
  Preallocate(outbox_);
  in_progress_.reserve(64);
}

RobotDaemon::~RobotDaemon() { Stop(); }

void RobotDaemon::Preallocate(DaemonOutput& out) const {
  out.replies.reserve(256);
  out.executed.reserve(256);
  out.samples.assign(options_.max_buffered_samples, sample_);
  out.num_samples = 0;
}

void RobotDaemon::Start() {
  std::lock_guard lock(mutex_);
  if (running_) return;
  running_ = true;
  thread_ = std::thread([this] { DaemonLoop(); });
}

void RobotDaemon::Stop() {
  {
    std::lock_guard lock(mutex_);
    running_ = false;
  }
  wake_.notify_all();
  if (!thread_.joinable()) return;
  thread_.join();
  // The thread is gone, so this one may act as it: run what the server queued
  // last (the shutdown STOP), so no robot is left moving.
  RunOnce(clock_.Now());
}

void RobotDaemon::EndSoon() {
  {
    std::lock_guard lock(mutex_);
    running_ = false;
    shutting_down_ = true;
  }
  wake_.notify_all();
}

bool RobotDaemon::WaitEnded(Duration timeout) {
  std::unique_lock lock(mutex_);
  if (!thread_.joinable()) return true;
  return ended_changed_.wait_for(lock, timeout, [this] { return ended_; });
}

void RobotDaemon::Shutdown() {
  EndSoon();
  if (thread_.joinable()) {
    thread_.join();  // it did the last STOP itself
  } else {
    LastStop();  // never started: this thread acts as it, once
  }
}

void RobotDaemon::LastStop() {
  // What waits never runs (issue 19: a command due during the shutdown ran
  // after its STOP); it is not answered either: to its client it is an
  // outcome the server took away, as after a crash (an UnknownOutcomeError
  // once it meets the next server instance).
  std::vector<QueuedItem> waiting;
  {
    std::lock_guard lock(mutex_);
    scheduler_.FlushAll(waiting);
    arrived_waypoints_.clear();
  }
  QueueStop(/*only_if_moving=*/false);
  last_iteration_ = true;
  RunOnce(clock_.Now());
}

Duration RobotDaemon::CallRunning(TimePoint now) const {
  std::lock_guard lock(call_mutex_);
  return call_.name ? now - call_.started : Duration(0);
}

bool RobotDaemon::Abandon(TimePoint now) {
  // Under call_mutex_ throughout: the call cannot end (and the shutdown STOP
  // begin) between the check and the detach.
  std::lock_guard call_lock(call_mutex_);
  // Only the call that has run twice the bound at `now` is given up on: one
  // that returned meanwhile (its thread in the shutdown STOP, or done) is not.
  if (!call_.name || options_.driver_call_bound.count() <= 0 ||
      now - call_.started <= 2 * options_.driver_call_bound)
    return false;
  const std::string why =
      "robot '" + robot_name_ + "': NOT STOPPED: driver '" + driver_name_ + "' " + call_.name +
      " has not returned after " + planner_answers::Seconds(now - call_.started) +
      " (twice --driver-call-bound); the server shuts down without this robot's STOP: the "
      "robot may still move (it is in panic)";
  {
    std::lock_guard lock(mutex_);
    if (ended_ || !thread_.joinable()) return false;
    output_ready_ = nullptr;  // the ServerDaemon it wakes is going away
    outbox_.log.push_back(why);
  }
  thread_.detach();
  return true;
}

namespace {
std::string LateMs(Duration d) {
  char b[32];
  std::snprintf(b, sizeof b, "%.3f", std::chrono::duration<double, std::milli>(d).count());
  return b;
}
}  // namespace

void RobotDaemon::DaemonLoop() {
  const std::string timing = waiter_.Apply();
  std::unique_lock lock(mutex_);
  timing_ = timing;
  outbox_.log.push_back("robot '" + robot_name_ + "': RobotDaemon timing: " + timing);
  while (running_) {
    sleeping_until_.reset();
    lock.unlock();
    const TimePoint next = RunOnce(clock_.Now());
    lock.lock();
    sleeping_until_ = next;
    diag_.waited_for = next;
    diag_.spin = spin_;
    waiter_.WaitUntil(lock, wake_, next, spin_, woken_);
    if (log_late_) {
      diag_.woke = clock_.Now();
      diag_.by_submit = wake_flag_;
    }
    wake_flag_ = false;
  }
  const bool last_stop = shutting_down_;
  lock.unlock();
  if (last_stop) LastStop();
  lock.lock();
  ended_ = true;
  ended_changed_.notify_all();
}

// --- ServerDaemon side -------------------------------------------------------

void RobotDaemon::Submit(QueuedItem item) {
  const TimePoint now = clock_.Now();
  const bool due = !item.has_start_time || item.start <= now;
  bool wake = true;
  {
    std::lock_guard lock(mutex_);
    // A start after the deadline the thread sleeps until is taken then: no
    // wake-up per delayed command (issue 11: 64 clients x 100 Hz are CPU-bound
    // on thread switches). While it runs (no deadline yet) it is always told.
    wake = due || !sleeping_until_ || item.start < *sleeping_until_;
    if (log_late_ && item.has_start_time && now - item.start > std::chrono::milliseconds(1)) {
      outbox_.log.push_back("robot '" + robot_name_ + "': late start: command " +
                            std::to_string(item.command.id) + " handed over " + LateMs(now - item.start) +
                            " ms after its start (handled " + LateMs(item.start - item.received) +
                            " ms before it)");
    }
    if (item.is_waypoint() || item.is_speed_frame()) {
      // Planned toward before its time: the thread takes it at its next iteration.
      wake = true;
      arrived_waypoints_.push_back(std::move(item));
    } else {
      scheduler_.Push(std::move(item));
    }
    ++pushes_;
    if (due) snapshot_.NoteDue(pushes_);  // a snapshot older than this item is no answer
    if (wake) wake_flag_ = true;
  }
  if (wake) wake_.notify_one();
}

// What waits: in the scheduler, arrived for the planners, and held by them
// (waypoints and SETSPEED frames not yet passed, once counted nowhere:
// streamed far ahead, they grew the server without bound).
std::size_t RobotDaemon::queued(std::int64_t client_id) const {
  std::lock_guard lock(mutex_);
  std::size_t n = scheduler_.queued(client_id);
  for (const auto& [id, held] : held_) n += id == client_id ? held : 0;
  for (const QueuedItem& i : arrived_waypoints_) n += i.client_id == client_id ? 1 : 0;
  return n;
}

std::size_t RobotDaemon::queued_total() const {
  std::lock_guard lock(mutex_);
  std::size_t n = scheduler_.size() + arrived_waypoints_.size();
  for (const auto& entry : held_) n += entry.second;
  return n;
}

void RobotDaemon::FlushClient(std::int64_t client_id, std::vector<QueuedItem>& out) {
  std::lock_guard lock(mutex_);
  scheduler_.FlushClient(client_id, out);
  const auto theirs = std::stable_partition(arrived_waypoints_.begin(), arrived_waypoints_.end(),
                                            [&](const QueuedItem& i) { return i.client_id != client_id; });
  for (auto it = theirs; it != arrived_waypoints_.end(); ++it) out.push_back(std::move(*it));
  arrived_waypoints_.erase(theirs, arrived_waypoints_.end());
}

Duration RobotDaemon::SetStream(std::int64_t client_id, Duration period) {
  Duration now_period;
  {
    std::lock_guard lock(mutex_);
    now_period = scheduler_.SetStream(client_id, period, clock_.Now());
    wake_flag_ = true;
  }
  wake_.notify_one();
  return now_period;
}

Duration RobotDaemon::stream_period() const {
  std::lock_guard lock(mutex_);
  return scheduler_.stream_period();
}

void RobotDaemon::QueueStop(bool only_if_moving) {
  QueuedItem stop;
  stop.client_id = 0;
  stop.command.type = CommandType::kStop;
  stop.only_if_moving = only_if_moving;
  Submit(std::move(stop));
}

void RobotDaemon::QueueStopOnly(std::vector<int> joints, bool base) {
  QueuedItem stop;
  stop.client_id = 0;
  stop.command.type = CommandType::kStop;
  stop.scoped_stop = true;
  stop.stop_joints = std::move(joints);
  stop.stop_base = base;
  Submit(std::move(stop));
}

bool RobotDaemon::TakeOutput(DaemonOutput& out, bool wait) {
  if (out.samples.size() != options_.max_buffered_samples) Preallocate(out);
  out.Clear();
  std::unique_lock lock(mutex_, std::defer_lock);
  if (!wait && !lock.try_lock()) return false;
  if (wait) lock.lock();
  std::swap(out, outbox_);
  return !out.replies.empty() || !out.executed.empty() || out.num_samples > 0 || !out.log.empty() ||
         !out.audit.empty() || out.dropped_samples > 0;
}

// --- RobotDaemon side --------------------------------------------------------

void RobotDaemon::Emit(std::int64_t client_id, Reply reply) {
  if (client_id == 0) return;  // the server's own STOP has nobody to answer
  produced_.replies.push_back({client_id, std::move(reply)});
}

TimePoint RobotDaemon::RunOnce(TimePoint now) {
  if (log_late_) {
    diag_.previous_began = diag_.began;
    diag_.began = now;
  }
  bool sample_due = false;
  bool took_waypoints = false;
  Duration period{0};
  due_.clear();
  {
    std::lock_guard lock(mutex_);
    if (flush_deferred_.load()) FlushForPanicLocked();
    scheduler_.TakeDue(now, due_);
    waypoints_.clear();
    std::swap(waypoints_, arrived_waypoints_);
    // Held from now on (the planners take them below); recounted at the end.
    for (const QueuedItem& w : waypoints_) planner_answers::CountHeld(held_, w.client_id);
    took_waypoints = !waypoints_.empty();
    pushes_taken_ = pushes_;
    period = scheduler_.stream_period();
    sample_due = scheduler_.TakeSampleDue(now) || (last_iteration_ && period.count() > 0);
  }
  completions_.clear();
  produced_.Clear();
  // A Halt that throws still counts as halted: no Execute until the reset.
  if (panic_.BeginHalt() &&
      Guarded("Halt", nullptr, now, [&] { driver_->Halt(completions_); }) == CallOutcome::kThrew) {
    StopInstead(now);
  }
  // Not halted from the call on: a Resume that throws or overruns part-way
  // (the robot may already be let go) is a fault that halts it again.
  if (panic_.BeginResume()) Guarded("Resume", nullptr, now, [&] { driver_->Resume(); });
  for (const QueuedItem& item : due_) Execute(item, now);
  AddWaypoints(now);
  bool state_fresh = false;  // state_ read after this iteration's Update
  if (now >= next_update_) {
    TrackTrajectories(now);
    TrackBaseRamp(now);
    Guarded("Update", nullptr, now, [&] { driver_->Update(now, completions_); });
    std::string_view condition;  // the driver's own text: nothing allocated unless it changed
    if (Guarded("Fault", nullptr, now, [&] { condition = driver_->Fault(); }) == CallOutcome::kOk &&
        condition != reported_condition_) {
      if (!condition.empty()) Fault("driver '" + driver_name_ + "' reports: " + std::string(condition), now);
      reported_condition_.assign(condition);
    }
    const Duration p = driver_->period();
    next_update_ = next_update_ == TimePoint::min() ? now + p : next_update_ + p;
    if (next_update_ <= now) next_update_ = now + p;  // overran: skip, don't burst
    // Every period, watched or not: a non-finite state is a fault at once.
    state_fresh = ReadState(now);
  }
  const bool sampled = sample_due && Sample(now, period, state_fresh);  // none from a state not read
  for (const Completion& c : completions_) {
    auto owner = in_progress_.find(c.id);
    if (owner == in_progress_.end()) continue;
    Reply r;
    r.id = owner->second.client_command_id;
    r.signal = c.signal;
    r.message = c.message;
    r.exec_time = owner->second.started;
    r.lateness = owner->second.lateness;
    Emit(owner->second.client_id, std::move(r));
    in_progress_.erase(owner);
  }

  const bool state_read =
      snapshot_.wanted(clock_.Now()) && (state_fresh || sampled || ReadState(now)) && state_problem_.empty();
  TimePoint next = next_update_;
  TimePoint next_due = TimePoint::max();
  bool ready = false;
  // The planners' counts change only when they take items (above) or pass,
  // end or replace some (their total falls): walk what they hold only then,
  // not every period (measured: 12 µs a period with 32,768 waypoints held).
  const std::size_t held_total = tracker_.pending() + ramp_.pending();
  const bool recount = took_waypoints || held_total != held_total_;
  if (recount) {
    held_now_.clear();
    tracker_.CountPending(held_now_);
    ramp_.CountPending(held_now_);
    held_total_ = held_total;
  }
  {
    std::lock_guard lock(mutex_);
    if (recount) held_.swap(held_now_);
    for (auto& a : produced_.replies) outbox_.replies.push_back(std::move(a));
    for (const auto& e : produced_.executed) outbox_.executed.push_back(e);
    for (auto& line : produced_.log) outbox_.log.push_back(std::move(line));
    for (auto& line : produced_.audit) outbox_.audit.push_back(std::move(line));
    if (sampled) {
      if (outbox_.num_samples < outbox_.samples.size()) {
        outbox_.samples[outbox_.num_samples++] = sample_;  // same sizes: no allocation
      } else {
        ++outbox_.dropped_samples;  // the ServerDaemon is behind: drop the newest
      }
    }
    next_due = scheduler_.NextDeadline();
    spin_ = next_due < next;  // a start time or sample, not a driver period
    next = std::min(next, next_due);
    if (panic_.requests_pending()) next = now;
    ready = !produced_.replies.empty() || !produced_.executed.empty() || !produced_.log.empty() ||
            !produced_.audit.empty() || sampled;
  }
  snapshot_.Publish(state_read ? &state_ : nullptr, now, driver_->period(), pushes_taken_, next_due,
                    panic_.driver_halted());
  if (ready) {
    // Under the lock: Abandon() clears it when the ServerDaemon goes away.
    std::lock_guard lock(mutex_);
    if (output_ready_) output_ready_();
  }
  if (log_late_) diag_.previous_ended = clock_.Now();
  return next;
}

void RobotDaemon::Execute(const QueuedItem& item, TimePoint now) {
  Reply r;
  r.id = item.command.id;
  r.exec_time = now;
  if (item.has_start_time && now > item.start) r.lateness = now - item.start;
  if (log_late_ && item.has_start_time && now - item.start > std::chrono::milliseconds(1)) {
    // Times in ms after the command's start: what the thread did before it ran it.
    const auto at = [&](TimePoint t) { return LateMs(t - item.start); };
    produced_.log.push_back(
        "robot '" + robot_name_ + "': late start: command " + std::to_string(item.command.id) + " ran " +
        at(now) + " ms after its start; handled at " + at(item.received) + "; the thread waited for " +
        at(diag_.waited_for) + (diag_.spin ? " (spin)" : "") + ", woke at " + at(diag_.woke) +
        (diag_.by_submit ? " (a submit)" : "") + "; the iteration before ran " + at(diag_.previous_began) +
        " to " + at(diag_.previous_ended) + "; this one began at " + at(diag_.began) + "; now " +
        at(clock_.Now()));
  }
  if (item.is_query) {
    AnswerQuery(item, r);
    Emit(item.client_id, std::move(r));
    return;
  }
  const auto driver_call = [&](const char* name, auto&& call) {
    const CallOutcome outcome = Guarded(name, &item, now, call);
    if (outcome == CallOutcome::kThrew) {
      r.signal = Signal::kError;
      r.message = panic_.last_fault() + "; robot '" + robot_name_ + "' halted (panic) until PANIC_RESET";
      Emit(item.client_id, std::move(r));
    }
    return outcome == CallOutcome::kOk;
  };
  if (item.command.type == CommandType::kStop) {
    if (item.only_if_moving) {
      // The server's STOP when it gives a robot up: a robot at rest needs none.
      if (!ReadState(now) || !state_.moving) return;
    }
    // A client's STOP stops everything; the watchdog's stops what the
    // vanished client owned (its GOTO included). Neither can be refused:
    // Stop() and StopOnly() answer nothing.
    const StopScope scope{.joints = item.stop_joints, .base = item.stop_base};
    if (item.scoped_stop) {
      for (int j : item.stop_joints) tracker_.End(j, now, "stopped: its client vanished", tracked_);
      if (item.stop_base) EndRamp(now, "stopped: its client vanished");
    } else {
      tracker_.EndAll(now, "stopped by STOP", tracked_);
      EndRamp(now, "stopped by STOP");
    }
    EmitTracked();
    if (!driver_call(item.scoped_stop ? "StopOnly" : "Stop", [&] {
          if (item.scoped_stop) {
            driver_->StopOnly(scope, now, completions_);
          } else {
            driver_->Stop(now, completions_);
          }
        }))
      return;
    // A STOP of everything ends every ownership; a scoped one ends only the
    // vanished client's, which RobotSessions::Expire already cleared.
    if (!item.scoped_stop) produced_.executed.push_back({item.client_id, CommandType::kStop, -1});
    if (last_iteration_ && item.client_id == 0) {
      produced_.log.push_back("robot '" + robot_name_ +
                              "': stopped (STOP executed; the server is shutting down)");
    }
    r.signal = Signal::kSuccess;
    Emit(item.client_id, std::move(r));
    return;
  }
  if (panic_.in_panic() || panic_.driver_halted()) {
    r.signal = Signal::kInterrupted;
    r.message = "the robot entered panic before the command ran";
    Emit(item.client_id, std::move(r));
    return;
  }
  if (item.has_start_time && r.lateness > item.max_late) {  // issue 23: past its deadline
    const ExpiryHold hold = HoldAfterExpiry(item.command.type, item.command.target);
    const int joint = hold.joint;
    const StopScope scope{.joints = std::span<const int>(&joint, hold.joint >= 0 ? 1 : 0), .base = hold.base};
    if (hold.base) EndRamp(now, "stopped: SETSPEED " + std::to_string(item.command.id) + " expired");
    if (hold.joint >= 0) {  // the joint's trajectory ends too, or its next reference would move it on
      tracker_.End(hold.joint, now,
                   std::string("stopped: ") + ToString(item.command.type) + " " +
                       std::to_string(item.command.id) + " expired",
                   tracked_);
      EmitTracked();
    }
    if (hold.any() && !driver_call("StopOnly", [&] { driver_->StopOnly(scope, now, completions_); })) return;
    r.signal = Signal::kInterrupted;
    r.message = *ExpiryRefusal(r.lateness, item.max_late, item.received - item.start);
    Emit(item.client_id, std::move(r));
    return;
  }
  EndTrajectoriesFor(item, now);
  DriverCommand command = item.command;
  command.id = next_driver_id_++;
  DriverResult result;
  if (!driver_call("Execute", [&] { result = driver_->Execute(command, now, completions_); })) return;
  // Only what the driver accepted is ownership and ran; a refusal (BUSY, NA,
  // INTERRUPTED, ERROR) moved nothing (issue 19: a refused SETSPEED named the
  // wrong client to the watchdog, and the soak counted it as run).
  const bool accepted =
      result.in_progress || result.signal == Signal::kSuccess || result.signal == Signal::kModified;
  if (accepted) produced_.executed.push_back({item.client_id, item.command.type, item.command.target});
  if (options_.log_executions) Audit(item, result, accepted);
  if (result.in_progress) {
    in_progress_[command.id] = Owner{item.client_id, item.command.id, now, r.lateness};
    return;
  }
  r.signal = result.signal;
  r.message = std::move(result.message);
  Emit(item.client_id, std::move(r));
}

void RobotDaemon::Audit(const QueuedItem& item, const DriverResult& result, bool accepted) {
  char line[256];
  std::snprintf(line, sizeof line, "robot '%s': %s client %016" PRIx64 " command %" PRId64 " %s -> %s",
                robot_name_.c_str(), accepted ? "executed" : "refused",
                static_cast<std::uint64_t>(item.client_id), item.command.id, ToString(item.command.type),
                result.in_progress ? "in progress" : std::string(ToString(result.signal)).c_str());
  produced_.audit.emplace_back(line);
  if (!accepted && !result.message.empty()) produced_.audit.back() += " (" + result.message + ")";
}

void RobotDaemon::AnswerQuery(const QueuedItem& item, Reply& reply) {
  if (!ReadState(reply.exec_time)) {
    reply.signal = Signal::kError;
    reply.message = std::string(ToString(item.query)) + ": " + panic_.last_fault();
    return;
  }
  if (!state_problem_.empty()) {  // a broken sensor: no value is trusted
    reply.signal = Signal::kError;
    reply.message = std::string(ToString(item.query)) + ": driver '" + driver_name_ + "' reports " +
                    state_problem_ + "; robot '" + robot_name_ + "' halted (panic) until PANIC_RESET";
    return;
  }
  AnswerQueryFrom(model(), state_, kinematics_, roots_, item, reply);
  if (panic_.in_panic()) {  // a fault names itself: "... the robot has fallen (...)"
    const std::string why = panic_.reason();
    if (!why.empty()) reply.message = "robot '" + robot_name_ + "' is in panic: " + why;
  }
}

bool RobotDaemon::ReadState(TimePoint now) {
  if (Guarded("ReadState", nullptr, now, [&] { driver_->ReadState(state_); }) != CallOutcome::kOk)
    return false;
  std::optional<std::string> problem = MisfitState(model(), state_);
  const bool misfit = problem.has_value();
  if (misfit) {
    *problem = "a state that does not fit the model: " + *problem;
  } else if ((problem = NonFiniteState(model(), state_))) {
    *problem = "a non-finite state: " + *problem;
  }
  if (!problem) {
    if (!state_problem_.empty()) state_problem_.clear();
    return true;
  }
  state_problem_ = std::move(*problem);
  // A broken sensor: the robot cannot be driven safely on it. The fault's
  // text is the same while the value stays bad (the log prints it once).
  Fault("driver '" + driver_name_ + "' reports " + state_problem_, now);
  return !misfit;  // non-finite values are still sent, in panic; a misfit cannot be read
}

bool RobotDaemon::Sample(TimePoint now, Duration period, bool state_fresh) {
  if (!state_fresh && !ReadState(now)) return false;
  FillSample(now, period);  // in panic; non-finite values are sent as they are (docs/protocol.md)
  return true;
}

}  // namespace robotalk
