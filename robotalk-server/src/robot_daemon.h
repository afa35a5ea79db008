// The paper's RobotDaemon for one robot: runs the driver on time, and nothing
// else. It owns the driver and its thread, takes the due items of every
// client from the Scheduler at their start times, executes them on the driver
// with a fault guard, and hands replies and state samples to the ServerDaemon
// through an outbox (PumpOutput, daemon_pump.h). Three parts live beside it,
// each a type of its own (issue 20): how it waits for a deadline
// (DeadlineWaiter), the panic/halt/fault state (PanicState) and the state
// snapshot queries are answered from on receipt (QuerySnapshot, read by
// RobotSessions directly).
//
// Threads:
// - the ServerDaemon calls Submit(), Panic(), ResetPanic(), SetStream(),
//   QueueStop(), TakeOutput() and the accessors; each takes the short
//   inbox/outbox lock (mutex_) or the PanicState's and never waits on the
//   driver;
// - the RobotDaemon thread (Start()) runs RunOnce() at each deadline (a start
//   time, a driver period, a state sample), with absolute deadlines. It holds
//   mutex_ only to take due items and to append to the outbox, never while
//   calling the driver. It does not log (log lines travel in the outbox) and,
//   once warmed up, does not allocate except for replies that carry text or
//   query values (tests/server/robot_daemon_test.cpp counts).
// Tests leave the thread unstarted and call RunOnce() with a ManualClock.
//
// Fewer hops (issue 11, 20): after every iteration it publishes the state it
// read to its QuerySnapshot, which RobotSessions answers a state query from
// on receipt when that is still what the driver would report (query_snapshot.h);
// such a query never reaches this class. Panic() does not wait for mutex_: it
// latches panic at once in the PanicState (nothing runs after it) and, if
// the RobotDaemon holds the lock, leaves the flush to FinishPanic() (called
// after the acknowledgement is sent) or to the RobotDaemon's next
// iteration, whichever comes first.
//
// Driver faults (driver.h): an exception from any driver call, or a call
// still running past `driver_call_bound` (seen by CheckOverrun(), which the
// ServerDaemon calls), halts the robot and latches panic with the reason;
// the command answers ERROR naming the driver, the call and the message.
#pragma once

#include "deadline_waiter.h"
#include "panic_state.h"
#include "query_snapshot.h"
#include "robotalk/clock.h"
#include "robotalk/driver.h"
#include "robotalk/kinematics.h"
#include "scheduler.h"
#include "speed_ramp.h"
#include "trajectory_tracker.h"

#include <Eigen/Core>
#include <array>
#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <span>
#include <string>
#include <thread>
#include <unordered_map>
#include <vector>

namespace robotalk {

struct RobotDaemonOptions {
  /// Add one log line per executed command to the outbox (diagnostics).
  bool log_executions = false;
  /// A driver call running longer than this is a driver fault (0 = no bound).
  Duration driver_call_bound = std::chrono::seconds(2);
  /// State samples the outbox holds before the oldest are dropped (counted).
  std::size_t max_buffered_samples = 64;
  /// Tighter deadlines for the RobotDaemon thread: 1 ns timer slack
  /// (prctl PR_SET_TIMERSLACK), a busy wait of `final_spin` before a start
  /// time or state sample, and SCHED_FIFO at `fifo_priority` when the process
  /// may (else it stays SCHED_OTHER, silently; the outbox log says once which
  /// was applied). robotalk::Server turns it off for --no-precise-timing or
  /// ROBOTALK_PRECISE_TIMING=0 (the benchmark compares both). Cost: up to `final_spin` of CPU
  /// per start time or sample, at most `spin_share` of a core over time
  /// (past that budget, deadlines are dense and waited for without a spin).
  bool precise_timing = true;
  Duration final_spin = std::chrono::microseconds(50);
  double spin_share = 0.05;
  int fifo_priority = 10;
  /// Trajectories' acceleration limit per dof (rad/s² | m/s², > 0): the
  /// server's --max-acceleration (trajectory_tracker.h).
  double max_acceleration = kDefaultTrajectoryAcceleration;
  /// The base's acceleration limit for SETSPEED ramps (m/s² of the planar
  /// speed, rad/s² of the yaw rate; > 0): the server's --max-base-acceleration
  /// (speed_ramp.h).
  double base_linear_acceleration = kDefaultBaseLinearAcceleration;
  double base_angular_acceleration = kDefaultBaseAngularAcceleration;
};

/// One broadcast state sample, preallocated for the model.
struct RobotSample {
  TimePoint time{};
  Duration period{0};
  std::int64_t sample = 0;
  bool panic = false;
  bool moving = false;
  Eigen::VectorXd position, velocity, effort;
  std::array<double, 5> base{};     ///< x y θ v ω of the first root
  std::vector<double> frame_poses;  ///< x y z qw qx qy qz per control frame
  bool frames_valid = true;         ///< false when the state was not finite
};

/// What the RobotDaemon hands the ServerDaemon. Swapped whole, so buffers
/// keep their capacity on both sides.
struct DaemonOutput {
  struct Answer {
    std::int64_t client_id = 0;
    Reply reply;
  };
  struct Executed {  ///< a command the driver accepted (SUCCESS, MODIFIED, in progress): ownership
    std::int64_t client_id = 0;
    CommandType type = CommandType::kStop;
    int target = -1;  ///< joint (JOINT_*) or frame (FRAME_SETPOINT) index
  };
  std::vector<Answer> replies;
  std::vector<Executed> executed;
  std::vector<RobotSample> samples;  ///< the first `num_samples` are filled
  std::size_t num_samples = 0;
  std::uint64_t dropped_samples = 0;
  std::vector<std::string> log;    ///< lines for the ServerDaemon to print (rate-limited)
  std::vector<std::string> audit;  ///< --log-executions lines, printed in full (asked for)

  void Clear() {
    replies.clear();
    executed.clear();
    num_samples = 0;
    dropped_samples = 0;
    log.clear();
    audit.clear();
  }
};

/// What in `state` is not finite, naming the joint and dof or the base
/// field ("joint 'pan' dof 0 position is NaN", "root 'base' x is +inf",
/// "base v is NaN"); nullopt when every value is finite. Allocates only then.
std::optional<std::string> NonFiniteState(const RobotModel& model, const RobotState& state);
/// What in `state` does not fit `model` (a driver's bug: every later read of
/// it would run past the end): "position has 0 values, the model has 1 dofs",
/// "root_poses has 0 poses, the model has 1 roots"; nullopt when it fits.
std::optional<std::string> MisfitState(const RobotModel& model, const RobotState& state);

class RobotDaemon {
 public:
  RobotDaemon(std::string robot_name, std::string driver_name, std::unique_ptr<Driver> driver,
              const Clock& clock, RobotDaemonOptions options = {});
  ~RobotDaemon();
  RobotDaemon(const RobotDaemon&) = delete;
  RobotDaemon& operator=(const RobotDaemon&) = delete;

  const std::string& robot_name() const { return robot_name_; }
  const std::string& driver_name() const { return driver_name_; }
  const RobotModel& model() const { return driver_->model(); }
  /// Sizes a DaemonOutput's sample buffers for this robot (call once).
  void Preallocate(DaemonOutput& out) const;

  /// Starts / stops the thread. Stop() runs one last iteration after joining,
  /// so a STOP queued just before (QueueStop) still executes.
  void Start();
  void Stop();
  /// The server's shutdown. EndSoon() (returns at once) asks the thread to
  /// end after its current iteration, dropping every waiting item without
  /// running it (unanswered, as after a crash), and to STOP the robot as its
  /// last act: that STOP is the last command the driver gets, and the
  /// broadcast stream gets a last sample after it. The thread does this
  /// itself, so a robot whose driver call hangs keeps no other robot from
  /// its STOP (the Server calls EndSoon() on every robot first).
  /// WaitEnded() waits at most `timeout` for that to be done (true when it
  /// is, or when the thread was never started). Shutdown() is EndSoon() and
  /// an unbounded wait (joined); without a thread it does the STOP itself.
  void EndSoon();
  bool WaitEnded(Duration timeout);
  void Shutdown();
  /// How long the driver call now running has run at `now` (0 when none).
  Duration CallRunning(TimePoint now) const;
  /// The server gives up waiting for a thread whose driver call hangs
  /// during the shutdown (robotalk::Server, after twice the call bound):
  /// says so in the outbox (naming the call and how long it has run at
  /// `now`), detaches the thread and stops waking the ServerDaemon. Should
  /// the call ever return, the thread still drops what waits and STOPs the
  /// robot. REQUIRES: EndSoon(); the daemon is never destroyed afterwards
  /// (its thread may still use it). Returns false (nothing done) when the
  /// call running has not run twice the call bound at `now` (the one
  /// measured returned meanwhile, its thread perhaps in the shutdown STOP)
  /// or the thread ended.
  bool Abandon(TimePoint now);

  // --- ServerDaemon side (thread-safe) ------------------------------------
  /// Queues a checked item. REQUIRES: admission checks passed. A state query
  /// due now is answered from snapshot() first when it can be (RobotSessions).
  void Submit(QueuedItem item);
  /// Diagnostics (issue 23, eleventh session; the server's --log-playback):
  /// a log line for each command that begins more than 1 ms after its start
  /// time (what the thread waited for, when it woke, the iteration before)
  /// and for each timed item handed over after its start. Set before Start().
  void LogLateStarts(bool on) { log_late_ = on; }
  /// The state queries are answered from on receipt (the session side's).
  QuerySnapshot& snapshot() { return snapshot_; }
  /// The robot's panic, halt and driver-fault state.
  const PanicState& panic_state() const { return panic_; }
  std::size_t queued(std::int64_t client_id) const;
  /// Items of every client (and the server's) waiting.
  std::size_t queued_total() const;
  /// TrajectoryTracker::max_reference_acceleration(), as of the last period
  /// (any thread).
  double max_reference_acceleration() const {
    return max_reference_acceleration_.load(std::memory_order_relaxed);
  }
  /// Panic: removes every waiting item (appended to `flushed`), latches
  /// panic and asks the thread to halt the driver.
  void Panic(std::vector<QueuedItem>& flushed, const std::string& reason = {});
  /// Completes a panic whose flush Panic() left to later (the lock was held):
  /// flushes every waiting item (answered INTERRUPTED through the outbox) and
  /// wakes the thread to halt. Returns false (a no-op) when there was none.
  /// May wait for mutex_.
  bool FinishPanic();
  /// Panic reset: returns false if the robot was not in panic.
  bool ResetPanic();
  bool in_panic() const { return panic_.in_panic(); }
  /// Why the robot is in panic: "" for a client's panic, else the driver fault.
  std::string fault() const { return panic_.reason(); }
  /// Removes one client's waiting items (appended to `out`).
  void FlushClient(std::int64_t client_id, std::vector<QueuedItem>& out);
  /// Broadcast request of a client (0 cancels); returns the stream period now.
  Duration SetStream(std::int64_t client_id, Duration period);
  Duration stream_period() const;
  /// A STOP from the server itself (watchdog, shutdown); with
  /// `only_if_moving` it is skipped when the robot is at rest.
  void QueueStop(bool only_if_moving);
  /// The watchdog's STOP for a vanished client: the same path as a STOP,
  /// restricted to what it owned (Driver::StopOnly): the given joints stop
  /// and hold and, with `base`, the base stops and a task on it (a GOTO)
  /// completes INTERRUPTED. A driver cannot refuse it. Another client's
  /// motion runs on.
  void QueueStopOnly(std::vector<int> joints, bool base);
  /// Swaps the outbox with `out` (cleared first). Returns false when empty.
  /// With `wait` false it does not wait for mutex_: when the RobotDaemon
  /// holds it, `out` is left cleared and false returned (take it later).
  bool TakeOutput(DaemonOutput& out, bool wait = true);
  /// Which timing the thread runs with (precise_timing), once started; "" before.
  std::string timing() const;
  /// Called from the RobotDaemon thread whenever the outbox has something.
  void set_output_ready_callback(std::function<void()> callback) { output_ready_ = std::move(callback); }
  /// Driver-call watchdog: if a call has run past the bound at `now`, latch
  /// a driver fault and answer its command ERROR. Returns true when it did.
  bool CheckOverrun(TimePoint now);

  // --- RobotDaemon side ----------------------------------------------------
  /// One iteration at `now`: halt/resume, every due item in run order, the
  /// driver's Update when its period is due, a state sample when due, the
  /// query snapshot. Returns when it next has work.
  TimePoint RunOnce(TimePoint now);

 private:
  struct Owner {  // whose command a driver command is
    std::int64_t client_id;
    CommandId client_command_id;
    TimePoint started;
    Duration lateness;
  };
  struct CurrentCall {  // GUARDED_BY(call_mutex_): what the driver is doing now
    const char* name = nullptr;
    TimePoint started{};
    std::int64_t client_id = 0;
    CommandId command_id = 0;
    bool has_command = false;
    bool overran = false;
  };

  void DaemonLoop();
  // The shutdown's last iteration (EndSoon): drops what waits, STOPs the robot.
  void LastStop();
  void FlushForPanicLocked();  // REQUIRES: mutex_ held
  void Execute(const QueuedItem& item, TimePoint now);
  void AnswerQuery(const QueuedItem& item, Reply& reply);
  // The --log-executions line of a motion command: "executed" (the driver
  // accepted it) or "refused" (with the driver's reason).
  void Audit(const QueuedItem& item, const DriverResult& result, bool accepted);
  // Reads the driver's state into state_ with the fault guard; a non-finite
  // value is a driver fault (halt, panic; issue 19) and state_problem_ names
  // it; a state that does not fit the model (sizes) too. False when the call
  // threw or the state does not fit (nothing in state_ may be read then).
  bool ReadState(TimePoint now);
  // False when the state could not be read: no sample (an old one is never sent again).
  bool Sample(TimePoint now, Duration period, bool state_fresh);
  void FillSample(TimePoint now, Duration period);  // from state_, just read
  enum class CallOutcome { kOk, kThrew, kOverran };
  // Runs one driver call with the fault guard (a throw latches a fault;
  // an overrun was latched by CheckOverrun and its command answered there).
  template <typename F>
  CallOutcome Guarded(const char* name, const QueuedItem* item, TimePoint now, F&& call);
  // Latches a fault and halts the driver. `kind` opens the log line: a
  // driver's ("DRIVER FAULT") or the server's own ("SERVER FAULT").
  void Fault(const std::string& what, TimePoint now, std::string_view kind = "DRIVER FAULT");
  // Runs one call of the server's own planners (the TrajectoryTracker, the
  // SpeedRamp). They are pure code, but a throw out of one would end this
  // thread with the robot following its last reference: it is a fault like
  // a driver's (PlannerFault). False when the call threw.
  template <typename F>
  bool GuardedPlanner(const char* name, TimePoint now, std::span<const QueuedItem> arriving, F&& call);
  // Halts the robot (panic, "SERVER FAULT"); every waypoint and frame the
  // planners hold, and every one of `arriving` not yet answered, answers
  // INTERRUPTED once: nothing is left unanswered, nothing runs on.
  void PlannerFault(const std::string& what, TimePoint now, std::span<const QueuedItem> arriving);
  // Answers each of `items` INTERRUPTED: the robot entered panic (naming why) before it ran.
  void InterruptInPanic(std::span<const QueuedItem> items, TimePoint now);
  // After a Halt that threw: a STOP, so the robot does not move on (a throw is logged).
  void StopInstead(TimePoint now);
  void Emit(std::int64_t client_id, Reply reply);
  // Trajectories: the waypoints that arrived join their joints' trajectories
  // (after this iteration's due items ran); every control period each active
  // one is sampled and handed to the driver (Driver::Track).
  void AddWaypoints(TimePoint now);
  void TrackTrajectories(TimePoint now);
  // A command that moves joints ends their trajectories first (the base's
  // ramp, for a base command).
  void EndTrajectoriesFor(const QueuedItem& item, TimePoint now);
  void EmitTracked();
  // The base's SETSPEED ramp: frames that arrived join it; every control
  // period it is sampled and handed to the driver (Driver::TrackBase).
  void AddSpeedFrames(TimePoint now);
  void TrackBaseRamp(TimePoint now);
  void EndRamp(TimePoint now, const std::string& why);

  const std::string robot_name_;
  const std::string driver_name_;
  std::unique_ptr<Driver> driver_;
  const Clock& clock_;
  const RobotDaemonOptions options_;
  std::function<void()> output_ready_;
  PanicState panic_;

  // The inbox and outbox, shared with the ServerDaemon.
  mutable std::mutex mutex_;
  std::condition_variable wake_;
  Scheduler scheduler_;                        // GUARDED_BY(mutex_)
  std::vector<QueuedItem> arrived_waypoints_;  // GUARDED_BY(mutex_): QueuedItem::is_waypoint(), not yet taken
  DaemonOutput outbox_;                        // GUARDED_BY(mutex_)
  /// Waypoints and SETSPEED frames the planners hold, per client: what a
  /// client has waiting beside the scheduler's queue (queued()).
  planner_answers::HeldCounts held_;  // GUARDED_BY(mutex_)
  bool wake_flag_ = false;            // GUARDED_BY(mutex_)
  /// The deadline the thread waits for; nullopt while it runs (Submit wakes it
  /// only for an item due before this).
  std::optional<TimePoint> sleeping_until_;  // GUARDED_BY(mutex_)
  bool running_ = false;                     // GUARDED_BY(mutex_)
  bool shutting_down_ = false;               // GUARDED_BY(mutex_): EndSoon() was called
  bool ended_ = false;                       // GUARDED_BY(mutex_): the thread has done its last STOP
  std::condition_variable ended_changed_;
  std::uint64_t pushes_ = 0;                 // GUARDED_BY(mutex_): items submitted so far
  std::string timing_;                       // GUARDED_BY(mutex_)
  std::atomic<bool> flush_deferred_{false};  // Panic() could not take mutex_ to flush
  std::atomic<double> max_reference_acceleration_{0};

  mutable std::mutex call_mutex_;
  CurrentCall call_;  // GUARDED_BY(call_mutex_)

  // RobotDaemon thread only (preallocated).
  std::thread thread_;
  DeadlineWaiter waiter_;
  std::function<bool()> woken_;  // the waiter's wake-up condition (under mutex_)
  bool spin_ = false;            // the next deadline is a start time or sample
  bool log_late_ = false;        // LogLateStarts
  // LogLateStarts' record of the thread's last wait and iterations (its thread only).
  struct LateDiag {
    TimePoint waited_for{}, woke{}, began{}, previous_began{}, previous_ended{};
    bool spin = false, by_submit = false;
  } diag_;
  std::vector<QueuedItem> due_;
  std::vector<QueuedItem> waypoints_;  // taken from arrived_waypoints_ this iteration
  TrajectoryTracker tracker_;
  std::vector<TrajectoryTracker::Answer> tracked_;  // the tracker's answers of this iteration
  std::vector<TrajectoryTracker::Started> trajectory_owners_;
  std::vector<QueuedItem> speed_frames_;  // this iteration's SETSPEED frames (QueuedItem::is_speed_frame())
  SpeedRamp ramp_;
  std::vector<SpeedRamp::Answer> ramped_;  // the ramp's answers of this iteration
  planner_answers::HeldCounts held_now_;   // held_ as this iteration leaves it (swapped in)
  std::size_t held_total_ = 0;             // the planners' total when held_ was last recounted
  std::vector<Completion> completions_;
  std::uint64_t pushes_taken_ = 0;  // pushes_ when this iteration took its due items
  DaemonOutput produced_;
  std::unordered_map<CommandId, Owner> in_progress_;  // driver command id -> owner
  CommandId next_driver_id_ = 1;
  RobotState state_;
  Kinematics kinematics_;
  std::vector<Eigen::Isometry3d> roots_;
  RobotSample sample_;
  TimePoint next_update_ = TimePoint::min();
  std::int64_t samples_ = 0;
  bool last_iteration_ = false;     // Shutdown()'s: STOP, then a last sample
  std::string reported_condition_;  // the driver's last Driver::Fault() text
  std::string state_problem_;  // what was wrong with the last state read ("a non-finite state: …"), or ""
  // Published after every iteration; read by RobotSessions (declared last:
  // it is built from the model and state_).
  QuerySnapshot snapshot_;
};

template <typename F>
bool RobotDaemon::GuardedPlanner(const char* name, TimePoint now, std::span<const QueuedItem> arriving,
                                 F&& call) {
  try {
    call();
    return true;
  } catch (const std::exception& e) {
    PlannerFault(std::string("the server's ") + name + " threw: " + e.what(), now, arriving);
  } catch (...) {
    PlannerFault(std::string("the server's ") + name + " threw an exception that is not a std::exception",
                 now, arriving);
  }
  return false;
}

template <typename F>
RobotDaemon::CallOutcome RobotDaemon::Guarded(const char* name, const QueuedItem* item, TimePoint now,
                                              F&& call) {
  {
    std::lock_guard lock(call_mutex_);
    call_ = CurrentCall{name,
                        now,
                        item ? item->client_id : 0,
                        item ? item->command.id : 0,
                        item != nullptr && item->client_id != 0,
                        false};
  }
  std::string error;
  bool threw = false;
  try {
    call();
  } catch (const std::exception& e) {
    threw = true;
    error = e.what();
  } catch (...) {
    threw = true;
    error = "an exception that is not a std::exception";
  }
  bool overran = false;
  {
    std::lock_guard lock(call_mutex_);
    overran = call_.overran;
    call_ = CurrentCall{};
  }
  if (overran) return CallOutcome::kOverran;
  if (!threw) return CallOutcome::kOk;
  Fault("driver '" + driver_name_ + "' threw in " + name + ": " + error, now);
  return CallOutcome::kThrew;
}

}  // namespace robotalk
