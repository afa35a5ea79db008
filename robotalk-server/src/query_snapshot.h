// The state a robot's queries are answered from on receipt (issue 11, and
// issue 20: read directly by the session side, no detour through the
// RobotDaemon's queues). The RobotDaemon publishes a copy of the state it read
// after each iteration; RobotSessions answers a state query due now from it
// when it is what the driver would report now, and queues the query
// otherwise (the RobotDaemon then answers it in order).
//
// "What the driver would report now" (Answer) means: the copy was read after
// every item due so far ran (no item became due since, none was due on
// arrival after it was read), the driver's halt state is the one the panic
// state asks for, no driver fault is latched (a query then names the fault,
// RobotDaemon::AnswerQuery), and it is at most one driver period old.
//
// Thread safety: Publish() and wanted() on the RobotDaemon's thread;
// NoteDue(), Answer() and answered() on one other thread (the ServerDaemon's,
// RobotSessions). A small lock is held only to copy the state (same sizes: no
// allocation).
#pragma once

#include "command_queue.h"
#include "panic_state.h"
#include "robotalk/clock.h"
#include "robotalk/driver.h"
#include "robotalk/kinematics.h"
#include "robotalk/request.h"

#include <Eigen/Geometry>
#include <atomic>
#include <cstdint>
#include <memory>
#include <mutex>
#include <vector>

namespace robotalk {

/// x y z qw qx qy qz of `x`, written to out[0..6].
void WritePose7(const Eigen::Isometry3d& x, double* out);
/// The heading of `x` about the world z axis (rad).
double PlanarYaw(const Eigen::Isometry3d& x);
/// Answers a state query (JOINT_STATE, LINK_POSES, FRAME_POSES, BASE_POSE)
/// from `state`: values and signal; ERROR naming the query for a state
/// kinematics cannot use. `kinematics` and `roots` are the caller's scratch,
/// sized for `model`.
void AnswerQueryFrom(const RobotModel& model, const RobotState& state, Kinematics& kinematics,
                     std::vector<Eigen::Isometry3d>& roots, const QueuedItem& item, Reply& reply);

class QuerySnapshot {
 public:
  /// `model`, `clock` and `panic` must outlive it.
  QuerySnapshot(const RobotModel& model, const RobotState& initial, const Clock& clock,
                const PanicState& panic);
  QuerySnapshot(const QuerySnapshot&) = delete;
  QuerySnapshot& operator=(const QuerySnapshot&) = delete;

  // --- RobotDaemon thread ----------------------------------------------------
  /// Whether a query came within the last second: only then is a copy made.
  bool wanted(TimePoint now) const { return now.time_since_epoch().count() < wanted_until_.load(); }
  /// Publishes `state` (nullptr: no valid state now), read at `time` after
  /// every item pushed before the `items_taken`-th ran; `next_due` is the
  /// scheduler's next deadline then, `max_age` the driver period, `halted`
  /// whether the driver was halted.
  void Publish(const RobotState* state, TimePoint time, Duration max_age, std::uint64_t items_taken,
               TimePoint next_due, bool halted);

  // --- session side ----------------------------------------------------------
  /// The `pushes`-th item submitted was due on arrival (RobotDaemon::Submit).
  void NoteDue(std::uint64_t pushes) { last_due_push_ = pushes; }
  /// Answers the state query `item`, due now, into `reply` (id, exec_time =
  /// the clock's now, values, signal) when the snapshot is current; returns
  /// false, `reply` untouched, when the query must be queued. Either way
  /// snapshots are published for the next second.
  bool Answer(const QueuedItem& item, Reply& reply);
  /// Queries answered here so far.
  std::uint64_t answered() const { return answered_; }

 private:
  struct Copy {
    RobotState state;
    bool valid = false;                     // the read succeeded and was finite
    bool halted = false;                    // the driver was halted then
    TimePoint time{};                       // when it was read
    Duration max_age{0};                    // the driver period: older is stale
    std::uint64_t items_taken = 0;          // every item pushed before this many was taken
    TimePoint next_due = TimePoint::min();  // the scheduler's next deadline then
  };

  const RobotModel& model_;
  const Clock& clock_;
  const PanicState& panic_;
  std::atomic<Duration::rep> wanted_until_{0};
  mutable std::mutex mutex_;
  Copy published_;  // GUARDED_BY(mutex_)
  // Session side only.
  Copy read_;
  std::uint64_t last_due_push_ = 0;
  std::uint64_t answered_ = 0;
  std::unique_ptr<Kinematics> kinematics_;
  std::vector<Eigen::Isometry3d> roots_;
};

}  // namespace robotalk
