// Issue 22: the RobotDaemon's trajectories, on a manual clock: the pure
// TrajectoryTracker, then a RobotDaemon with the kinematic driver (which
// follows a reference exactly), so what a client's waypoints do to the robot
// is checked end to end without a network.
#include "trajectory_tracker.h"
#include "kinematic_driver.h"
#include "queued_items.h"
#include "robot_daemon.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "support/allocation_counter.h"  // g_mallocs
#include "support/test_clients.h"

namespace robotalk {
namespace {

using std::chrono::milliseconds;
using ::testing::HasSubstr;

using testing::kAlice;
using testing::kBob;
using testing::kT0;

// A base and an arm joint "elbow" (revolute, ±2 rad, 2 rad/s) and a 2-dof "wrist".
RobotModel Arm() {
  RobotModelBuilder b("arm");
  b.AddLink(Link{.name = "base"}).AddLink(Link{.name = "upper"}).AddLink(Link{.name = "hand"});
  Joint elbow{.name = "elbow", .servo_types = ServoType::kSetPoint};
  elbow.dofs = {Dof{.axis = Eigen::Vector3d::UnitZ(), .limits = {.lower = -2, .upper = 2, .velocity = 2}}};
  Joint wrist{.name = "wrist", .servo_types = ServoType::kSetPoint};
  wrist.dofs = {Dof{.axis = Eigen::Vector3d::UnitY(), .limits = {.lower = -3, .upper = 3, .velocity = 4}},
                Dof{.axis = Eigen::Vector3d::UnitX(), .limits = {.lower = -3, .upper = 3, .velocity = 4}}};
  b.AddJoint(elbow, "base", "upper").AddJoint(wrist, "upper", "hand");
  b.AddControlFrame(ControlFrame{.name = "tool", .servo_types = ServoType::kSetPoint}, "hand");
  b.AddControlFrame(ControlFrame{.name = "plate", .servo_types = ServoType::kSetPoint}, "base");
  b.SetRoot("base", Pose{}, BaseType::kFixed);
  return b.Build();
}

using testing::Rest;
using testing::Waypoint;  // kItemClient is kAlice

class TrackerTest : public ::testing::Test {
 protected:
  RobotModel model_ = Arm();
  TrajectoryTracker tracker_{model_, TrackerOptions{.acceleration_limit = 20, .period = milliseconds(10)}};
  std::vector<TrajectoryTracker::Answer> answers_;
  std::vector<TrajectoryTracker::Started> started_;

  void Add(std::vector<QueuedItem> items, TimePoint now) {
    tracker_.Add(items, now, Rest(model_), answers_, started_);
  }
  // Samples every 10 ms from `from` to `to`; returns the elbow's positions.
  std::vector<double> Run(TimePoint from, TimePoint to) {
    std::vector<double> q;
    for (TimePoint t = from; t <= to; t += milliseconds(10)) {
      tracker_.Sample(t, answers_);
      for (const JointReference& r : tracker_.references()) {
        if (r.joint == 0) q.push_back(r.position[0]);
      }
    }
    return q;
  }
  const TrajectoryTracker::Answer* AnswerTo(CommandId id) const {
    for (const auto& a : answers_) {
      if (a.reply.id == id) return &a;
    }
    return nullptr;
  }
};

TEST_F(TrackerTest, PassesThroughEachWaypointAtItsTimeAndAnswersItThen) {
  Add({Waypoint(1, 0, kT0 + milliseconds(1000), {0.2}), Waypoint(2, 0, kT0 + milliseconds(2000), {0.5})},
      kT0);
  EXPECT_EQ(started_, (std::vector<TrajectoryTracker::Started>{{kAlice, CommandType::kJointSetPoint, 0}}));
  Run(kT0, kT0 + milliseconds(990));
  EXPECT_EQ(AnswerTo(1), nullptr) << "answered before its time";
  Run(kT0 + milliseconds(1000), kT0 + milliseconds(1000));
  ASSERT_NE(AnswerTo(1), nullptr);
  EXPECT_EQ(AnswerTo(1)->reply.signal, Signal::kSuccess) << AnswerTo(1)->reply.message;
  EXPECT_EQ(AnswerTo(1)->reply.exec_time, kT0 + milliseconds(1000));
  EXPECT_NEAR(tracker_.references()[0].position[0], 0.2, 1e-12);
  Run(kT0 + milliseconds(1010), kT0 + milliseconds(2000));
  EXPECT_NEAR(tracker_.references()[0].position[0], 0.5, 1e-12);
  EXPECT_EQ(AnswerTo(2)->reply.signal, Signal::kSuccess);
  EXPECT_DOUBLE_EQ(tracker_.references()[0].velocity[0], 0.0) << "the last waypoint is reached at rest";
  tracker_.Sample(kT0 + milliseconds(2010), answers_);
  EXPECT_FALSE(tracker_.active()) << "at rest after its last waypoint: the trajectory ends";
}

// A stream of one-waypoint packages (delay mode at 100 Hz) must not stop at
// every waypoint: the previous waypoint's velocity is chosen again when the
// next one arrives.
TEST_F(TrackerTest, AStreamOfSingleWaypointsMovesSmoothlyNotStopAndGo) {
  // Starts at rest (a cosine bump), so the plan is within the limits throughout.
  const auto sine = [](TimePoint t) { return 0.25 * (1 - std::cos(std::numbers::pi * ToSeconds(t - kT0))); };
  const milliseconds delay(100);
  const auto rate = [](TimePoint t) {
    return 0.25 * std::numbers::pi * std::sin(std::numbers::pi * ToSeconds(t - kT0));
  };
  double max_error = 0, max_velocity_error = 0;
  for (int k = 0; k <= 200; ++k) {
    const TimePoint now = kT0 + milliseconds(10 * k);
    Add({Waypoint(k + 1, 0, now + delay, {sine(now + delay)})}, now);
    tracker_.Sample(now, answers_);
    if (k >= 20 && k < 200) {
      max_error = std::max(max_error, std::abs(tracker_.references()[0].position[0] - sine(now)));
      max_velocity_error =
          std::max(max_velocity_error, std::abs(tracker_.references()[0].velocity[0] - rate(now)));
    }
  }
  EXPECT_LT(max_error, 1e-5);
  // Through a waypoint the velocity is its neighbours' (0.785 rad/s at most), not zero.
  EXPECT_LT(max_velocity_error, 1e-2);
  // From rest, the first plan may need more than the limit for a moment; after that every waypoint is passed
  // as planned.
  for (const auto& a : answers_) {
    if (a.reply.id > 15) {
      EXPECT_EQ(a.reply.signal, Signal::kSuccess) << a.reply.message;
    }
  }
}

TEST_F(TrackerTest, AStreamOfWaypointsAppendedToARunningTrajectoryDoesNotAllocate) {
  // Issue 22's goal: no allocation on the control path, the periods in which
  // waypoints arrive included, once warmed up (every buffer at its size, past
  // the knot bound). Quintic (the widest re-plan), on a 1-dof and a 2-dof joint.
  answers_.reserve(256);
  started_.reserve(16);
  std::vector<QueuedItem> batch;
  batch.reserve(2);
  const RobotState rest = Rest(model_);
  const auto wave = [](TimePoint t) { return 0.5 * std::sin(std::numbers::pi * ToSeconds(t - kT0)); };
  long during = 0;
  for (int k = 0; k < 400; ++k) {
    const TimePoint now = kT0 + milliseconds(10 * k), at = now + milliseconds(100);
    batch.clear();
    batch.push_back(Waypoint(2 * k + 1, 0, at, {wave(at)}, Interpolation::kQuintic));
    batch.push_back(Waypoint(2 * k + 2, 1, at, {wave(at), -wave(at)}, Interpolation::kQuintic));
    answers_.clear();
    const long before = g_mallocs;
    tracker_.Add(batch, now, rest, answers_, started_);
    tracker_.Sample(now, answers_);
    if (k >= 200) during += g_mallocs - before;
  }
  EXPECT_EQ(during, 0) << "allocations in 200 periods with arrivals";
  for (const auto& a : answers_) EXPECT_EQ(a.reply.signal, Signal::kSuccess) << a.reply.message;
}

TEST_F(TrackerTest, AWaypointOfAnotherInterpolationReplacesTheRunningTrajectoryFromWhereTheJointIs) {
  // A cubic trajectory running, then a quintic waypoint on the same joint:
  // the cubic one is superseded and the quintic one starts from the measured
  // state (it once started from nothing and threw out of the RobotDaemon).
  Add({Waypoint(1, 0, kT0 + milliseconds(200), {0.3}), Waypoint(2, 0, kT0 + milliseconds(400), {0.5})}, kT0);
  Run(kT0, kT0 + milliseconds(100));
  RobotState here = Rest(model_);
  here.position[0] = tracker_.references()[0].position[0];
  here.velocity[0] = tracker_.references()[0].velocity[0];
  tracker_.Add(
      std::vector<QueuedItem>{Waypoint(3, 0, kT0 + milliseconds(500), {0.2}, Interpolation::kQuintic)},
      kT0 + milliseconds(100), here, answers_, started_);
  ASSERT_NE(AnswerTo(1), nullptr);
  EXPECT_EQ(AnswerTo(1)->reply.signal, Signal::kInterrupted);
  EXPECT_THAT(AnswerTo(1)->reply.message, HasSubstr("superseded by command 3 (quintic)"));
  const std::vector<double> q = Run(kT0 + milliseconds(100), kT0 + milliseconds(700));
  ASSERT_FALSE(q.empty());
  EXPECT_NEAR(q.front(), here.position[0], 1e-9) << "starts from where the joint is";
  ASSERT_NE(AnswerTo(3), nullptr);
  EXPECT_EQ(AnswerTo(3)->reply.signal, Signal::kSuccess) << AnswerTo(3)->reply.message;
  EXPECT_NEAR(q.back(), 0.2, 1e-9);
}

TEST_F(TrackerTest, ASpliceReplacesTheRemainderContinuouslyAndInterruptsWhatItReplaced) {
  Add({Waypoint(1, 0, kT0 + milliseconds(1000), {0.5}), Waypoint(2, 0, kT0 + milliseconds(2000), {1.0}),
       Waypoint(3, 0, kT0 + milliseconds(3000), {1.5})},
      kT0);
  Run(kT0, kT0 + milliseconds(1250));
  const double before_p = tracker_.references()[0].position[0];
  const double before_v = tracker_.references()[0].velocity[0];
  // Bob's waypoint at 1.75 s replaces 2 and 3 (last commanded wins).
  Add({Waypoint(9, 0, kT0 + milliseconds(1750), {0.5}, Interpolation::kCubic, kBob)},
      kT0 + milliseconds(1250));
  tracker_.Sample(kT0 + milliseconds(1260), answers_);
  const double dt = 0.01;
  EXPECT_NEAR(tracker_.references()[0].position[0], before_p + before_v * dt, 20 * dt * dt)
      << "a jump at the splice";
  EXPECT_NEAR(tracker_.references()[0].velocity[0], before_v, 20 * dt) << "a velocity step at the splice";
  ASSERT_NE(AnswerTo(2), nullptr);
  EXPECT_EQ(AnswerTo(2)->reply.signal, Signal::kInterrupted);
  EXPECT_THAT(AnswerTo(2)->reply.message, HasSubstr("superseded by command 9 of another client"));
  EXPECT_EQ(AnswerTo(3)->reply.signal, Signal::kInterrupted);
  EXPECT_EQ(AnswerTo(1)->reply.signal, Signal::kSuccess);
  EXPECT_EQ(started_.back(), (TrajectoryTracker::Started{kBob, CommandType::kJointSetPoint, 0}))
      << "bob owns the joint now";
  Run(kT0 + milliseconds(1270), kT0 + milliseconds(1750));
  EXPECT_NEAR(tracker_.references()[0].position[0], 0.5, 1e-6);
}

// The receding-horizon client: every 10 ms a 200 ms trajectory
// starting 20 ms ahead, for 10 s. No freeze, no jump, no velocity step
// larger than one period's worth of the acceleration limit.
TEST_F(TrackerTest, ARecedingHorizonClientRunsWithoutAFreezeAJumpOrAVelocityStep) {
  const auto target = [](TimePoint t) { return 1.2 * std::sin(0.8 * ToSeconds(t - kT0)); };
  CommandId id = 1;
  double last_v = 0, last_p = 0, max_dv = 0, max_dp = 0;
  int frozen = 0;
  for (int tick = 0; tick < 1000; ++tick) {
    const TimePoint now = kT0 + milliseconds(10 * tick);
    std::vector<QueuedItem> batch;
    for (int k = 0; k < 20; ++k) {
      const TimePoint at = now + milliseconds(20 + 10 * k);
      batch.push_back(Waypoint(id++, 0, at, {target(at)}, Interpolation::kQuintic));
    }
    Add(batch, now);
    tracker_.Sample(now, answers_);
    ASSERT_EQ(tracker_.references().size(), 1u) << "the trajectory ended at tick " << tick;
    const double p = tracker_.references()[0].position[0], v = tracker_.references()[0].velocity[0];
    if (tick > 10) {
      max_dv = std::max(max_dv, std::abs(v - last_v));
      max_dp = std::max(max_dp, std::abs(p - last_p));
      if (p == last_p) ++frozen;
    }
    last_v = v;
    last_p = p;
  }
  EXPECT_EQ(frozen, 0);
  EXPECT_LE(max_dv, 20 * 0.010 * 1.0001) << "a velocity step beyond the acceleration limit";
  EXPECT_LT(max_dp, 2 * 0.010 * 1.0001) << "a jump beyond the velocity limit";
  EXPECT_LE(tracker_.pending(), 21u) << "replaced waypoints must not pile up";
}

TEST_F(TrackerTest, ATooFastPlanIsFollowedWithinTheLimitsAndAnswersModifiedNamingTheLimit) {
  // 1.5 rad in 0.1 s needs about 22 rad/s; the elbow allows 2.
  Add({Waypoint(1, 0, kT0 + milliseconds(100), {1.5})}, kT0);
  double vmax = 0, amax = 0, last_v = 0;
  for (TimePoint t = kT0; t <= kT0 + std::chrono::seconds(3); t += milliseconds(10)) {
    tracker_.Sample(t, answers_);
    if (tracker_.references().empty()) break;
    const double v = tracker_.references()[0].velocity[0];
    vmax = std::max(vmax, std::abs(v));
    amax = std::max(amax, std::abs(v - last_v) / 0.01);
    last_v = v;
  }
  EXPECT_LE(vmax, 2 * (1 + 1e-6));
  EXPECT_LE(amax, 20 * (1 + 1e-6));
  // The tracker's own record of it (SERVER_COUNTERS' reference_max_acceleration): the limit, reached.
  EXPECT_NEAR(tracker_.max_reference_acceleration(), amax, 1e-6);
  EXPECT_NEAR(tracker_.max_reference_acceleration(), 20, 1e-6);
  EXPECT_NEAR(tracker_.references().empty() ? 1.5 : tracker_.references()[0].position[0], 1.5, 1e-6);
  ASSERT_NE(AnswerTo(1), nullptr);
  EXPECT_EQ(AnswerTo(1)->reply.signal, Signal::kModified);
  EXPECT_THAT(AnswerTo(1)->reply.message,
              HasSubstr("reference limited: JOINT_SETPOINT 'elbow' dof 0: the plan"));
  EXPECT_THAT(AnswerTo(1)->reply.message, HasSubstr("the limit"));
  EXPECT_THAT(AnswerTo(1)->reply.message, HasSubstr("from it at its time"));
  EXPECT_EQ(AnswerTo(1)->reply.exec_time, kT0 + milliseconds(100)) << "the client's timing is kept";
}

// A linear plan's velocity steps at its knots, its first one included: the
// start knot is where the joint is, moving or not, and the first segment's
// slope is whatever the waypoint asks. That first step is limited like any
// other (review 10: from rest, the first reference of a 2 rad/s slope was
// 2 rad/s, 200 rad/s² in one period, and reference_max_acceleration did not
// count it; a cubic moving at 1.6 rad/s replaced by a linear waypoint the
// other way stepped 3.2 rad/s at once).
TEST_F(TrackerTest, ALinearPlansFirstVelocityStepIsWithinTheAccelerationLimitToo) {
  double amax = 0, last_v = 0;
  const auto run = [&](TimePoint from, TimePoint to) {
    for (TimePoint t = from; t <= to; t += milliseconds(10)) {
      tracker_.Sample(t, answers_);
      if (tracker_.references().empty()) {
        last_v = 0;
        continue;
      }
      const double v = tracker_.references()[0].velocity[0];
      amax = std::max(amax, std::abs(v - last_v) / 0.01);
      last_v = v;
    }
  };
  // From rest: 1 rad in 0.5 s, the elbow's 2 rad/s.
  Add({Waypoint(1, 0, kT0 + milliseconds(500), {1.0}, Interpolation::kLinear)}, kT0);
  run(kT0, kT0 + std::chrono::seconds(2));
  EXPECT_LE(amax, 20 * (1 + 1e-6)) << "from rest";
  EXPECT_LE(tracker_.max_reference_acceleration(), 20 * (1 + 1e-6));
  ASSERT_NE(AnswerTo(1), nullptr);
  EXPECT_EQ(AnswerTo(1)->reply.signal, Signal::kModified) << "the reference was limited on the way";

  // Moving (a cubic at speed), then a linear waypoint back the other way.
  const TimePoint t1 = kT0 + std::chrono::seconds(3);
  RobotState at_one = Rest(model_);
  at_one.position[0] = 1.0;  // where the first plan ended
  tracker_.Add(std::vector<QueuedItem>{Waypoint(2, 0, t1 + milliseconds(500), {0.0}),
                                       Waypoint(3, 0, t1 + milliseconds(1000), {-1.0})},
               t1, at_one, answers_, started_);
  run(t1, t1 + milliseconds(500));
  ASSERT_FALSE(tracker_.references().empty());
  ASSERT_LT(last_v, -1.0) << "moving";
  const TimePoint t2 = t1 + milliseconds(510);
  RobotState moving = Rest(model_);
  moving.position[0] = tracker_.references()[0].position[0];
  moving.velocity[0] = last_v;
  tracker_.Add(std::vector<QueuedItem>{Waypoint(4, 0, t2 + milliseconds(400), {0.5}, Interpolation::kLinear)},
               t2, moving, answers_, started_);
  amax = 0;
  run(t2, t2 + std::chrono::seconds(2));
  EXPECT_LE(amax, 20 * (1 + 1e-6)) << "switching a moving cubic to linear";
  EXPECT_LE(tracker_.max_reference_acceleration(), 20 * (1 + 1e-6));
}

TEST_F(TrackerTest, AWaypointBeyondAPositionLimitIsClampedAndSaysSo) {
  Add({Waypoint(1, 0, kT0 + std::chrono::seconds(3), {2.5})}, kT0);
  const std::vector<double> q = Run(kT0, kT0 + std::chrono::seconds(3));
  for (double x : q) EXPECT_LE(x, 2.0);
  EXPECT_EQ(AnswerTo(1)->reply.signal, Signal::kModified);
  EXPECT_THAT(AnswerTo(1)->reply.message, HasSubstr("2.5 clamped to the upper limit 2"));
}

// Starvation: the client stops sending; the joint decelerates to rest within
// the limit, it never extrapolates.
TEST_F(TrackerTest, WhenWaypointsStopComingTheJointHoldsWithinTheAccelerationLimit) {
  // Cubic: the last known waypoint is planned at rest, so the joint stops on it.
  for (int k = 1; k <= 10; ++k) {
    Add({Waypoint(k, 0, kT0 + milliseconds(100 * k), {0.02 * k}, Interpolation::kCubic)},
        kT0 + milliseconds(100 * (k - 1)));
    Run(kT0 + milliseconds(100 * (k - 1)), kT0 + milliseconds(100 * k - 10));
  }
  std::vector<double> q = Run(kT0 + milliseconds(1000), kT0 + std::chrono::seconds(2));
  EXPECT_NEAR(q.back(), 0.2, 1e-9) << "held at the last waypoint";
  for (double x : q) EXPECT_LE(x, 0.2 + 1e-9) << "past the last waypoint";
  EXPECT_FALSE(tracker_.active());
}

// Linear: the plan stops at once at the last waypoint (an infinite
// deceleration); the reference brakes within the acceleration limit, so it
// passes the waypoint by at most its braking distance, v^2 / (2 a), and
// comes back to it. It never runs on along the last slope.
TEST_F(TrackerTest, ALinearTrajectoryStarvedBrakesWithinItsBrakingDistance) {
  for (int k = 1; k <= 10; ++k) {
    Add({Waypoint(k, 0, kT0 + milliseconds(100 * k), {0.1 * k}, Interpolation::kLinear)}, kT0);
  }
  const std::vector<double> q = Run(kT0, kT0 + std::chrono::seconds(3));
  const double v = 1.0, braking = v * v / (2 * 20);
  for (double x : q) EXPECT_LE(x, 1.0 + braking * 1.01);
  EXPECT_NEAR(q.back(), 1.0, 1e-6);
}

TEST_F(TrackerTest, ALateWaypointIsSkippedWhenALaterOneIsPlannedElseJoinedOnePeriodAhead) {
  Add({Waypoint(1, 0, kT0 + milliseconds(300), {0.3})}, kT0);
  Run(kT0, kT0 + milliseconds(100));
  Add({Waypoint(2, 0, kT0 + milliseconds(50), {0.1})}, kT0 + milliseconds(100));
  ASSERT_NE(AnswerTo(2), nullptr);
  EXPECT_EQ(AnswerTo(2)->reply.signal, Signal::kInterrupted);
  EXPECT_THAT(AnswerTo(2)->reply.message, HasSubstr("after its time; a later waypoint is already planned"));

  Run(kT0 + milliseconds(110), kT0 + milliseconds(800));  // passed 1 and came to rest
  Add({Waypoint(3, 0, kT0 + milliseconds(750), {0.31})}, kT0 + milliseconds(800));
  Run(kT0 + milliseconds(800), kT0 + milliseconds(900));
  ASSERT_NE(AnswerTo(3), nullptr);
  EXPECT_EQ(AnswerTo(3)->reply.signal, Signal::kModified);
  EXPECT_THAT(AnswerTo(3)->reply.message, HasSubstr("after its time: joined"));
}

// Issue 23: a late waypoint past its deadline is not joined: it expires.
TEST_F(TrackerTest, ALateWaypointPastItsDeadlineExpires) {
  QueuedItem late = Waypoint(1, 0, kT0, {0.3});
  late.max_late = milliseconds(50);
  late.received = kT0 + milliseconds(80);
  Add({late}, kT0 + milliseconds(80));
  ASSERT_NE(AnswerTo(1), nullptr);
  EXPECT_EQ(AnswerTo(1)->reply.signal, Signal::kInterrupted);
  EXPECT_THAT(AnswerTo(1)->reply.message, ::testing::StartsWith("expired: arrived 0.08 s after its start"));
  EXPECT_FALSE(tracker_.active()) << "an expired waypoint starts nothing";
}

// A waypoint whose time came between two control periods was passed: a
// STOP (or a step command) right after it does not call it INTERRUPTED.
TEST_F(TrackerTest, AWaypointDueBeforeAnEndInTheSamePeriodCountsAsPassed) {
  Add({Waypoint(1, 0, kT0 + milliseconds(100), {0.01}), Waypoint(2, 0, kT0 + milliseconds(200), {0.02})},
      kT0);
  Run(kT0, kT0 + milliseconds(90));
  tracker_.EndAll(kT0 + milliseconds(105), "stopped by STOP", answers_);
  ASSERT_NE(AnswerTo(1), nullptr);
  EXPECT_EQ(AnswerTo(1)->reply.signal, Signal::kSuccess);
  EXPECT_EQ(AnswerTo(2)->reply.signal, Signal::kInterrupted);
}

TEST_F(TrackerTest, AFrameWaypointNoJointCanMoveAnswersNa) {
  Add({Waypoint(1, 1, kT0 + milliseconds(500), {0, 0, 0, 1, 0, 0, 0}, Interpolation::kCubic, kAlice,
                CommandType::kFrameSetPoint)},
      kT0);
  ASSERT_NE(AnswerTo(1), nullptr);
  EXPECT_EQ(AnswerTo(1)->reply.signal, Signal::kNa);
  EXPECT_THAT(AnswerTo(1)->reply.message, HasSubstr("FRAME_SETPOINT 'plate': no joint"));
  EXPECT_FALSE(tracker_.active());
}

TEST_F(TrackerTest, EndInterruptsEveryWaypointNotYetPassed) {
  Add({Waypoint(1, 0, kT0 + milliseconds(100), {0.01}), Waypoint(2, 0, kT0 + milliseconds(200), {0.02}),
       Waypoint(3, 1, kT0 + milliseconds(200), {0.02, 0.01})},
      kT0);
  Run(kT0, kT0 + milliseconds(100));
  tracker_.EndAll(kT0 + milliseconds(100), "stopped by STOP", answers_);
  EXPECT_EQ(AnswerTo(1)->reply.signal, Signal::kSuccess);
  EXPECT_EQ(AnswerTo(2)->reply.signal, Signal::kInterrupted);
  EXPECT_EQ(AnswerTo(2)->reply.message, "stopped by STOP");
  EXPECT_EQ(AnswerTo(3)->reply.signal, Signal::kInterrupted);
  EXPECT_FALSE(tracker_.active());
}

// --- End to end: a RobotDaemon with the kinematic driver ---------------------

class TrackedDaemonTest : public ::testing::Test {
 protected:
  TrackedDaemonTest()
      : daemon_("arm", "kinematic", std::make_unique<KinematicDriver>(Arm()), clock_,
                RobotDaemonOptions{.precise_timing = false}) {
    daemon_.Preallocate(out_);
  }
  std::vector<DaemonOutput::Answer> RunTo(TimePoint t) {
    std::vector<DaemonOutput::Answer> all;
    while (clock_.Now() < t) {
      clock_.Set(std::min(daemon_.RunOnce(clock_.Now()), t));
      daemon_.TakeOutput(out_);
      for (auto& a : out_.replies) all.push_back(a);
    }
    daemon_.RunOnce(clock_.Now());
    daemon_.TakeOutput(out_);
    for (auto& a : out_.replies) all.push_back(a);
    return all;
  }
  double Elbow() {
    QueuedItem q;
    q.client_id = kAlice;
    q.is_query = true;
    q.query = QueryType::kJointState;
    q.command.id = 777;
    daemon_.Submit(q);
    for (const auto& a : RunTo(clock_.Now())) {
      if (a.reply.id == 777) return a.reply.values.at(0);
    }
    ADD_FAILURE() << "no joint state";
    return NAN;
  }
  ManualClock clock_{kT0};
  RobotDaemon daemon_;
  DaemonOutput out_;
};

TEST_F(TrackedDaemonTest, TheKinematicDriverFollowsACubicSineBetweenItsWaypoints) {
  const auto sine = [](TimePoint t) { return 0.5 * std::sin(std::numbers::pi * ToSeconds(t - kT0)); };
  double max_error = 0;
  for (int k = 0; k < 150; ++k) {  // 10 Hz frames, 0.3 s ahead, over 15 s
    const TimePoint at = kT0 + milliseconds(300 + 100 * k);
    daemon_.Submit(Waypoint(k + 1, 0, at, {sine(at)}, Interpolation::kCubic));
    RunTo(kT0 + milliseconds(100 * (k + 1) + 50));  // between waypoints
    if (k > 5) max_error = std::max(max_error, std::abs(Elbow() - sine(clock_.Now())));
  }
  EXPECT_LT(max_error, 3e-3);
}

// The tracker is the server's own code, but a throw out of it ended the
// RobotDaemon's thread with the robot following its last reference. Here an
// allocation fails in the middle of adding waypoints (the first of a joint's
// trajectory allocates): a SERVER FAULT halts the robot, and every waypoint,
// held or arriving, answers INTERRUPTED exactly once.
TEST_F(TrackedDaemonTest, AThrowInsideTheTrackerHaltsTheRobotAndAnswersEveryWaypointOnce) {
  daemon_.Submit(Waypoint(1, 0, kT0 + milliseconds(500), {0.4}));
  daemon_.Submit(Waypoint(2, 0, kT0 + milliseconds(900), {0.6}));
  std::vector<DaemonOutput::Answer> replies = RunTo(kT0 + milliseconds(100));
  ASSERT_TRUE(replies.empty());
  daemon_.Submit(Waypoint(3, 1, kT0 + milliseconds(600), {0.1, 0.2}));  // the wrist: a new trajectory
  daemon_.Submit(Waypoint(4, 1, kT0 + milliseconds(800), {0.2, 0.3}));
  g_fail_allocation = 1;
  daemon_.RunOnce(clock_.Now());
  g_fail_allocation = 0;
  daemon_.TakeOutput(out_);
  replies = out_.replies;
  EXPECT_TRUE(daemon_.in_panic());
  EXPECT_THAT(daemon_.fault(), HasSubstr("the server's trajectory tracker threw: std::bad_alloc"));
  ASSERT_FALSE(out_.log.empty());
  EXPECT_THAT(out_.log.front(), HasSubstr("SERVER FAULT"));
  const double halted_at = Elbow();
  EXPECT_GT(halted_at, 0.0) << "the elbow's trajectory ran until the fault";
  for (const auto& a : RunTo(kT0 + milliseconds(1500))) replies.push_back(a);
  for (CommandId id : {1, 2, 3, 4}) {
    EXPECT_EQ(std::count_if(replies.begin(), replies.end(), [id](const auto& a) { return a.reply.id == id; }),
              1)
        << "waypoint " << id;
  }
  for (const auto& a : replies) {
    EXPECT_EQ(a.reply.signal, Signal::kInterrupted) << a.reply.message;
    EXPECT_THAT(a.reply.message, HasSubstr("trajectory tracker threw"));
  }
  EXPECT_DOUBLE_EQ(Elbow(), halted_at) << "the elbow stopped where the fault halted it";
}

TEST_F(TrackedDaemonTest, AStepPackageStillJumpsAsBefore) {
  daemon_.Submit(Waypoint(1, 0, kT0 + milliseconds(500), {0.4}, Interpolation::kStep));
  RunTo(kT0 + milliseconds(490));
  EXPECT_DOUBLE_EQ(Elbow(), 0.0) << "a step set-point does not move before its time";
  RunTo(kT0 + milliseconds(800));
  EXPECT_DOUBLE_EQ(Elbow(), 0.4);
}

TEST_F(TrackedDaemonTest, AStopEndsTheTrajectoryAndAnswersItsWaypointsInterrupted) {
  daemon_.Submit(Waypoint(1, 0, kT0 + milliseconds(500), {1.0}, Interpolation::kQuintic));
  daemon_.Submit(Waypoint(2, 0, kT0 + milliseconds(900), {1.5}, Interpolation::kQuintic));
  RunTo(kT0 + milliseconds(300));
  QueuedItem stop;
  stop.client_id = kBob;
  stop.command.id = 50;
  stop.command.type = CommandType::kStop;
  daemon_.Submit(stop);
  const auto answers = RunTo(kT0 + milliseconds(1000));
  int interrupted = 0;
  for (const auto& a : answers) {
    if (a.reply.id == 1 || a.reply.id == 2) {
      EXPECT_EQ(a.reply.signal, Signal::kInterrupted);
      EXPECT_EQ(a.reply.message, "stopped by STOP");
      ++interrupted;
    }
  }
  EXPECT_EQ(interrupted, 2);
  const double q = Elbow();
  EXPECT_GT(q, 0.0);
  EXPECT_LT(q, 1.0) << "the joint stopped where it was";
}

TEST_F(TrackedDaemonTest, APanicEndsTheTrajectoryAndNoReferenceReachesTheDriverAfter) {
  daemon_.Submit(Waypoint(1, 0, kT0 + milliseconds(500), {1.0}, Interpolation::kCubic));
  RunTo(kT0 + milliseconds(200));
  std::vector<QueuedItem> flushed;
  daemon_.Panic(flushed);
  const auto answers = RunTo(kT0 + milliseconds(300));
  const double q = Elbow();
  RunTo(kT0 + milliseconds(800));
  EXPECT_DOUBLE_EQ(Elbow(), q) << "moved in panic";
  bool answered = false;
  for (const auto& a : answers) {
    if (a.reply.id == 1) {
      answered = true;
      EXPECT_EQ(a.reply.signal, Signal::kInterrupted);
    }
  }
  EXPECT_TRUE(answered);
}

// A FRAME_SETPOINT trajectory: the frame's orientation turns about z (the
// elbow's axis); the pose is interpolated in task space and solved by the
// inverse kinematics every period, so the elbow follows the angle.
TEST_F(TrackedDaemonTest, AFrameTrajectoryIsInterpolatedInTaskSpaceAndSolvedEveryPeriod) {
  const auto angle = [](TimePoint t) { return 0.3 * std::sin(std::numbers::pi * ToSeconds(t - kT0)); };
  const auto pose = [&](TimePoint t) {
    const Eigen::Quaterniond q(Eigen::AngleAxisd(angle(t), Eigen::Vector3d::UnitZ()));
    return std::vector<double>{0, 0, 0, q.w(), q.x(), q.y(), q.z()};
  };
  double max_error = 0;
  std::vector<DaemonOutput::Answer> answers;
  for (int k = 0; k < 40; ++k) {  // 10 Hz frames, 0.3 s ahead, over 4 s
    const TimePoint at = kT0 + milliseconds(300 + 100 * k);
    daemon_.Submit(
        Waypoint(k + 1, 0, at, pose(at), Interpolation::kCubic, kAlice, CommandType::kFrameSetPoint));
    for (auto& a : RunTo(kT0 + milliseconds(100 * (k + 1) + 50))) answers.push_back(a);  // between waypoints
    if (k > 5) max_error = std::max(max_error, std::abs(Elbow() - angle(clock_.Now())));
  }
  EXPECT_LT(max_error, 5e-3);
  int success = 0;
  for (const auto& a : answers) {
    if (a.reply.id >= 1 && a.reply.id <= 40) success += a.reply.signal == Signal::kSuccess;
  }
  EXPECT_GT(success, 30) << "frame waypoints passed on time";
}

// A joint waypoint on a joint a frame trajectory moves replaces that trajectory.
TEST_F(TrackerTest, AJointWaypointOnAFramesChainEndsTheFrameTrajectory) {
  const Eigen::Quaterniond q(Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitZ()));
  Add({Waypoint(1, 0, kT0 + milliseconds(1000), {0, 0, 0, q.w(), q.x(), q.y(), q.z()}, Interpolation::kCubic,
                kAlice, CommandType::kFrameSetPoint)},
      kT0);
  EXPECT_EQ(started_.back(), (TrajectoryTracker::Started{kAlice, CommandType::kFrameSetPoint, 0}));
  Run(kT0, kT0 + milliseconds(200));
  EXPECT_FALSE(tracker_.references().empty()) << "the frame's chain gets references";
  Add({Waypoint(2, 0, kT0 + milliseconds(1500), {0.1})}, kT0 + milliseconds(200));
  ASSERT_NE(AnswerTo(1), nullptr);
  EXPECT_EQ(AnswerTo(1)->reply.signal, Signal::kInterrupted);
  EXPECT_THAT(AnswerTo(1)->reply.message, HasSubstr("superseded by JOINT_SETPOINT 'elbow' command 2"));
}

}  // namespace
}  // namespace robotalk
