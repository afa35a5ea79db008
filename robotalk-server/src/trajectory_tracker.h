// The RobotDaemon's trajectories (issue 22): the timed JOINT_SETPOINT
// waypoints of interpolated packages, joined per joint into a
// robotalk::Trajectory and sampled every control period into the reference
// the driver follows (Driver::Track). A pure class: no threads, no clock, no
// driver calls; the RobotDaemon feeds it arrivals and times.
//
// The rules (docs/protocol.md, Trajectories):
// - A waypoint is taken when it arrives. An idle joint's trajectory starts at
//   that moment from the joint's measured position and velocity.
// - A waypoint at or before the trajectory's last one replaces the remainder
//   from its time on (a splice): the replaced waypoints answer INTERRUPTED,
//   naming the command that replaced them, whichever client sent it ("last
//   commanded wins", as ownership). Position and velocity (and acceleration,
//   quintic) stay continuous.
// - A waypoint appended after the last one re-plans only the segments that
//   depend on it (the previous waypoint's velocity is chosen again now that
//   its next one is known): a stream of single-waypoint packages runs
//   smoothly, not stop-and-go.
// - Limits: a waypoint outside the joint's position limits is clamped. A plan
//   whose velocity (URDF) or acceleration (the server's --max-acceleration)
//   exceeds the limits keeps its times -- the client's timing is the
//   contract, and time-scaling would make every later waypoint of a stream
//   land before the stretched ones -- and the reference is limited instead:
//   it follows the plan exactly while the plan is within the limits, and
//   otherwise approaches it at most at the velocity and acceleration limits
//   until it is back on it. The waypoints concerned answer MODIFIED naming
//   the limit and the value (and how far the reference was from them at
//   their time). So no reference beyond a position, velocity or acceleration
//   limit, and no velocity step beyond one period's worth of the acceleration
//   limit, ever reaches a driver.
// - After the last waypoint the trajectory holds (decelerating within the
//   acceleration limit); it never extrapolates.
// - A waypoint that arrives after its time: INTERRUPTED when a later waypoint
//   of the joint is already planned; otherwise it is joined one control
//   period from now (its reference limited if it must be) and answers MODIFIED.
// - Each waypoint is answered when the trajectory passes it: SUCCESS, or
//   MODIFIED with what was changed.
//
// Allocation: once every joint has had a trajectory and each has held its
// most waypoints, neither Sample() nor Add() of a waypoint appended to a
// running trajectory allocates; an answer with a message (MODIFIED,
// INTERRUPTED, a refusal) allocates its text, and so do End(), a trajectory's
// start and a frame trajectory's start.
#pragma once

#include "command_queue.h"
#include "planner_answers.h"
#include "robotalk/command.h"
#include "robotalk/driver.h"
#include "robotalk/inverse_kinematics.h"
#include "robotalk/kinematics.h"
#include "robotalk/robot_model.h"
#include "robotalk/trajectory.h"

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace robotalk {

/// The default of TrackerOptions::acceleration_limit (rad/s² or m/s²).
inline constexpr double kDefaultTrajectoryAcceleration = 20.0;

struct TrackerOptions {
  /// Per dof, for the reference limiter and the hold after the last waypoint (> 0).
  double acceleration_limit = kDefaultTrajectoryAcceleration;
  /// The driver's control period: a late waypoint is joined this far ahead.
  Duration period = std::chrono::milliseconds(10);
};

class TrajectoryTracker {
 public:
  /// The most heap one held waypoint costs (its pending slot, its MODIFIED
  /// note, its knot in the trajectory; the containers' doubling and the moment
  /// a growing one holds its old and new storage included), for the server's
  /// memory bound (QueuedItemBytes). Measured at most 1,059 B (a 6-dof
  /// joint's clamped quintic waypoints with rates; HeldWaypointMemory).
  static constexpr std::size_t kHeldWaypointBytes = 1152;

  struct Answer {
    std::int64_t client_id = 0;
    Reply reply;
  };
  /// A trajectory now a client's (ownership): of a joint, or of a control frame.
  struct Started {
    std::int64_t client_id = 0;
    CommandType type = CommandType::kJointSetPoint;
    int target = -1;
    bool operator==(const Started&) const = default;
  };

  TrajectoryTracker(const RobotModel& model, TrackerOptions options);

  /// Adds the waypoints that arrived (QueuedItem::is_waypoint(), any joints,
  /// in arrival order) at `now`; `state` is the robot's measured state.
  /// Refused, replaced and superseded waypoints are answered in `answers`.
  /// `started` gets (client, joint) for every joint whose trajectory this
  /// made that client's (ownership).
  void Add(std::span<const QueuedItem> waypoints, TimePoint now, const RobotState& state,
           std::vector<Answer>& answers, std::vector<Started>& started);

  /// Samples every active trajectory at `now` into references(); answers the
  /// waypoints passed by `now`. A trajectory that has passed its last waypoint
  /// and come to rest ends (its joint holds there: the last reference).
  void Sample(TimePoint now, std::vector<Answer>& answers);
  /// The references of the last Sample(): one per joint with an active trajectory.
  std::span<const JointReference> references() const { return references_; }

  /// Ends joint `joint`'s trajectory (or the frame trajectory that moves
  /// it): every waypoint not yet passed answers INTERRUPTED with `why`. No-op
  /// for a joint without one.
  void End(int joint, TimePoint now, const std::string& why, std::vector<Answer>& answers);
  /// Ends every trajectory.
  void EndAll(TimePoint now, const std::string& why, std::vector<Answer>& answers);
  /// After a throw out of this tracker (a server fault): drops every
  /// trajectory without sampling or planning; every waypoint it holds answers
  /// INTERRUPTED with `why`, passed or not (none is known to have run).
  void Abandon(TimePoint now, const std::string& why, std::vector<Answer>& answers);
  bool active() const { return active_ > 0; }
  /// The largest |velocity change| / (time since the previous reference) of
  /// any reference handed out so far, over every joint (rad/s² or m/s²): what
  /// the acceleration limit bounds, measured on the server's own periods
  /// (SERVER_COUNTERS' reference_max_acceleration).
  double max_reference_acceleration() const { return max_reference_acceleration_; }
  /// Waypoints waiting to be passed, over every joint (for tests and bounds).
  std::size_t pending() const;
  /// Adds each client's waypoints waiting to be passed to `counts`.
  void CountPending(planner_answers::HeldCounts& counts) const;

 private:
  struct Pending {  // a waypoint not yet passed: the trajectory's last knots, in order
    std::int64_t client_id = 0;
    CommandId id = 0;
    TimePoint requested{};  // the time the client asked for
    Waypoint waypoint;      // as given (position clamped; rates as given or empty)
    std::string note;       // why it is MODIFIED, or ""
  };
  // The waypoints not yet passed, oldest first. Its slots (and the vectors in
  // them) are reused: it allocates only to grow past the most it has held.
  class PendingQueue {
   public:
    bool empty() const { return count_ == 0; }
    std::size_t size() const { return count_; }
    Pending& operator[](std::size_t i) { return slots_[(head_ + i) % slots_.size()]; }
    const Pending& operator[](std::size_t i) const { return slots_[(head_ + i) % slots_.size()]; }
    Pending& front() { return (*this)[0]; }
    Pending& back() { return (*this)[count_ - 1]; }
    const Pending& back() const { return (*this)[count_ - 1]; }
    void pop_front() {
      head_ = (head_ + 1) % slots_.size();
      --count_;
    }
    /// Keeps the first `n`.
    void truncate(std::size_t n) { count_ = std::min(count_, n); }
    /// A slot at the back, holding whatever it held last: assign it.
    Pending& push_back();

   private:
    std::vector<Pending> slots_;
    std::size_t head_ = 0, count_ = 0;
  };
  struct Track {
    std::optional<Trajectory> trajectory;
    std::string label;  // "JOINT_SETPOINT 'name'" / "FRAME_SETPOINT 'name'", for answers
    PendingQueue pending;
    Pending incoming;             // the waypoint being added (reused)
    std::vector<Waypoint> batch;  // the waypoints spliced in by one addition (reused; at most 3)
    TrajectorySample sample;
    TrajectoryLimits limits;
    // The reference handed to the driver (limited), and whether it is the plan's sample.
    Eigen::VectorXd ref_position, ref_velocity, ref_acceleration;
    TimePoint last_sample{};
    bool on_plan = true;
    bool fresh = false;      // started at last_sample: its first reference is its start state
    std::int64_t owner = 0;  // the client of its latest waypoint
    std::string limited;     // the first limit the reference met since the last waypoint passed
    int first_dof = 0;
    int dofs = 0;
    // A control frame's track (6 dofs: x y z and the rotation vector of its
    // orientation relative to `base`), or -1 for a joint's.
    int frame = -1;
    Eigen::Quaterniond base = Eigen::Quaterniond::Identity();
    std::vector<int> chain;  // a frame's: the joints its inverse kinematics moves
    // A joint's: the frame whose trajectory moves it (-1: none), and the
    // last solution's velocity (for the acceleration of the next).
    int moved_by = -1;
    Eigen::VectorXd solved_velocity;
  };

  void AddJointWaypoint(const QueuedItem& item, TimePoint now, const RobotState& state,
                        std::vector<Answer>& answers, std::vector<Started>& started);
  void AddFrameWaypoint(const QueuedItem& item, TimePoint now, const RobotState& state,
                        std::vector<Answer>& answers, std::vector<Started>& started);
  // t.incoming, set for `item` (the position and rates are the caller's to fill).
  Pending& Incoming(Track& t, const QueuedItem& item);
  // Joins `p` to `t`'s trajectory (starting it at `now` from `start` when
  // idle): late, splice and replacement rules. False when refused (answered).
  // `start` is used only when the track is idle (a trajectory of another
  // interpolation was ended by the caller). `p` is t.incoming.
  bool Join(Track& t, const std::string& label, Pending& p, const QueuedItem& item, TimePoint now,
            const TrajectoryState& start, std::vector<Answer>& answers);
  void EndTrack(Track& t, TimePoint now, const std::string& why, std::vector<Answer>& answers);
  void EndFrame(int frame, TimePoint now, const std::string& why, std::vector<Answer>& answers);
  // Answers the waypoints of `t` passed by `now`; `label` names its target.
  void AnswerPassed(Track& t, TimePoint now, const std::string& label, std::vector<Answer>& answers);
  // A frame trajectory's period: its pose by inverse kinematics, the chain's references.
  void SampleFrame(Track& f, TimePoint now, std::vector<Answer>& answers);
  void Interrupt(Track& t, std::size_t from, TimePoint now, const std::string& why,
                 std::vector<Answer>& answers);
  // The reference from the plan's sample: the plan itself while it is within
  // the limits and the reference is on it; else a rate-limited approach.
  void Limit(Track& t, TimePoint now);

  const RobotModel& model_;
  TrackerOptions options_;
  std::vector<Track> tracks_;        // per joint
  std::vector<Track> frame_tracks_;  // per control frame
  Kinematics kinematics_;
  InverseKinematics ik_;
  Eigen::VectorXd ik_start_;  // where the next solve starts (the last solution)
  std::vector<Eigen::Isometry3d> roots_;
  std::vector<JointReference> references_;
  std::vector<const QueuedItem*> order_;  // Add()'s waypoints in time order (reused)
  int active_ = 0;
  double max_reference_acceleration_ = 0;
  Eigen::VectorXd velocity_before_;  // Limit()'s previous reference velocity (sized once)
};

}  // namespace robotalk
