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
#include <map>
#include <memory>
#include <vector>

#include "support/test_clients.h"

namespace robotalk {
namespace {

using std::chrono::milliseconds;
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

class HostileNumbersTest : public ::testing::Test {
 protected:
  HostileNumbersTest()
      : daemon_("arm", "kinematic", MakeDriver(), clock_, RobotDaemonOptions{.precise_timing = false}),
        sessions_(daemon_, ConfigHash(daemon_.model()), SessionOptions{}) {
    daemon_.Preallocate(out_);
  }

  // One interpolated package of `commands`, all due at kT0 + `ahead`.
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

Command Waypoint(CommandId id, const std::string& joint, TimePoint at, std::vector<double> values,
                 std::vector<double> velocities = {}) {
  Command c{id, CommandType::kJointSetPoint, StartTime::At(at), joint, std::move(values)};
  c.velocities = std::move(velocities);
  return c;
}

// DEFECT: a waypoint's velocity is only checked finite. 1e308 rad/s 0.1 s
// ahead overflows the cubic's coefficients (trajectory.cpp, Rebuild: -inf and
// +inf), the plan's sample is NaN, TrajectoryTracker::Limit passes NaN on
// (std::clamp of NaN is NaN) and the kinematic driver's joint becomes NaN:
// the RobotDaemon halts the robot in panic for every client ("non-finite
// state"), where the promise is a clear error naming the field to the sender.
TEST_F(HostileNumbersTest, DISABLED_AWaypointWhoseVelocityOverflowsThePlanIsRefusedAndTheRobotServesOn) {
  const Command w = Waypoint(1, "elbow", kT0 + milliseconds(100), {0.5}, {1e308});
  ASSERT_FALSE(CheckCommand(daemon_.model(), w)) << "CheckCommand accepts it: it is finite";
  const std::map<CommandId, Reply> immediate = Send({w}, Interpolation::kCubic);
  RunTo(kT0 + milliseconds(500));
  EXPECT_FALSE(daemon_.in_panic()) << "one client's waypoint halted the robot: " << daemon_.fault();
  EXPECT_TRUE(std::isfinite(Position(0))) << "a non-finite reference reached the driver";
  const Reply& answer = immediate.contains(1) ? immediate.at(1) : replies_[1];
  EXPECT_EQ(answer.signal, Signal::kError) << answer.message;
  EXPECT_THAT(answer.message, HasSubstr("velocit"));
}

// DEFECT: the same through a frame waypoint's position (a pose's x, y, z are
// only checked finite): 1e308 m ahead makes the cubic's sample NaN, the
// tracker hands NaN to the inverse kinematics, which throws, and the
// RobotDaemon reports a SERVER FAULT and halts the robot in panic.
TEST_F(HostileNumbersTest, DISABLED_AFrameWaypointAHugeDistanceAwayIsRefusedAndTheRobotServesOn) {
  Command w{1, CommandType::kFrameSetPoint, StartTime::At(kT0 + milliseconds(100)), "tool",
            std::vector<double>{1e308, 0, 0, 1, 0, 0, 0}};
  ASSERT_FALSE(CheckCommand(daemon_.model(), w)) << "CheckCommand accepts it: it is finite";
  const std::map<CommandId, Reply> immediate = Send({w}, Interpolation::kCubic);
  RunTo(kT0 + milliseconds(500));
  EXPECT_FALSE(daemon_.in_panic()) << "one client's waypoint halted the robot: " << daemon_.fault();
  const Reply& answer = immediate.contains(1) ? immediate.at(1) : replies_[1];
  EXPECT_NE(answer.signal, Signal::kSuccess) << answer.message;
}

// DEFECT: a continuous joint with no <limit> has no position or velocity
// bound; two finite waypoints ±1.7e308 rad make their difference overflow and
// the plan NaN: the robot halts in panic as above.
TEST_F(HostileNumbersTest, DISABLED_WaypointsWhoseDifferenceOverflowsAreRefusedAndTheRobotServesOn) {
  const std::map<CommandId, Reply> immediate =
      Send({Waypoint(1, "wheel", kT0 + milliseconds(100), {1.7e308}),
            Waypoint(2, "wheel", kT0 + milliseconds(200), {-1.7e308})},
           Interpolation::kLinear);
  RunTo(kT0 + milliseconds(500));
  EXPECT_FALSE(daemon_.in_panic()) << "one client's waypoints halted the robot: " << daemon_.fault();
  EXPECT_TRUE(std::isfinite(Position(1)));
}

// DEFECT: the same in the base speed ramp (speed_ramp.cpp, Approach): two
// SETSPEED frames of a linear package, +1.7e308 and -1.7e308 m/s, make the
// plan's segment -inf; the clipped reference is ref + 0 * -inf = NaN, and
// driver_support::ShapeBaseSpeed passes NaN on (NaN > max_v is false): the
// base pose becomes NaN and the robot halts in panic.
TEST_F(HostileNumbersTest, DISABLED_SpeedFramesWhoseDifferenceOverflowsAreRefusedAndTheRobotServesOn) {
  const auto speed = [](CommandId id, TimePoint at, double v) {
    return Command{id, CommandType::kSetSpeed, StartTime::At(at), "", std::vector<double>{v, 0}};
  };
  Send({speed(1, kT0 + milliseconds(100), 1.7e308), speed(2, kT0 + milliseconds(200), -1.7e308)},
       Interpolation::kLinear);
  RunTo(kT0 + milliseconds(500));
  EXPECT_FALSE(daemon_.in_panic()) << "one client's frames halted the robot: " << daemon_.fault();
}

}  // namespace
}  // namespace robotalk
