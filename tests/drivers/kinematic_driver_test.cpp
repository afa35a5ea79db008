#include "kinematic_driver.h"

#include "robotalk/error.h"
#include "robotalk/kinematics.h"
#include "robotalk/urdf_import.h"
#include "test_paths.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <functional>
#include <initializer_list>
#include <new>
#include <numbers>

#include "support/allocation_counter.h"  // g_allocations

namespace robotalk {
namespace {

using std::chrono::milliseconds;
using std::chrono::seconds;
using ::testing::HasSubstr;
constexpr double kPi = std::numbers::pi;
constexpr auto kPeriod = milliseconds(10);

DriverCommand Cmd(CommandId id, CommandType type, int target, std::initializer_list<double> values) {
  DriverCommand c{.id = id, .type = type, .target = target, .num_values = static_cast<int>(values.size())};
  int k = 0;
  for (double v : values) c.values[static_cast<size_t>(k++)] = v;
  return c;
}

RobotModel Pioneer(bool merge = false) {
  return LoadUrdfFile(testing::ProjectModel("pioneer2dx_pantilt.urdf"), {.merge_massless_chains = merge})
      .model;
}

Dof Revolute(double lower, double upper, double velocity) {
  return Dof{.type = DofType::kRevolute,
             .axis = Eigen::Vector3d::UnitZ(),
             .limits = {.lower = lower, .upper = upper, .velocity = velocity}};
}

// A planar 2-link arm (0.5 m + 0.4 m) about z, tool frame at the tip; the
// elbow may only bend to one side. `base` sets the root's base type.
RobotModel TwoLinkArm(BaseType base = BaseType::kFixed, const Pose& root_pose = {}) {
  RobotModelBuilder b("arm");
  b.AddLink({.name = "base"}).AddLink({.name = "upper"}).AddLink({.name = "lower"});
  b.AddJoint(Joint{.name = "shoulder", .dofs = {Revolute(-kPi, kPi, 1.0)}, .servo_types = ServoTypes::All()},
             "base", "upper");
  b.AddJoint(Joint{.name = "elbow",
                   .inboard = {0.5, 0, 0},
                   .dofs = {Revolute(0.0, 2.5, 1.0)},
                   .servo_types = ServoTypes::All()},
             "upper", "lower");
  b.AddControlFrame(
      ControlFrame{
          .name = "tool", .pose_in_link = {.translation = {0.4, 0, 0}}, .servo_types = ServoType::kSetPoint},
      "lower");
  b.SetRoot("base", root_pose, base);
  return b.Build();
}

// Drives a driver with plain TimePoints, one period at a time.
class Sim {
 public:
  explicit Sim(Driver& d) : driver_(d) { driver_.Update(now_, completed); }
  DriverResult Run(const DriverCommand& c) { return driver_.Execute(c, now_, completed); }
  void Stop() { driver_.Stop(now_, completed); }
  void Advance(Duration d) {
    for (const TimePoint end = now_ + d; now_ < end;) {
      now_ += kPeriod;
      driver_.Update(now_, completed);
    }
  }
  // Steps until a completion arrives or `limit` passes; returns the time taken.
  Duration RunUntilCompletion(Duration limit) {
    const TimePoint start = now_;
    while (completed.empty() && now_ - start < limit) Advance(kPeriod);
    return now_ - start;
  }
  RobotState State() const {
    RobotState s;
    const RobotModel& m = driver_.model();
    s.position.resize(m.num_dofs());
    s.velocity.resize(m.num_dofs());
    s.effort.resize(m.num_dofs());
    s.root_poses.resize(m.roots().size());
    driver_.ReadState(s);
    return s;
  }
  double Yaw() const {
    const Eigen::Matrix3d r = State().root_poses[0].rotation.toRotationMatrix();
    return std::atan2(r(1, 0), r(0, 0));
  }
  Eigen::Vector3d BasePosition() const { return State().root_poses[0].translation; }

  std::vector<Completion> completed;

 private:
  Driver& driver_;
  TimePoint now_{seconds(100)};
};

// ---------------------------------------------------------------- joints

TEST(KinematicDriver, SetPointReachesItsTargetAtTheVelocityLimit) {
  KinematicDriver d(Pioneer());
  Sim sim(d);
  const int pan = d.model().JointIndex("pan");
  const int dof = d.model().dof_offset(pan);
  EXPECT_EQ(sim.Run(Cmd(1, CommandType::kJointSetPoint, pan, {1.3})).signal, Signal::kSuccess);
  sim.Advance(milliseconds(250));  // 2.6 rad/s for 0.25 s
  RobotState s = sim.State();
  EXPECT_NEAR(s.position[dof], 0.65, 1e-9);
  EXPECT_NEAR(s.velocity[dof], 2.6, 1e-9);
  EXPECT_TRUE(s.moving);
  sim.Advance(milliseconds(260));
  s = sim.State();
  EXPECT_NEAR(s.position[dof], 1.3, 1e-12);
  sim.Advance(kPeriod);
  s = sim.State();
  EXPECT_EQ(s.velocity[dof], 0.0);
  EXPECT_FALSE(s.moving);
}

TEST(KinematicDriver, FirstUpdateOnlySetsTheTimeBase) {
  KinematicDriver d(Pioneer());
  const int pan = d.model().JointIndex("pan");
  std::vector<Completion> done;
  // No Update yet: Execute at t sets the time base; a first Update much later
  // integrates from there.
  const TimePoint t0(seconds(5));
  d.Execute(Cmd(1, CommandType::kJointSetPoint, pan, {1.0}), t0, done);
  d.Update(t0 + milliseconds(100), done);
  RobotState s{.position = Eigen::VectorXd::Zero(d.model().num_dofs())};
  d.ReadState(s);
  EXPECT_NEAR(s.position[d.model().dof_offset(pan)], 0.26, 1e-9);

  KinematicDriver fresh(Pioneer());
  fresh.Update(TimePoint(seconds(7)), done);  // first call: no motion
  fresh.ReadState(s);
  EXPECT_TRUE(s.position.isZero());
}

TEST(KinematicDriver, ClampedSetPointAnswersModifiedAndStopsAtTheLimit) {
  KinematicDriver d(Pioneer());
  Sim sim(d);
  const int tilt = d.model().JointIndex("tilt");
  const DriverResult r = sim.Run(Cmd(1, CommandType::kJointSetPoint, tilt, {1.0}));
  EXPECT_EQ(r.signal, Signal::kModified);
  EXPECT_THAT(r.message, HasSubstr("'tilt'"));
  EXPECT_THAT(r.message, HasSubstr("dof 0"));
  EXPECT_THAT(r.message, HasSubstr("clamped to the upper limit 0.5411"));
  sim.Advance(seconds(1));
  EXPECT_NEAR(sim.State().position[d.model().dof_offset(tilt)], 0.5411, 1e-12);
}

TEST(KinematicDriver, SpeedCommandMovesAtConstantVelocityAndHoldsAtThePositionLimit) {
  KinematicDriver d(Pioneer());
  Sim sim(d);
  const int pan = d.model().JointIndex("pan");
  const int dof = d.model().dof_offset(pan);
  EXPECT_EQ(sim.Run(Cmd(1, CommandType::kJointSpeed, pan, {1.0})).signal, Signal::kSuccess);
  sim.Advance(seconds(1));
  EXPECT_NEAR(sim.State().position[dof], 1.0, 1e-9);
  EXPECT_NEAR(sim.State().velocity[dof], 1.0, 1e-9);
  sim.Advance(seconds(3));
  EXPECT_DOUBLE_EQ(sim.State().position[dof], 2.775);
  EXPECT_EQ(sim.State().velocity[dof], 0.0);
  EXPECT_FALSE(sim.State().moving);
}

TEST(KinematicDriver, SpeedAboveTheVelocityLimitIsClampedWithModified) {
  KinematicDriver d(Pioneer());
  Sim sim(d);
  const int pan = d.model().JointIndex("pan");
  const DriverResult r = sim.Run(Cmd(1, CommandType::kJointSpeed, pan, {-5.0}));
  EXPECT_EQ(r.signal, Signal::kModified);
  EXPECT_THAT(r.message, HasSubstr("clamped to the velocity limit 2.6"));
  sim.Advance(milliseconds(100));
  EXPECT_NEAR(sim.State().velocity[d.model().dof_offset(pan)], -2.6, 1e-9);
}

TEST(KinematicDriver, JointWithoutVelocityLimitMovesAtTheDefaultVelocity) {
  RobotModelBuilder b("slider");
  b.AddLink({.name = "a"}).AddLink({.name = "b"});
  b.AddJoint(Joint{.name = "x",
                   .dofs = {Dof{.type = DofType::kPrismatic, .axis = Eigen::Vector3d::UnitX()}},
                   .servo_types = ServoTypes::All()},
             "a", "b");
  KinematicDriver d(b.Build(), {.default_velocity = 0.25});
  Sim sim(d);
  sim.Run(Cmd(1, CommandType::kJointSetPoint, 0, {10.0}));
  sim.Advance(seconds(2));
  EXPECT_NEAR(sim.State().position[0], 0.5, 1e-9);
}

TEST(KinematicDriver, JointForceAnswersNaBecauseThereAreNoDynamics) {
  KinematicDriver d(TwoLinkArm());
  Sim sim(d);
  const DriverResult r = sim.Run(Cmd(1, CommandType::kJointForce, 0, {1.0}));
  EXPECT_EQ(r.signal, Signal::kNa);
  EXPECT_THAT(r.message, HasSubstr("simulates no dynamics"));
}

TEST(KinematicDriver, MimicJointFollowsItsLeader) {
  RobotModelBuilder b("gripper");
  b.AddLink({.name = "palm"}).AddLink({.name = "left"}).AddLink({.name = "right"});
  b.AddJoint(Joint{.name = "l", .dofs = {Revolute(-1, 1, 1.0)}, .servo_types = ServoTypes::All()}, "palm",
             "left");
  b.AddJoint(Joint{.name = "r", .dofs = {Revolute(-1, 1, 1.0)}}, "palm", "right");
  b.SetMimic("r", "l", -1.0, 0.0);
  KinematicDriver d(b.Build());
  Sim sim(d);
  sim.Run(Cmd(1, CommandType::kJointSetPoint, 0, {0.5}));
  sim.Advance(milliseconds(200));
  RobotState s = sim.State();
  EXPECT_NEAR(s.position[1], -0.2, 1e-9);
  EXPECT_NEAR(s.velocity[1], -1.0, 1e-9);
  sim.Advance(seconds(1));
  s = sim.State();
  EXPECT_NEAR(s.position[1], -0.5, 1e-12);
  EXPECT_FALSE(s.moving);
  // A command to the follower never reaches a driver: the server refuses it (driver.h).
  const Command to_follower{2, CommandType::kJointSetPoint, std::nullopt, "r", {0.1}};
  const auto refusal = CheckCommand(d.model(), to_follower);
  ASSERT_TRUE(refusal);
  EXPECT_THAT(refusal->message, HasSubstr("mimic"));
  EXPECT_EQ(refusal->signal, Signal::kNa);
}

// ---------------------------------------------------------------- base

TEST(KinematicDriver, SetSpeedTracesAnArcOfRadiusVOverOmega) {
  KinematicDriver d(Pioneer());
  Sim sim(d);
  EXPECT_EQ(sim.Run(Cmd(1, CommandType::kSetSpeed, -1, {0.5, 1.0})).signal, Signal::kSuccess);
  // Radius 0.5 m about (0, 0.5): every sample stays on that circle.
  for (int i = 0; i < 10; ++i) {
    sim.Advance(milliseconds(300));
    const Eigen::Vector3d p = sim.BasePosition();
    EXPECT_NEAR(std::hypot(p.x(), p.y() - 0.5), 0.5, 1e-9);
  }
  const RobotState s = sim.State();
  EXPECT_DOUBLE_EQ(s.base_v, 0.5);
  EXPECT_DOUBLE_EQ(s.base_omega, 1.0);
  EXPECT_TRUE(s.moving);
  // After pi seconds in all: half a circle, at (0, 1) facing -x. (3.0 s so far.)
  sim.Advance(milliseconds(140));
  const Eigen::Vector3d p = sim.BasePosition();
  const double t = 3.14;
  EXPECT_NEAR(p.x(), 0.5 * std::sin(t), 1e-9);
  EXPECT_NEAR(p.y(), 0.5 * (1 - std::cos(t)), 1e-9);
  EXPECT_NEAR(sim.Yaw(), t, 1e-9);
}

TEST(KinematicDriver, SetSpeedAboveTheBaseLimitsIsClampedWithModified) {
  KinematicDriver d(Pioneer(), {.base_max_v = 0.7, .base_max_omega = 2.0});
  Sim sim(d);
  const DriverResult r = sim.Run(Cmd(1, CommandType::kSetSpeed, -1, {1.5, -3.0}));
  EXPECT_EQ(r.signal, Signal::kModified);
  EXPECT_THAT(r.message, HasSubstr("clamped to base_max_v 0.7"));
  EXPECT_THAT(r.message, HasSubstr("clamped to base_max_omega 2"));
  sim.Advance(kPeriod);
  EXPECT_DOUBLE_EQ(sim.State().base_v, 0.7);
  EXPECT_DOUBLE_EQ(sim.State().base_omega, -2.0);
}

TEST(KinematicDriver, LateralSpeedOnADifferentialBaseIsDroppedWithModified) {
  KinematicDriver d(Pioneer());
  Sim sim(d);
  const DriverResult r = sim.Run(Cmd(1, CommandType::kSetSpeed, -1, {0.3, 0.2, 0.0}));
  EXPECT_EQ(r.signal, Signal::kModified);
  EXPECT_THAT(r.message, HasSubstr("lateral speed"));
  EXPECT_THAT(r.message, HasSubstr("differential"));
  sim.Advance(seconds(1));
  EXPECT_NEAR(sim.BasePosition().x(), 0.3, 1e-9);
  EXPECT_NEAR(sim.BasePosition().y(), 0.0, 1e-12);
}

TEST(KinematicDriver, HolonomicBaseAcceptsLateralSpeed) {
  KinematicDriver d(TwoLinkArm(BaseType::kHolonomic));
  Sim sim(d);
  EXPECT_EQ(sim.Run(Cmd(1, CommandType::kSetSpeed, -1, {0.3, 0.2, 0.0})).signal, Signal::kSuccess);
  sim.Advance(seconds(1));
  EXPECT_NEAR(sim.BasePosition().x(), 0.3, 1e-9);
  EXPECT_NEAR(sim.BasePosition().y(), 0.2, 1e-9);
}

TEST(KinematicDriver, RootPoseComposesThePlanarPoseWithTheModelRootPose) {
  // Root 0.2 m up, rolled by 0.1 rad and yawed by pi/2 in the model.
  const Eigen::Quaterniond yaw(Eigen::AngleAxisd(kPi / 2, Eigen::Vector3d::UnitZ()));
  const Eigen::Quaterniond roll(Eigen::AngleAxisd(0.1, Eigen::Vector3d::UnitX()));
  KinematicDriver d(
      TwoLinkArm(BaseType::kDifferential, {.translation = {1, 2, 0.2}, .rotation = yaw * roll}));
  Sim sim(d);
  sim.Run(Cmd(1, CommandType::kSetSpeed, -1, {0.5, 0.0}));
  sim.Advance(seconds(1));  // drives along world +y
  const Pose p = sim.State().root_poses[0];
  EXPECT_NEAR(p.translation.x(), 1.0, 1e-9);
  EXPECT_NEAR(p.translation.y(), 2.5, 1e-9);
  EXPECT_NEAR(p.translation.z(), 0.2, 1e-12);
  EXPECT_TRUE(p.rotation.isApprox(yaw * roll, 1e-12));
}

TEST(KinematicDriver, GotoReachesItsGoalThenCompletesWithSuccess) {
  KinematicDriver d(Pioneer());
  Sim sim(d);
  const DriverResult r = sim.Run(Cmd(7, CommandType::kGoto, -1, {1.0, 1.0, kPi / 2}));
  EXPECT_TRUE(r.in_progress);
  EXPECT_TRUE(sim.State().moving);
  const Duration took = sim.RunUntilCompletion(seconds(20));
  ASSERT_EQ(sim.completed.size(), 1u);
  EXPECT_EQ(sim.completed[0].id, 7);
  EXPECT_EQ(sim.completed[0].signal, Signal::kSuccess);
  const Eigen::Vector3d p = sim.BasePosition();
  EXPECT_LE(std::hypot(p.x() - 1.0, p.y() - 1.0), 0.01);
  EXPECT_LE(std::abs(sim.Yaw() - kPi / 2), 0.01);
  // Turn pi/4 at 2 rad/s, drive sqrt(2) m at 0.7 m/s, turn pi/4: about 2.8 s.
  EXPECT_LT(ToSeconds(took), 3.2);
  EXPECT_FALSE(sim.State().moving);
  EXPECT_EQ(sim.State().base_v, 0.0);
}

TEST(KinematicDriver, GotoBehindTheRobotAndToTheCurrentPoseBothComplete) {
  KinematicDriver d(Pioneer());
  Sim sim(d);
  EXPECT_EQ(sim.Run(Cmd(1, CommandType::kGoto, -1, {0.0, 0.0, 0.0})).signal, Signal::kSuccess);
  EXPECT_TRUE(sim.Run(Cmd(2, CommandType::kGoto, -1, {-2.0, 0.5, -3.0})).in_progress);
  sim.RunUntilCompletion(seconds(20));
  ASSERT_EQ(sim.completed.size(), 1u);
  EXPECT_EQ(sim.completed[0].signal, Signal::kSuccess);
  EXPECT_LE(std::hypot(sim.BasePosition().x() + 2.0, sim.BasePosition().y() - 0.5), 0.01);
  EXPECT_LE(std::abs(std::remainder(sim.Yaw() + 3.0, 2 * kPi)), 0.01);
}

TEST(KinematicDriver, GotoOrSetSpeedDuringAGotoAnswersBusyButJointsStillMove) {
  KinematicDriver d(Pioneer());
  Sim sim(d);
  EXPECT_TRUE(sim.Run(Cmd(1, CommandType::kGoto, -1, {2.0, 0.0, 0.0})).in_progress);
  sim.Advance(milliseconds(500));
  DriverResult r = sim.Run(Cmd(2, CommandType::kGoto, -1, {0.0, 1.0, 0.0}));
  EXPECT_EQ(r.signal, Signal::kBusy);
  EXPECT_FALSE(r.in_progress);
  EXPECT_THAT(r.message, HasSubstr("GOTO in progress"));
  r = sim.Run(Cmd(3, CommandType::kSetSpeed, -1, {0.1, 0.0}));
  EXPECT_EQ(r.signal, Signal::kBusy);
  EXPECT_THAT(r.message, HasSubstr("GOTO in progress"));
  EXPECT_EQ(sim.Run(Cmd(4, CommandType::kJointSetPoint, d.model().JointIndex("pan"), {0.5})).signal,
            Signal::kSuccess);
  sim.RunUntilCompletion(seconds(20));
  ASSERT_EQ(sim.completed.size(), 1u);
  EXPECT_EQ(sim.completed[0].id, 1);
  EXPECT_NEAR(sim.State().position[d.model().dof_offset(d.model().JointIndex("pan"))], 0.5, 1e-12);
}

TEST(KinematicDriver, StopInterruptsAGotoAndFreezesEveryMotion) {
  KinematicDriver d(Pioneer());
  Sim sim(d);
  const int pan = d.model().JointIndex("pan");
  const int wheel = d.model().JointIndex("left_wheel_joint");
  sim.Run(Cmd(1, CommandType::kGoto, -1, {2.0, 0.0, 0.0}));
  sim.Run(Cmd(2, CommandType::kJointSetPoint, pan, {2.0}));
  sim.Run(Cmd(3, CommandType::kJointSpeed, wheel, {5.0}));
  sim.Advance(milliseconds(500));
  sim.Stop();
  ASSERT_EQ(sim.completed.size(), 1u);
  EXPECT_EQ(sim.completed[0].id, 1);
  EXPECT_EQ(sim.completed[0].signal, Signal::kInterrupted);
  EXPECT_THAT(sim.completed[0].message, HasSubstr("STOP"));
  const RobotState before = sim.State();
  EXPECT_FALSE(before.moving);
  sim.Advance(seconds(1));
  const RobotState after = sim.State();
  EXPECT_EQ(after.position, before.position);
  EXPECT_TRUE(after.root_poses[0] == before.root_poses[0]);
  EXPECT_TRUE(after.velocity.isZero());
  // A new GOTO is accepted after the STOP.
  EXPECT_TRUE(sim.Run(Cmd(5, CommandType::kGoto, -1, {0.0, 0.0, 0.0})).in_progress);
}

TEST(KinematicDriver, HaltInterruptsAndHoldsTheRobotWhereItIsAfterResume) {
  KinematicDriver d(Pioneer());
  Sim sim(d);
  const int pan = d.model().JointIndex("pan");
  sim.Run(Cmd(1, CommandType::kGoto, -1, {2.0, 0.0, 0.0}));
  sim.Run(Cmd(2, CommandType::kJointSpeed, pan, {1.0}));
  sim.Advance(milliseconds(300));
  std::vector<Completion> interrupted;
  d.Halt(interrupted);
  ASSERT_EQ(interrupted.size(), 1u);
  EXPECT_EQ(interrupted[0].id, 1);
  EXPECT_EQ(interrupted[0].signal, Signal::kInterrupted);
  const RobotState halted = sim.State();
  EXPECT_FALSE(halted.moving);
  sim.Advance(seconds(1));
  EXPECT_EQ(sim.State().position, halted.position);
  d.Resume();
  sim.Advance(seconds(1));
  EXPECT_EQ(sim.State().position, halted.position);  // stays where it is
  EXPECT_EQ(sim.Run(Cmd(5, CommandType::kJointSetPoint, pan, {0.0})).signal, Signal::kSuccess);
}

TEST(KinematicDriver, BaseCommandsOnAFixedBaseAnswerNa) {
  KinematicDriver d(TwoLinkArm());
  Sim sim(d);
  EXPECT_EQ(sim.Run(Cmd(1, CommandType::kGoto, -1, {1, 0, 0})).signal, Signal::kNa);
  const DriverResult r = sim.Run(Cmd(2, CommandType::kSetSpeed, -1, {0.1, 0}));
  EXPECT_EQ(r.signal, Signal::kNa);
  EXPECT_THAT(r.message, HasSubstr("fixed base"));
}

// ---------------------------------------------------------------- frames

Pose ToolPoseAt(const RobotModel& model, int frame, const Eigen::VectorXd& q) {
  Kinematics kin(model);
  kin.Update(q);
  return Pose::FromIsometry(kin.frame_pose(frame));
}

DriverCommand FrameCmd(CommandId id, int frame, const Pose& p) {
  const auto& t = p.translation;
  const auto& r = p.rotation;
  return Cmd(id, CommandType::kFrameSetPoint, frame, {t.x(), t.y(), t.z(), r.w(), r.x(), r.y(), r.z()});
}

TEST(KinematicDriver, FrameSetPointReachesAReachablePoseOnATwoLinkArm) {
  const RobotModel model = TwoLinkArm();
  const Pose goal = ToolPoseAt(model, 0, Eigen::Vector2d(0.7, 1.2));
  KinematicDriver d(model);
  Sim sim(d);
  const DriverResult r = sim.Run(FrameCmd(1, 0, goal));
  EXPECT_EQ(r.signal, Signal::kSuccess) << r.message;
  sim.Advance(seconds(3));
  const Pose reached = ToolPoseAt(model, 0, sim.State().position);
  EXPECT_LE((reached.translation - goal.translation).norm(), 1e-3);
  EXPECT_LE(reached.rotation.angularDistance(goal.rotation), 1e-2);
}

TEST(KinematicDriver, FrameSetPointOutOfReachAnswersModifiedWithTheResidual) {
  const RobotModel model = TwoLinkArm();
  KinematicDriver d(model);
  Sim sim(d);
  const DriverResult r = sim.Run(FrameCmd(1, 0, {.translation = {2.0, 0.0, 0.0}}));
  EXPECT_EQ(r.signal, Signal::kModified);
  EXPECT_THAT(r.message, HasSubstr("'tool'"));
  EXPECT_THAT(r.message, HasSubstr("not reachable"));
  EXPECT_THAT(r.message, HasSubstr("1.1 m"));  // stretched out, 0.9 m long
  sim.Advance(seconds(3));
  EXPECT_NEAR(ToolPoseAt(model, 0, sim.State().position).translation.x(), 0.9, 1e-3);
}

TEST(KinematicDriver, FrameSetPointIsSolvedInTheMovedBaseFrame) {
  const RobotModel model = TwoLinkArm(BaseType::kHolonomic);
  KinematicDriver d(model);
  Sim sim(d);
  sim.Run(Cmd(1, CommandType::kSetSpeed, -1, {0.0, 0.5, 0.0}));
  sim.Advance(seconds(1));
  sim.Stop();
  // In the world the base now sits at y = 0.5: ask for a pose expressed there.
  Pose goal = ToolPoseAt(model, 0, Eigen::Vector2d(0.3, 0.9));
  goal.translation.y() += 0.5;
  EXPECT_EQ(sim.Run(FrameCmd(3, 0, goal)).signal, Signal::kSuccess);
  sim.Advance(seconds(3));
  EXPECT_NEAR(sim.State().position[0], 0.3, 1e-3);
  EXPECT_NEAR(sim.State().position[1], 0.9, 1e-3);
}

TEST(KinematicDriver, FrameSetPointReachesAPoseOnTheIiwa14) {
  ROBOTALK_REQUIRE_SHARED_ROBOTS();
  const RobotModel iiwa = LoadUrdfFile(testing::SharedRobot("iiwa14.urdf")).model;
  // The URDF has no control frame: add a tool frame 10 cm beyond link 7.
  std::vector<ControlFrame> frames(iiwa.frames().begin(), iiwa.frames().end());
  const int last = iiwa.LinkIndex("iiwa_link_7");
  const int tool = static_cast<int>(frames.size());
  frames.push_back(ControlFrame{.name = "tool",
                                .parent_link = last,
                                .pose_in_link = {.translation = {0, 0, 0.1}},
                                .servo_types = ServoType::kSetPoint});
  std::vector<Link> links(iiwa.links().begin(), iiwa.links().end());
  std::vector<Joint> joints(iiwa.joints().begin(), iiwa.joints().end());
  std::vector<RootLink> roots(iiwa.roots().begin(), iiwa.roots().end());
  const RobotModel model("iiwa14_tool", links, joints, frames, roots);

  Eigen::VectorXd q_goal(model.num_dofs());
  q_goal << 0.4, 0.6, -0.3, -1.2, 0.5, 0.8, -0.2;
  const Pose goal = ToolPoseAt(model, tool, q_goal);
  KinematicDriver d(model);
  Sim sim(d);
  const DriverResult r = sim.Run(FrameCmd(1, tool, goal));
  EXPECT_EQ(r.signal, Signal::kSuccess) << r.message;
  sim.Advance(seconds(5));
  const Pose reached = ToolPoseAt(model, tool, sim.State().position);
  EXPECT_LE((reached.translation - goal.translation).norm(), 1e-3);
  EXPECT_LE(reached.rotation.angularDistance(goal.rotation), 1e-2);
  ASSERT_EQ(model.num_dofs(), 7);
  for (int j = 0; j < static_cast<int>(model.joints().size()); ++j) {
    for (size_t k = 0; k < model.joint(j).dofs.size(); ++k) {
      const double q = sim.State().position[model.dof_offset(j) + static_cast<int>(k)];
      EXPECT_GE(q, model.joint(j).dofs[k].limits.lower);
      EXPECT_LE(q, model.joint(j).dofs[k].limits.upper);
    }
  }
  // Two metres away is out of reach of a 1.3 m arm.
  EXPECT_EQ(sim.Run(FrameCmd(2, tool, {.translation = {2.0, 0.0, 1.0}})).signal, Signal::kModified);
}

// ---------------------------------------------------------------- real-time path

TEST(KinematicDriver, UpdateAndReadStateDoNotAllocate) {
  KinematicDriver d(Pioneer());
  Sim sim(d);
  sim.Run(Cmd(1, CommandType::kGoto, -1, {1.0, 1.0, 0.0}));
  sim.Run(Cmd(2, CommandType::kJointSetPoint, d.model().JointIndex("pan"), {1.0}));
  sim.completed.reserve(4);
  RobotState s = sim.State();
  const long before = g_allocations;
  sim.Advance(milliseconds(500));
  d.ReadState(s);
  EXPECT_EQ(g_allocations, before);
  EXPECT_TRUE(s.moving);
}

// ---------------------------------------------------------------- registry

TEST(KinematicDriver, RegistryCreatesTheKinematicDriverFromThePioneerUrdf) {
  DriverRegistry registry;
  RegisterKinematicDriver(registry);
  EXPECT_THAT(registry.names(), ::testing::Contains("kinematic"));
  const DriverConfig config{
      .robot_name = "pioneer",
      .urdf_path = testing::ProjectModel("pioneer2dx_pantilt.urdf"),
      .options = {{"merge_chains", "true"}, {"period_ms", "20"}, {"base_max_v", "0.5"}}};
  const std::unique_ptr<Driver> d = registry.Create("kinematic", config);
  EXPECT_EQ(d->model().name(), "pioneer");
  EXPECT_TRUE(d->model().FindJoint("pan+tilt").has_value());
  EXPECT_EQ(d->period(), milliseconds(20));
  std::vector<Completion> done;
  const DriverResult r =
      d->Execute(Cmd(1, CommandType::kSetSpeed, -1, {0.6, 0.0}), TimePoint(seconds(1)), done);
  EXPECT_EQ(r.signal, Signal::kModified);  // base_max_v = 0.5
}

TEST(KinematicDriver, RegistryRejectsUnknownOptionsAndBadValues) {
  DriverRegistry registry;
  RegisterKinematicDriver(registry);
  DriverConfig config{.robot_name = "pioneer", .urdf_path = testing::ProjectModel("pioneer2dx_pantilt.urdf")};
  config.options = {{"max_speed", "1"}};
  EXPECT_THAT([&] { registry.Create("kinematic", config); },
              ::testing::ThrowsMessage<Error>(HasSubstr("unknown option 'max_speed'")));
  config.options = {{"period_ms", "-3"}};
  EXPECT_THAT([&] { registry.Create("kinematic", config); },
              ::testing::ThrowsMessage<Error>(HasSubstr("period_ms='-3'")));
  config.options = {{"merge_chains", "maybe"}};
  EXPECT_THAT([&] { registry.Create("kinematic", config); },
              ::testing::ThrowsMessage<Error>(HasSubstr("merge_chains='maybe'")));
  config.options = {{"goto_tolerance", "1cm"}};
  EXPECT_THAT([&] { registry.Create("kinematic", config); },
              ::testing::ThrowsMessage<Error>(HasSubstr("goto_tolerance='1cm'")));
  config.options = {};
  config.urdf_path = "/nonexistent/robot.urdf";
  EXPECT_THROW(registry.Create("kinematic", config), UrdfError);
}

// The option and Validate() words every driver shares (driver_support.h:
// OptionReader::Milliseconds, CheckPeriod, CheckPositive), exactly.
TEST(KinematicDriver, BadOptionsAreNamedInTheWordsEveryDriverUses) {
  const auto error_of = [](const std::function<void()>& f) -> std::string {
    try {
      f();
    } catch (const Error& e) {
      return e.what();
    }
    return "(no error)";
  };
  EXPECT_EQ(error_of([] {
              KinematicDriverOptions::FromMap({{"period_ms", "1e-9"}});
            }),
            "kinematic driver: option period_ms='1e-9': expected a number of milliseconds > 0");
  EXPECT_EQ(error_of([] {
              KinematicDriverOptions::FromMap({{"period_ms", "0"}});
            }),
            "kinematic driver: option period_ms='0': expected a number of milliseconds > 0");
  EXPECT_EQ(KinematicDriverOptions::FromMap({{"period_ms", "2.5"}}).period, std::chrono::microseconds(2500));
  EXPECT_EQ(KinematicDriverOptions::FromMap({}).period, KinematicDriverOptions{}.period);
  EXPECT_EQ(error_of([] { KinematicDriver d(TwoLinkArm(), {.period = Duration::zero()}); }),
            "KinematicDriver: period = 0 s, expected > 0");
  EXPECT_EQ(error_of([] { KinematicDriver d(TwoLinkArm(), {.goto_tolerance = -0.5}); }),
            "KinematicDriver: goto_tolerance = -0.5, expected > 0");
}

TEST(KinematicDriver, ConstructorRejectsBadOptions) {
  EXPECT_THAT([] { KinematicDriver d(TwoLinkArm(), {.base_max_v = 0.0}); },
              ::testing::ThrowsMessage<Error>(HasSubstr("base_max_v")));
}

}  // namespace
}  // namespace robotalk
