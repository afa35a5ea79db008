// The RobotDaemon's panics and faults (robot_daemon.h, panic_state.h): the
// ServerDaemon's Panic() / FinishPanic() / ResetPanic() and the flush a
// panic implies (every waiting item answered INTERRUPTED), the driver-call
// watchdog (CheckOverrun) that raises one when a driver call outlives its
// bound, and, on the RobotDaemon's side, Fault(): the robot halted and
// latched in panic when its driver or a planner fails.
#include "planner_answers.h"
#include "robot_daemon.h"

#include "robotalk/signal.h"

#include <cstdio>
#include <string>
#include <utility>

namespace robotalk {
using planner_answers::Seconds;

void RobotDaemon::Panic(std::vector<QueuedItem>& flushed, const std::string& reason) {
  panic_.Raise(reason);  // from here on only a STOP runs (Execute checks it)
  std::unique_lock lock(mutex_, std::try_to_lock);
  if (!lock.owns_lock()) {
    if (reason.empty()) {
      // The RobotDaemon holds the lock: do not wait for it before the
      // acknowledgement; FinishPanic() or its next iteration flushes.
      flush_deferred_ = true;
      return;
    }
    lock.lock();
  }
  scheduler_.FlushAll(flushed);
  for (QueuedItem& w : arrived_waypoints_) flushed.push_back(std::move(w));
  arrived_waypoints_.clear();
  wake_flag_ = true;
  lock.unlock();
  wake_.notify_one();
}

bool RobotDaemon::FinishPanic() {
  if (!flush_deferred_.load()) return false;
  {
    std::lock_guard lock(mutex_);
    if (flush_deferred_.load()) FlushForPanicLocked();
  }
  wake_.notify_one();
  return true;
}

void RobotDaemon::FlushForPanicLocked() {
  flush_deferred_ = false;
  std::vector<QueuedItem> flushed;
  scheduler_.FlushAll(flushed);
  for (QueuedItem& w : arrived_waypoints_) flushed.push_back(std::move(w));
  arrived_waypoints_.clear();
  wake_flag_ = true;
  const TimePoint now = clock_.Now();
  for (const QueuedItem& item : flushed) {
    if (item.client_id == 0) continue;
    Reply r;
    r.id = item.command.id;
    r.signal = Signal::kInterrupted;
    r.message = "flushed by panic";
    r.exec_time = now;
    outbox_.replies.push_back({item.client_id, std::move(r)});
  }
}

bool RobotDaemon::ResetPanic() {
  FinishPanic();  // a deferred flush never outlives its panic
  if (!panic_.Reset()) return false;
  {
    std::lock_guard lock(mutex_);
    wake_flag_ = true;
  }
  wake_.notify_one();
  return true;
}

bool RobotDaemon::CheckOverrun(TimePoint now) {
  std::lock_guard call_lock(call_mutex_);
  if (!call_.name || call_.overran || options_.driver_call_bound.count() <= 0 ||
      now - call_.started <= options_.driver_call_bound) {
    return false;
  }
  call_.overran = true;
  const std::string what = "driver '" + driver_name_ + "' " + call_.name + " has run for " +
                           Seconds(now - call_.started) + " (the bound is " +
                           Seconds(options_.driver_call_bound) + ")";
  panic_.Raise(what);
  {
    std::lock_guard lock(mutex_);
    wake_flag_ = true;
    outbox_.log.push_back("robot '" + robot_name_ + "': DRIVER FAULT: " + what +
                          "; robot held in panic until PANIC_RESET");
    if (call_.has_command) {
      Reply r;
      r.id = call_.command_id;
      r.signal = Signal::kError;
      r.message = what + "; robot '" + robot_name_ + "' halted (panic) until PANIC_RESET";
      r.exec_time = call_.started;
      outbox_.replies.push_back({call_.client_id, std::move(r)});
    }
  }
  wake_.notify_one();
  return true;
}

// --- RobotDaemon side --------------------------------------------------------

void RobotDaemon::Fault(const std::string& what, TimePoint now, std::string_view kind) {
  const bool halt = panic_.Fault(what);
  produced_.log.push_back("robot '" + robot_name_ + "': " + std::string(kind) + ": " + what +
                          "; robot halted, in panic until PANIC_RESET");
  if (!halt) return;
  try {
    driver_->Halt(completions_);
  } catch (const std::exception& e) {
    produced_.log.push_back("robot '" + robot_name_ + "': driver '" + driver_name_ +
                            "' threw in Halt too: " + e.what());
    StopInstead(now);
  } catch (...) {
    produced_.log.push_back("robot '" + robot_name_ + "': driver '" + driver_name_ + "' threw in Halt too");
    StopInstead(now);
  }
}

void RobotDaemon::StopInstead(TimePoint now) {
  try {
    driver_->Stop(now, completions_);
  } catch (...) {
    produced_.log.push_back("robot '" + robot_name_ + "': driver '" + driver_name_ +
                            "' threw in Stop too, after Halt: the robot may still move");
  }
}

}  // namespace robotalk
