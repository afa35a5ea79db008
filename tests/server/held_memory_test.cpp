// The heap a waypoint costs while the trajectory tracker holds it, measured
// (tests/support/allocation_counter.cpp counts every malloc-family byte and
// the peak), against the per-item price the server's memory bound uses
// (ServerMemoryBound in session_memory_test.cpp). The widest kinds: a 6-dof
// joint's quintic waypoints with their rates, every position clamped (the
// longest MODIFIED note), and a control frame's (6 dofs, with rates).
#include "queued_items.h"
#include "robot_sessions.h"
#include "speed_ramp.h"
#include "trajectory_tracker.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>

#include "support/allocation_counter.h"

namespace robotalk {
namespace {

using std::chrono::milliseconds;
using testing::kT0;
using testing::Rest;
using testing::Waypoint;

// A base, a 6-dof joint "free" (±1, clamps the test's ±5), a 1-dof "elbow"
// and a frame "tool" the two move.
RobotModel SixDofArm() {
  RobotModelBuilder b("six");
  b.AddLink(Link{.name = "base"}).AddLink(Link{.name = "carriage"}).AddLink(Link{.name = "hand"});
  Joint free{.name = "free", .servo_types = ServoType::kSetPoint};
  for (int k = 0; k < 6; ++k) {
    Dof d{.type = k < 3 ? DofType::kPrismatic : DofType::kRevolute,
          .axis = Eigen::Vector3d::Unit(k % 3),
          .limits = {.lower = -1, .upper = 1, .velocity = 1e3}};
    free.dofs.push_back(d);
  }
  Joint elbow{.name = "elbow", .servo_types = ServoType::kSetPoint};
  elbow.dofs = {Dof{.axis = Eigen::Vector3d::UnitZ(), .limits = {.lower = -2, .upper = 2, .velocity = 2}}};
  b.AddJoint(free, "base", "carriage").AddJoint(elbow, "carriage", "hand");
  b.AddControlFrame(ControlFrame{.name = "tool", .servo_types = ServoType::kSetPoint}, "hand");
  b.SetRoot("base", Pose{}, BaseType::kFixed);
  return b.Build();
}

struct Cost {
  double held = 0;  ///< bytes in use per waypoint held
  double peak = 0;  ///< the most in use while adding them, per waypoint
};

// Adds `n` waypoints one at a time (as they arrive), 10 ms apart, after a
// first one that starts the trajectory; the bytes they added, per waypoint.
Cost Hold(int n, bool frame) {
  const RobotModel model = SixDofArm();
  TrajectoryTracker tracker(model, TrackerOptions{.acceleration_limit = 1e3, .period = milliseconds(1)});
  std::vector<TrajectoryTracker::Answer> answers;
  std::vector<TrajectoryTracker::Started> started;
  const RobotState rest = Rest(model);
  auto item = [frame](int k) {
    const TimePoint at = kT0 + std::chrono::seconds(1) + k * milliseconds(10);
    QueuedItem w = frame ? Waypoint(k + 1, 0, at, {0.1, 0.2, 0.3, 1, 0, 0, 0}, Interpolation::kQuintic,
                                    testing::kItemClient, CommandType::kFrameSetPoint)
                         : Waypoint(k + 1, 0, at, {5, -5, 5, -5, 5, -5}, Interpolation::kQuintic);
    w.num_velocities = w.num_accelerations = 6;
    for (int d = 0; d < 6; ++d) {
      w.velocities[static_cast<std::size_t>(d)] = 0.1 * (d + 1);
      w.accelerations[static_cast<std::size_t>(d)] = -0.2 * (d + 1);
    }
    return w;
  };
  std::vector<QueuedItem> one{item(0)};
  tracker.Add(one, kT0, rest, answers, started);
  answers.clear();
  answers.reserve(16);
  const long before = HeapBytesInUse();
  ResetHeapBytesPeak();
  for (int k = 1; k <= n; ++k) {
    one[0] = item(k);
    tracker.Add(one, kT0, rest, answers, started);
    answers.clear();
  }
  EXPECT_EQ(tracker.pending(), static_cast<std::size_t>(n + 1)) << "every waypoint held";
  return {static_cast<double>(HeapBytesInUse() - before) / n,
          static_cast<double>(HeapBytesPeak() - before) / n};
}

// The same for SETSPEED frames the speed ramp holds (3 values, 10 ms apart).
Cost HoldSpeedFrames(int n) {
  SpeedRamp ramp(SpeedRampOptions{.period = milliseconds(1)});
  std::vector<SpeedRamp::Answer> answers;
  auto item = [](int k) {
    QueuedItem f = testing::Motion(k + 1, CommandType::kSetSpeed, {0.1, -0.1, 0.2});
    f.has_start_time = true;
    f.start = kT0 + std::chrono::seconds(1) + k * milliseconds(10);
    f.received = kT0;
    f.interpolation = Interpolation::kLinear;
    return f;
  };
  std::vector<QueuedItem> one{item(0)};
  ramp.Add(one, kT0, BaseReference{}, answers);
  answers.reserve(16);
  const long before = HeapBytesInUse();
  ResetHeapBytesPeak();
  for (int k = 1; k <= n; ++k) {
    one[0] = item(k);
    ramp.Add(one, kT0, BaseReference{}, answers);
    answers.clear();
  }
  EXPECT_EQ(ramp.pending(), static_cast<std::size_t>(n + 1)) << "every frame held";
  return {static_cast<double>(HeapBytesInUse() - before) / n,
          static_cast<double>(HeapBytesPeak() - before) / n};
}

// The tracker's containers double: just past a doubling (2^k + 1 items) a
// waypoint costs the most; the peak includes the moment the old and the new
// buffer both exist.
TEST(HeldWaypointMemory, AHeldWaypointOrSpeedFrameCostsNoMoreThanTheServersBoundPricesIt) {
  double waypoint = 0, speed = 0;
  for (bool frame : {false, true}) {
    for (int n : {1024, 2048, 4096}) {
      const Cost c = Hold(n, frame);
      std::printf("%s quintic waypoints with rates, %d held: %.0f B each in use, %.0f B at the peak\n",
                  frame ? "frame (6-dof)" : "joint (6-dof, clamped)", n + 1, c.held, c.peak);
      waypoint = std::max({waypoint, c.held, c.peak});
      EXPECT_GT(c.held, 0) << "the counter sees the tracker's heap";
    }
  }
  for (int n : {1024, 4096}) {
    const Cost c = HoldSpeedFrames(n);
    std::printf("SETSPEED frames, %d held: %.0f B each in use, %.0f B at the peak\n", n + 1, c.held, c.peak);
    speed = std::max({speed, c.held, c.peak});
  }
  EXPECT_LE(waypoint, static_cast<double>(TrajectoryTracker::kHeldWaypointBytes));
  EXPECT_LE(speed, static_cast<double>(SpeedRamp::kHeldFrameBytes));
  // The server's sum prices every waiting item at the most any of them costs.
  EXPECT_GE(QueuedItemBytes(), TrajectoryTracker::kHeldWaypointBytes);
  EXPECT_GE(QueuedItemBytes(), SpeedRamp::kHeldFrameBytes);
}

}  // namespace
}  // namespace robotalk
