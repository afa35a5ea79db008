// Review (session 6): finite but hostile numbers in the fields CheckCommand
// accepts (a waypoint's rates, a frame waypoint's position), sent through the
// session layer to a RobotDaemon with the kinematic driver on a manual clock.
// What the safety case promises for them: bad input gets a clear error naming
// what was wrong, no reference beyond a limit reaches a driver, and one
// client's package never halts the robot for every client.
#include "kinematic_driver.h"
#include "robot_daemon.h"
#include "robot_sessions.h"
#include "robotalk/config_message.h"
#include "robotalk/request.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <initializer_list>
#include <map>
#include <memory>
#include <vector>

#include "support/test_clients.h"

namespace robotalk {
namespace {

using std::chrono::milliseconds;
using std::chrono::seconds;
using ::testing::HasSubstr;
using testing::kAlice;
using testing::kT0;

// A fixed base, an "elbow" (revolute, ±2 rad, 2 rad/s), a continuous "wheel"
// with no limits at all (a URDF continuous joint without <limit>), and a
// control frame "tool" on the hand; on a differential base (so SETSPEED runs).
RobotModel Arm() {
  RobotModelBuilder b("arm");
  b.AddLink(Link{.name = "base"}).AddLink(Link{.name = "upper"}).AddLink(Link{.name = "hand"});
  Joint elbow{.name = "elbow", .servo_types = ServoType::kSetPoint};
  elbow.dofs = {Dof{.axis = Eigen::Vector3d::UnitZ(), .limits = {.lower = -2, .upper = 2, .velocity = 2}}};
  Joint wheel{.name = "wheel", .servo_types = ServoType::kSetPoint | ServoType::kSpeed};
  wheel.dofs = {Dof{.axis = Eigen::Vector3d::UnitY()}};
  b.AddJoint(elbow, "base", "upper").AddJoint(wheel, "upper", "hand");
  b.AddControlFrame(ControlFrame{.name = "tool", .servo_types = ServoType::kSetPoint}, "hand");
  b.SetRoot("base", Pose{}, BaseType::kDifferential);
  return b.Build();
}

Command Waypoint(CommandId id, const std::string& joint, TimePoint at, std::vector<double> values,
                 std::vector<double> velocities = {}) {
  Command c{id, CommandType::kJointSetPoint, StartTime::At(at), joint, std::move(values)};
  c.velocities = std::move(velocities);
  return c;
}

class HostileNumbersTest : public ::testing::Test {
 protected:
  explicit HostileNumbersTest(SessionOptions options = {})
      : daemon_("arm", "kinematic", MakeDriver(), clock_, RobotDaemonOptions{.precise_timing = false}),
        sessions_(daemon_, ConfigHash(daemon_.model()), options) {
    daemon_.Preallocate(out_);
  }

  // One interpolated package of `commands`; the immediate replies by id.
  std::map<CommandId, Reply> Send(std::vector<Command> commands, Interpolation interpolation) {
    Request r{.client_id = kAlice, .sequence = ++sequence_};
    r.interpolation = interpolation;
    r.commands = std::move(commands);
    std::map<CommandId, Reply> immediate;
    for (const Reply& reply : sessions_.Handle(r, clock_.Now()).batch.replies) immediate[reply.id] = reply;
    return immediate;
  }
  void RunTo(TimePoint t) {
    while (clock_.Now() < t) {
      clock_.Set(std::min(daemon_.RunOnce(clock_.Now()), t));
      Collect();
    }
  }
  void Collect() {
    daemon_.TakeOutput(out_);
    std::vector<ReplyBatch> batches;
    sessions_.File(out_, batches);
    for (const ReplyBatch& b : batches) {
      for (const Reply& r : b.replies) replies_[r.id] = r;
    }
  }
  double Position(int dof) {
    RobotState s;
    driver_->ReadState(s);
    return s.position[dof];
  }
  // Each of `ids` was answered ERROR at once, naming `text`.
  static void ExpectRefused(const std::map<CommandId, Reply>& immediate, std::initializer_list<CommandId> ids,
                            const std::string& text) {
    for (CommandId id : ids) {
      ASSERT_TRUE(immediate.contains(id)) << "command " << id << " not refused";
      EXPECT_EQ(immediate.at(id).signal, Signal::kError) << immediate.at(id).message;
      EXPECT_THAT(immediate.at(id).message, HasSubstr(text));
    }
  }
  // Nothing of the refused package ran: the robot is not in panic, and a
  // well-formed waypoint sent next still reaches the elbow.
  void ExpectServingOn() {
    RunTo(clock_.Now() + milliseconds(300));
    EXPECT_FALSE(daemon_.in_panic()) << "one client's package halted the robot: " << daemon_.fault();
    const TimePoint at = clock_.Now() + seconds(1);  // within the elbow's limits
    EXPECT_TRUE(Send({Waypoint(99, "elbow", at, {0.25})}, Interpolation::kCubic).empty());
    RunTo(at + milliseconds(20));
    ASSERT_TRUE(replies_.contains(99));
    EXPECT_EQ(replies_[99].signal, Signal::kSuccess) << replies_[99].message;
    EXPECT_NEAR(Position(0), 0.25, 1e-9);
  }
  std::unique_ptr<Driver> MakeDriver() {
    auto driver = std::make_unique<KinematicDriver>(Arm());
    driver_ = driver.get();
    return driver;
  }

  KinematicDriver* driver_ = nullptr;  // owned by daemon_
  ManualClock clock_{kT0};
  RobotDaemon daemon_;
  RobotSessions sessions_;
  DaemonOutput out_;
  std::int64_t sequence_ = 0;
  std::map<CommandId, Reply> replies_;
};

// Each test below halted the robot in panic before CheckCommand bounded every
// number by kMaxCommandMagnitude (1e9): a finite but huge number overflowed
// the plan's arithmetic to NaN, which reached the driver.
//
// A waypoint's velocity: 1e308 rad/s 0.1 s ahead overflowed the cubic's
// coefficients (trajectory.cpp, Rebuild: -inf and +inf), the plan's sample
// was NaN, TrajectoryTracker::Limit passed NaN on (std::clamp of NaN is NaN),
// the kinematic driver's joint became NaN and the RobotDaemon halted the
// robot ("non-finite state") for every client.
TEST_F(HostileNumbersTest, AWaypointWhoseVelocityOverflowsThePlanIsRefusedAndTheRobotServesOn) {
  const std::map<CommandId, Reply> immediate =
      Send({Waypoint(1, "elbow", kT0 + milliseconds(100), {0.5}, {1e308})}, Interpolation::kCubic);
  ExpectRefused(immediate, {1}, "JOINT_SETPOINT 'elbow': velocity 0 is 1e+308, beyond ±1e+09");
  ExpectServingOn();
}

// A frame waypoint's position (a pose's x, y, z were only checked finite):
// 1e308 m made the cubic's sample NaN, the inverse kinematics threw on it and
// the RobotDaemon reported a SERVER FAULT and halted the robot.
TEST_F(HostileNumbersTest, AFrameWaypointAHugeDistanceAwayIsRefusedAndTheRobotServesOn) {
  const std::map<CommandId, Reply> immediate =
      Send({Command{1, CommandType::kFrameSetPoint, StartTime::At(kT0 + milliseconds(100)), "tool",
                    std::vector<double>{1e308, 0, 0, 1, 0, 0, 0}}},
           Interpolation::kCubic);
  ExpectRefused(immediate, {1}, "FRAME_SETPOINT 'tool': value 0 is 1e+308, beyond ±1e+09");
  ExpectServingOn();
}

// A continuous joint with no <limit> has no position or velocity bound: two
// waypoints ±1.7e308 rad made their difference overflow and the plan NaN.
TEST_F(HostileNumbersTest, WaypointsWhoseDifferenceOverflowsAreRefusedAndTheRobotServesOn) {
  const std::map<CommandId, Reply> immediate =
      Send({Waypoint(1, "wheel", kT0 + milliseconds(100), {1.7e308}),
            Waypoint(2, "wheel", kT0 + milliseconds(200), {-1.7e308})},
           Interpolation::kLinear);
  ExpectRefused(immediate, {1, 2}, "JOINT_SETPOINT 'wheel': value 0 is");
  ExpectServingOn();
}

// The base speed ramp (speed_ramp.cpp, Approach): SETSPEED frames +1.7e308
// and -1.7e308 m/s made the plan's segment -inf, the clipped reference
// ref + 0 * -inf = NaN, and driver_support::ShapeBaseSpeed passed NaN on
// (NaN > max_v is false): the base pose became NaN.
TEST_F(HostileNumbersTest, SpeedFramesWhoseDifferenceOverflowsAreRefusedAndTheRobotServesOn) {
  const auto speed = [](CommandId id, TimePoint at, double v) {
    return Command{id, CommandType::kSetSpeed, StartTime::At(at), "", std::vector<double>{v, 0}};
  };
  const std::map<CommandId, Reply> immediate =
      Send({speed(1, kT0 + milliseconds(100), 1.7e308), speed(2, kT0 + milliseconds(200), -1.7e308)},
           Interpolation::kLinear);
  ExpectRefused(immediate, {1, 2}, "SETSPEED: value 0 is");
  ExpectServingOn();
}

// The bound is what keeps the arithmetic finite: the worst a client may send
// within it (quintic waypoints ±1e9 rad on the unlimited wheel, 1 µs apart,
// every rate ±1e9, and SETSPEED frames ±1e9 m/s) is accepted and runs
// without a non-finite reference reaching the driver.
TEST_F(HostileNumbersTest, TheWorstNumbersWithinTheBoundRunWithoutANonFiniteReference) {
  constexpr double kMax = kMaxCommandMagnitude;
  Command a = Waypoint(1, "wheel", kT0 + milliseconds(100), {kMax}, {-kMax});
  a.accelerations = {kMax};
  Command b = Waypoint(2, "wheel", kT0 + milliseconds(100) + std::chrono::microseconds(1), {-kMax}, {kMax});
  b.accelerations = {-kMax};
  std::map<CommandId, Reply> immediate = Send({a, b}, Interpolation::kQuintic);
  EXPECT_TRUE(immediate.empty()) << immediate.begin()->second.message;
  immediate = Send({Command{3, CommandType::kSetSpeed, StartTime::At(kT0 + milliseconds(150)), "",
                            std::vector<double>{kMax, -kMax}},
                    Command{4, CommandType::kSetSpeed, StartTime::At(kT0 + milliseconds(160)), "",
                            std::vector<double>{-kMax, kMax}}},
                   Interpolation::kLinear);
  EXPECT_TRUE(immediate.empty()) << immediate.begin()->second.message;
  RunTo(kT0 + milliseconds(300));
  EXPECT_FALSE(daemon_.in_panic()) << daemon_.fault();
  EXPECT_TRUE(std::isfinite(Position(1)));
}

// Issue 23's expiry (expiry.h): a speed that arrives past its deadline "was
// meant to end the previous motion at its start time, so that actuator is
// stopped and holds ... the previous speed does not run on past its time".
// The base's ramp is ended for an expired SETSPEED; a joint's trajectory was
// not ended for an expired JOINT_SPEED: the driver's StopOnly held the joint
// for one period and the tracker's next reference moved it on along the
// trajectory the expired command was meant to replace.
using ExpiredSpeedTest = HostileNumbersTest;

TEST_F(ExpiredSpeedTest, AnExpiredJointSpeedEndsTheJointsTrajectoryAndTheJointHolds) {
  EXPECT_TRUE(Send({Waypoint(1, "wheel", kT0 + milliseconds(1000), {1.0}),
                    Waypoint(2, "wheel", kT0 + milliseconds(2000), {2.0})},
                   Interpolation::kCubic)
                  .empty());
  RunTo(kT0 + milliseconds(500));
  ASSERT_GT(Position(1), 0.1) << "the trajectory moves the wheel";
  // Due 0.3 s ago: past the robot's 0.1 s default deadline for servo commands.
  const std::map<CommandId, Reply> immediate =
      Send({Command{3, CommandType::kJointSpeed, StartTime::At(clock_.Now() - milliseconds(300)), "wheel",
                    std::vector<double>{0.5}}},
           Interpolation::kStep);
  EXPECT_TRUE(immediate.empty());
  RunTo(kT0 + milliseconds(520));
  ASSERT_TRUE(replies_.contains(3));
  EXPECT_EQ(replies_[3].signal, Signal::kInterrupted) << replies_[3].message;
  EXPECT_THAT(replies_[3].message, HasSubstr("expired"));
  const double held = Position(1);
  RunTo(kT0 + milliseconds(900));
  EXPECT_DOUBLE_EQ(Position(1), held) << "the trajectory the expired speed replaced ran on";
  for (CommandId id : {1, 2}) {
    ASSERT_TRUE(replies_.contains(id)) << "waypoint " << id << " unanswered";
    EXPECT_EQ(replies_[id].signal, Signal::kInterrupted) << replies_[id].message;
    EXPECT_THAT(replies_[id].message, HasSubstr("stopped: JOINT_SPEED 3 expired"));
  }
}

// The watchdog on trajectories: no test named in docs/safety.md covered a
// vanished client's joint or frame trajectory (the watchdog matrix sends step
// commands; only the base's ramp has a test). Both must end, the joints hold
// where the stop found them. (Their waypoints' answers go nowhere: a vanished
// session's replies are dropped.)
using WatchdogTrajectoryTest = HostileNumbersTest;

TEST_F(WatchdogTrajectoryTest, AVanishedClientsJointAndFrameTrajectoriesEndAndTheJointsHold) {
  const Eigen::Quaterniond turned(Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ()));
  const std::vector<double> pose{0, 0, 0, turned.w(), turned.x(), turned.y(), turned.z()};
  for (const bool frame : {false, true}) {
    SCOPED_TRACE(frame ? "a frame trajectory" : "a joint trajectory");
    const TimePoint t0 = clock_.Now();
    const std::vector<Command> waypoints =
        frame ? std::vector<Command>{Command{11, CommandType::kFrameSetPoint, StartTime::At(t0 + seconds(6)),
                                             "tool", pose}}
              : std::vector<Command>{Waypoint(1, "wheel", t0 + seconds(3), {3.0}),
                                     Waypoint(2, "wheel", t0 + seconds(6), {6.0})};
    EXPECT_TRUE(Send(waypoints, Interpolation::kCubic).empty());
    RunTo(t0 + milliseconds(2500));  // the session has been silent for 2.5 s: past the 2 s timeout
    const int dof = frame ? 0 : 1;
    const double before = Position(dof);
    ASSERT_GT(std::abs(before), 0.01) << "the trajectory moves the joint";
    ASSERT_EQ(sessions_.Expire(clock_.Now()).size(), 1u);
    RunTo(t0 + milliseconds(2520));
    const double held = Position(dof);
    RunTo(t0 + milliseconds(4000));
    EXPECT_DOUBLE_EQ(Position(dof), held) << "the vanished client's trajectory ran on";
  }
}

// Bounds (docs/safety.md): "the robot's queue is bounded", a client may keep
// at most --max-queue items waiting. A waypoint was counted only until the
// RobotDaemon handed it to its TrajectoryTracker (RobotDaemon::queued counted
// the scheduler and arrived_waypoints_): the tracker's pending waypoints (and
// the Trajectory's knots) were counted nowhere, so a client sending waypoints
// ever further ahead (up to --max-future, 1 h) between two control periods
// grew the server's memory without bound (200k waypoints: +64 MiB of RSS).
class SmallQueueTest : public HostileNumbersTest {
 protected:
  SmallQueueTest() : HostileNumbersTest(SessionOptions{.max_queue = 50}) {}
  // 40 packages of 50 timed commands, each ever further ahead, one control
  // period apart (the planners take them in between); how many were accepted.
  std::size_t Flood(const std::function<Command(CommandId, TimePoint)>& make) {
    std::size_t accepted = 0;
    CommandId id = 0;
    for (int package = 0; package < 40; ++package) {
      std::vector<Command> commands;
      for (int k = 0; k < 50; ++k, ++id)
        commands.push_back(make(id + 1, kT0 + seconds(10) + milliseconds(id)));
      accepted += commands.size() - Send(commands, Interpolation::kLinear).size();
      RunTo(clock_.Now() + milliseconds(10));
    }
    return accepted;
  }
};

TEST_F(SmallQueueTest, WaypointsWaitingInTheTrackerCountAgainstTheClientsQueueBound) {
  const std::size_t accepted =
      Flood([](CommandId id, TimePoint at) { return Waypoint(id, "elbow", at, {0.001 * (id % 100)}); });
  EXPECT_LE(accepted, 50u) << "waypoints of one client waiting on the robot, beyond --max-queue 50";
}

// The same for the base's speed ramp: SETSPEED frames of interpolated
// packages waited in SpeedRamp::pending_, counted nowhere.
TEST_F(SmallQueueTest, SpeedFramesWaitingInTheRampCountAgainstTheClientsQueueBound) {
  const std::size_t accepted = Flood([](CommandId id, TimePoint at) {
    return Command{id, CommandType::kSetSpeed, StartTime::At(at), "",
                   std::vector<double>{0.001 * (id % 100), 0}};
  });
  EXPECT_LE(accepted, 50u) << "SETSPEED frames of one client waiting on the robot, beyond --max-queue 50";
}

// "A STOP always runs, however late" (docs/safety.md, Deadlines). Admission
// refused any start time more than --max-future (1 h) in the past with ERROR
// ("is the client's clock synchronised?"), a STOP's too, before the deadline
// rule that exempts it was reached: a STOP from a client whose clock was wrong
// by more than an hour was refused and the robot moved on.
TEST_F(HostileNumbersTest, AStopDueLongAgoStillRuns) {
  EXPECT_TRUE(
      Send({Command{1, CommandType::kJointSpeed, StartTime::Now(), "wheel", std::vector<double>{0.5}}},
           Interpolation::kStep)
          .empty());
  RunTo(kT0 + milliseconds(200));
  ASSERT_GT(Position(1), 0.05) << "the wheel turns";
  const std::map<CommandId, Reply> immediate =
      Send({Command{2, CommandType::kStop, StartTime::At(clock_.Now() - std::chrono::hours(2)), "", {}}},
           Interpolation::kStep);
  EXPECT_FALSE(immediate.contains(2)) << immediate.at(2).message;
  RunTo(kT0 + milliseconds(220));
  const double stopped = Position(1);
  RunTo(kT0 + milliseconds(500));
  EXPECT_DOUBLE_EQ(Position(1), stopped) << "the wheel still turns after the STOP";
}

// The same promise against the queue bound: a client whose queue is full
// (here 50 timed set-points 10 s ahead) had its STOP refused "command not
// queued", and the wheel turned on.
TEST_F(SmallQueueTest, AStopDueNowRunsWhenTheClientsQueueIsFull) {
  EXPECT_TRUE(
      Send({Command{1, CommandType::kJointSpeed, StartTime::Now(), "wheel", std::vector<double>{0.5}}},
           Interpolation::kStep)
          .empty());
  std::vector<Command> ahead;
  for (CommandId id = 2; id < 2 + 60; ++id)
    ahead.push_back(Command{id, CommandType::kJointSetPoint,
                            StartTime::At(kT0 + seconds(10) + milliseconds(id)), "elbow",
                            std::vector<double>{0.1}});
  const std::map<CommandId, Reply> refused = Send(ahead, Interpolation::kStep);
  ASSERT_FALSE(refused.empty()) << "the queue never filled";
  ASSERT_NE(refused.begin()->second.message.find("--max-queue"), std::string::npos)
      << refused.begin()->second.message;
  RunTo(kT0 + milliseconds(200));
  ASSERT_GT(Position(1), 0.05) << "the wheel turns";
  CommandId stop = 100;
  for (const StartTime start : {StartTime::Now(), StartTime::At(clock_.Now())}) {
    const std::map<CommandId, Reply> immediate =
        Send({Command{stop, CommandType::kStop, start, "", {}}}, Interpolation::kStep);
    EXPECT_FALSE(immediate.contains(stop)) << immediate.at(stop).message;
    ++stop;
  }
  RunTo(clock_.Now() + milliseconds(20));
  const double stopped = Position(1);
  RunTo(clock_.Now() + milliseconds(300));
  EXPECT_DOUBLE_EQ(Position(1), stopped) << "the wheel still turns after the STOP";
}

}  // namespace
}  // namespace robotalk
