// A client's command queue: a min-heap ordered by start time, ties in arrival
// order (paper §IV-A). Items due "now" (no start time) sort before any timed
// item. Pure data structure, no locking: the owner (Scheduler, under the
// RobotDaemon's lock) synchronises.
#pragma once

#include "robotalk/clock.h"
#include "robotalk/command.h"
#include "robotalk/driver.h"
#include "robotalk/trajectory.h"

#include <array>
#include <cstdint>
#include <vector>

namespace robotalk {

/// A command or query waiting for its start time.
struct QueuedItem {
  TimePoint start = TimePoint::min();  ///< TimePoint::min() = at once
  std::uint64_t arrival = 0;           ///< server-wide arrival counter
  std::int64_t client_id = 0;          ///< 0 = the server itself (watchdog STOP)
  bool has_start_time = false;         ///< false = "now" (no lateness to report)
  /// How late after `start` it may still begin (expiry.h: EffectiveMaxLate,
  /// set on admission); Duration::max() = never expires.
  Duration max_late = Duration::max();
  TimePoint received{};  ///< when its package reached the server (the expiry's text)
  bool is_query = false;
  DriverCommand command;  ///< when !is_query; command.id is the client's id
  QueryType query = QueryType::kJointState;
  int query_target = -1;        ///< joint / link / frame index, -1 = all
  bool only_if_moving = false;  ///< the server's STOP: skipped if the robot is still
  /// A STOP of only part of the robot (Driver::StopOnly): the watchdog's for
  /// a vanished client (client_id 0): these joints and, with `stop_base`,
  /// the base and its task. Other clients' motion runs on.
  bool scoped_stop = false;
  std::vector<int> stop_joints;
  bool stop_base = false;
  /// The package's interpolation. A JOINT_SETPOINT or FRAME_SETPOINT with a start time in a
  /// package that is not kStep is a trajectory waypoint (is_waypoint()): the
  /// RobotDaemon takes it when it arrives, not at its start time.
  Interpolation interpolation = Interpolation::kStep;
  /// A waypoint's given velocity and acceleration (the first num_rates used; 0 = chosen).
  int num_velocities = 0;
  int num_accelerations = 0;
  std::array<double, 6> velocities{};
  std::array<double, 6> accelerations{};

  bool is_waypoint() const {
    return !is_query && has_start_time && interpolation != Interpolation::kStep &&
           (command.type == CommandType::kJointSetPoint || command.type == CommandType::kFrameSetPoint);
  }

  /// A SETSPEED with a start time in a package that is not kStep: a frame of
  /// the base's speed ramp (speed_ramp.h), taken when it arrives.
  bool is_speed_frame() const {
    return !is_query && has_start_time && interpolation != Interpolation::kStep &&
           command.type == CommandType::kSetSpeed;
  }

  /// Earlier start first; equal starts in arrival order.
  bool RunsBefore(const QueuedItem& o) const {
    return start != o.start ? start < o.start : arrival < o.arrival;
  }
};

class CommandQueue {
 public:
  void Push(QueuedItem item);
  bool empty() const { return heap_.empty(); }
  size_t size() const { return heap_.size(); }
  /// The item that runs first. REQUIRES: !empty().
  const QueuedItem& Top() const { return heap_.front(); }
  /// Removes and returns Top(). REQUIRES: !empty().
  QueuedItem Pop();
  /// Removes every item, appending them to `out` in run order.
  void Flush(std::vector<QueuedItem>& out);

 private:
  std::vector<QueuedItem> heap_;  // std::push_heap order with RunsAfter as "less"
};

}  // namespace robotalk
