// The RobotDaemon's trajectories and base speed ramp (issue 22;
// trajectory_tracker.h, speed_ramp.h): the waypoints and SETSPEED frames of
// interpolated packages join them when they arrive; every control period
// they are sampled and handed to the driver (Driver::Track, TrackBase); a
// command that moves the same joints (the base) ends them. The planners are
// guarded like the driver: a throw is a SERVER FAULT, never the thread's end.
#include "robot_daemon.h"

#include <algorithm>
#include <utility>

namespace robotalk {

void RobotDaemon::PlannerFault(const std::string& what, TimePoint now, std::span<const QueuedItem> arriving) {
  Fault(what, now, "SERVER FAULT");
  const std::string why = "ended by panic: " + what;
  // Without sampling or re-planning: the planner that threw is not trusted.
  tracker_.Abandon(now, why, tracked_);
  ramp_.End(now, why, ramped_);
  const auto answered = [&](const QueuedItem& item) {
    const auto is = [&](const auto& a) {
      return a.client_id == item.client_id && a.reply.id == item.command.id;
    };
    return std::any_of(tracked_.begin(), tracked_.end(), is) ||
           std::any_of(ramped_.begin(), ramped_.end(), is);
  };
  for (const QueuedItem& item : arriving) {
    if (answered(item)) continue;
    Reply r;
    r.id = item.command.id;
    r.signal = Signal::kInterrupted;
    r.message = "not executed: " + what + "; robot '" + robot_name_ + "' halted (panic) until PANIC_RESET";
    r.exec_time = now;
    Emit(item.client_id, std::move(r));
  }
  EmitTracked();
  for (SpeedRamp::Answer& a : ramped_) Emit(a.client_id, std::move(a.reply));
  ramped_.clear();
}

void RobotDaemon::EmitTracked() {
  for (TrajectoryTracker::Answer& a : tracked_) Emit(a.client_id, std::move(a.reply));
  tracked_.clear();
}

void RobotDaemon::InterruptInPanic(std::span<const QueuedItem> items, TimePoint now) {
  const std::string why = panic_.has_reason() ? ": " + panic_.reason() : std::string();
  for (const QueuedItem& item : items) {
    Reply r;
    r.id = item.command.id;
    r.signal = Signal::kInterrupted;
    r.message = "the robot entered panic before the command ran" + why;
    r.exec_time = now;
    Emit(item.client_id, std::move(r));
  }
}

void RobotDaemon::AddWaypoints(TimePoint now) {
  if (waypoints_.empty()) return;
  // An idle joint's trajectory starts where it is (the ramp: at the base's
  // twist), so the state is read first -- and a read that fails or finds a
  // non-finite value halts the robot: the waypoints then answer as in panic.
  const bool halted = panic_.in_panic() || panic_.driver_halted();
  if (halted || !ReadState(now) || panic_.in_panic()) {
    InterruptInPanic(waypoints_, now);
    waypoints_.clear();
    return;
  }
  // SETSPEED frames go to the base's ramp; the rest keep their order.
  speed_frames_.clear();
  for (QueuedItem& w : waypoints_) {
    if (w.is_speed_frame()) speed_frames_.push_back(std::move(w));
  }
  waypoints_.erase(std::remove_if(waypoints_.begin(), waypoints_.end(),
                                  [](const QueuedItem& w) { return w.is_speed_frame(); }),
                   waypoints_.end());
  if (!waypoints_.empty()) {
    trajectory_owners_.clear();
    if (GuardedPlanner("trajectory tracker", now, waypoints_,
                       [&] { tracker_.Add(waypoints_, now, state_, tracked_, trajectory_owners_); })) {
      for (const TrajectoryTracker::Started& o : trajectory_owners_) {
        produced_.executed.push_back({o.client_id, o.type, o.target});
      }
      EmitTracked();
    } else {  // the robot is halted: the speed frames too
      InterruptInPanic(speed_frames_, now);
      speed_frames_.clear();
    }
  }
  AddSpeedFrames(now);
  waypoints_.clear();
}

void RobotDaemon::TrackBaseRamp(TimePoint now) {
  if (!ramp_.active()) return;
  if (panic_.in_panic() || panic_.driver_halted()) {
    EndRamp(now, "ended by panic");
    return;
  }
  bool sampled = false;
  if (!GuardedPlanner("speed ramp", now, {}, [&] { sampled = ramp_.Sample(now, ramped_); })) return;
  for (SpeedRamp::Answer& a : ramped_) Emit(a.client_id, std::move(a.reply));
  ramped_.clear();
  if (!sampled) return;
  DriverResult result;
  if (Guarded("TrackBase", nullptr, now, [&] {
        result = driver_->TrackBase(ramp_.reference(), now, completions_);
      }) != CallOutcome::kOk) {
    return;  // a fault: the next iteration ends the ramp (panic)
  }
  if (result.signal == Signal::kModified) {
    ramp_.NoteDriver(result.message);
  } else if (result.signal != Signal::kSuccess) {
    EndRamp(now, "driver '" + driver_name_ +
                     "' refused to follow the base's speed ramp: " + std::string(ToString(result.signal)) +
                     (result.message.empty() ? "" : " " + result.message));
  }
}

void RobotDaemon::TrackTrajectories(TimePoint now) {
  if (!tracker_.active()) return;
  if (panic_.in_panic() || panic_.driver_halted()) {
    tracker_.EndAll(now, "ended by panic", tracked_);
    EmitTracked();
    return;
  }
  if (!GuardedPlanner("trajectory tracker", now, {}, [&] { tracker_.Sample(now, tracked_); })) return;
  max_reference_acceleration_.store(tracker_.max_reference_acceleration(), std::memory_order_relaxed);
  for (const JointReference& ref : tracker_.references()) {
    DriverResult result;
    if (Guarded("Track", nullptr, now, [&] { result = driver_->Track(ref, now, completions_); }) !=
        CallOutcome::kOk) {
      break;  // a fault: the next iteration ends every trajectory (panic)
    }
    if (result.signal != Signal::kSuccess && result.signal != Signal::kModified) {
      tracker_.End(ref.joint, now,
                   "driver '" + driver_name_ + "' refused to follow joint '" + model().joint(ref.joint).name +
                       "': " + std::string(ToString(result.signal)) +
                       (result.message.empty() ? "" : " " + result.message),
                   tracked_);
    }
  }
  EmitTracked();
}

void RobotDaemon::EndTrajectoriesFor(const QueuedItem& item, TimePoint now) {
  if (!tracker_.active() && !ramp_.active()) return;
  const RobotModel& m = model();
  const std::string why =
      std::string("superseded by ") + ToString(item.command.type) + " " + std::to_string(item.command.id);
  if (Traits(item.command.type).target == CommandTarget::kBase) EndRamp(now, why);  // a GOTO, a step SETSPEED
  if (!tracker_.active()) return;
  switch (Traits(item.command.type).target) {
    case CommandTarget::kJoint:
      tracker_.End(item.command.target, now, why, tracked_);
      break;
    case CommandTarget::kFrame:  // the joints on the frame's chain
      for (int j : m.frame_chain(item.command.target)) tracker_.End(j, now, why, tracked_);
      break;
    case CommandTarget::kBase:
    case CommandTarget::kRobot:
      break;
  }
  EmitTracked();
}

void RobotDaemon::AddSpeedFrames(TimePoint now) {
  if (speed_frames_.empty()) return;
  const BaseReference measured{.vx = state_.base_v, .vy = state_.base_vy, .omega = state_.base_omega};
  std::int64_t owner = 0;
  if (!GuardedPlanner("speed ramp", now, speed_frames_,
                      [&] { owner = ramp_.Add(speed_frames_, now, measured, ramped_); })) {
    speed_frames_.clear();
    return;
  }
  if (owner != 0) produced_.executed.push_back({owner, CommandType::kSetSpeed, -1});
  for (SpeedRamp::Answer& a : ramped_) Emit(a.client_id, std::move(a.reply));
  ramped_.clear();
  speed_frames_.clear();
}

void RobotDaemon::EndRamp(TimePoint now, const std::string& why) {
  if (!ramp_.active()) return;
  ramp_.End(now, why, ramped_);
  for (SpeedRamp::Answer& a : ramped_) Emit(a.client_id, std::move(a.reply));
  ramped_.clear();
}

}  // namespace robotalk
