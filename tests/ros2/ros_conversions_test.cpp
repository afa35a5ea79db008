// robotalk-ros2's pure conversions (robotalk-ros2/src/ros_conversions.h).
#include "ros_conversions.h"

#include "robotalk/error.h"
#include "robotalk/urdf_import.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>

namespace robotalk::ros2 {
namespace {

using namespace std::chrono_literals;
using ::testing::HasSubstr;

const std::string kPioneer = std::string(ROBOTALK_MODELS_DIR) + "/pioneer2dx_pantilt.urdf";

// base --(free 6-dof "float")--> body --(2-dof "wrist")--> hand, hand has a
// control frame; body --(fixed "mount")--> sensor; "grip" mimics nothing.
RobotModel Chain() {
  RobotModelBuilder b("chain");
  b.AddLink(Link{.name = "base"})
      .AddLink(Link{.name = "body", .mass = 1, .com = {0.1, 0, 0}, .inertia = Eigen::Matrix3d::Identity()});
  b.AddLink(Link{.name = "hand"}).AddLink(Link{.name = "sensor"});
  Joint wrist{.name = "wrist", .inboard = {0.3, 0, 0}, .servo_types = ServoType::kSetPoint};
  wrist.dofs = {Dof{.axis = Eigen::Vector3d::UnitZ()}, Dof{.axis = Eigen::Vector3d::UnitY()}};
  Joint lift{
      .name = "lift", .inboard = {0, 0, 0.5}, .outboard = {-0.1, 0, 0}, .servo_types = ServoType::kSetPoint};
  lift.dofs = {
      Dof{.type = DofType::kPrismatic, .axis = Eigen::Vector3d::UnitZ(), .limits = {.lower = 0, .upper = 1}}};
  Joint mount{.name = "mount", .inboard = {0, 0.2, 0}};
  b.AddJoint(lift, "base", "body").AddJoint(wrist, "body", "hand").AddJoint(mount, "body", "sensor");
  b.AddControlFrame(ControlFrame{.name = "tool", .pose_in_link = {.translation = {0.05, 0, 0}}}, "hand");
  b.SetRoot("base", Pose{.translation = {0, 0, 0.2}}, BaseType::kDifferential);
  return b.Build();
}

TrajectoryMessage Trajectory(std::vector<std::string> names, std::vector<TrajectoryMessage::Point> points) {
  return TrajectoryMessage{.joint_names = std::move(names), .points = std::move(points)};
}

std::string Refusal(const RobotModel& m, const TrajectoryMessage& t) {
  try {
    TrajectoryToCommands(m, t, TimePoint(10s), TimePoint(10s));
  } catch (const Error& e) {
    return e.what();
  }
  return "accepted";
}

TEST(RosTime, RoundTripsTheSystemClockIncludingBeforeTheEpoch) {
  for (const auto ns : {0LL, 1LL, 1764150000123456789LL, -1LL, -1500000000LL}) {
    const SystemTime t{Duration(ns)};
    const RosTime r = ToRosTime(t);
    EXPECT_LT(r.nanosec, 1000000000u);
    EXPECT_EQ(FromRosTime(r), t) << ns;
  }
  EXPECT_TRUE(ToRosTime(SystemTime{}).is_zero());
}

TEST(RosNameToken, MakesAValidRosNameOfAnyRobotName) {
  EXPECT_EQ(RosNameToken("pioneer"), "pioneer");
  EXPECT_EQ(RosNameToken("arm-2.left"), "arm_2_left");
  EXPECT_EQ(RosNameToken("2arm"), "_2arm");
}

TEST(JointStateNames, NamesEveryDofInDofOrder) {
  EXPECT_THAT(JointStateNames(Chain()), ::testing::ElementsAre("lift", "wrist/0", "wrist/1"));
}

TEST(RobotFrames, PublishesFixedJointsAndFramesAsStaticAndMovingJointsFromTheSample) {
  const RobotModel m = Chain();
  RobotFrames frames(m, "chain/", "world");
  std::vector<std::string> statics;
  for (const FrameTransform& t : frames.static_transforms()) statics.push_back(t.parent + ">" + t.child);
  EXPECT_THAT(statics, ::testing::UnorderedElementsAre("chain/body>chain/sensor", "chain/hand>chain/tool"));
  StateSample s{.robot = "chain", .positions = {0.25, 0.5, -0.2}, .base = {.x = 1, .y = 2, .theta = 0.5}};
  s.velocities = s.efforts = {0, 0, 0};
  const auto& moving = frames.Update(s);
  ASSERT_EQ(moving.size(), 3u);  // lift, wrist, the root
  Kinematics kin(m);
  kin.Update(Eigen::Vector3d(0.25, 0.5, -0.2));
  EXPECT_EQ(moving[0].parent, "chain/base");
  EXPECT_EQ(moving[0].child, "chain/body");
  EXPECT_TRUE(moving[0].pose.isApprox(kin.link_pose(0).inverse() * kin.link_pose(1), 1e-12));
  EXPECT_TRUE(moving[1].pose.isApprox(kin.link_pose(1).inverse() * kin.link_pose(2), 1e-12));
  EXPECT_EQ(moving[2].parent, "world");
  EXPECT_TRUE(moving[2].pose.translation().isApprox(Eigen::Vector3d(1, 2, 0.2)));
  EXPECT_TRUE(
      moving[2].pose.linear().isApprox(Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitZ()).toRotationMatrix()));
  s.positions.pop_back();
  EXPECT_THROW(frames.Update(s), ProtocolError);
}

TEST(TrajectoryToCommands, SendsOneSetPointPerJointPerPointAtStampPlusTimeFromStart) {
  const RobotModel m = Chain();
  // Names in any order; a multi-dof joint's values are put in dof order.
  const auto t =
      Trajectory({"wrist/1", "lift", "wrist/0"},
                 {{.positions = {0.3, 0.5, 0.1}, .time_from_start = 0s},
                  {.positions = {0.4, 0.6, 0.2}, .velocities = {1, 2, 3}, .time_from_start = 500ms}});
  const TimePoint start(100s);
  const auto plan = TrajectoryToCommands(m, t, start, TimePoint(99s));
  ASSERT_EQ(plan.commands.size(), 4u);
  EXPECT_EQ(plan.points_skipped, 0u);
  EXPECT_EQ(plan.commands[0].type, CommandType::kJointSetPoint);
  EXPECT_EQ(plan.commands[0].target, "lift");
  EXPECT_EQ(plan.commands[0].values, std::vector<double>{0.5});
  EXPECT_EQ(plan.commands[0].start_time.time(), start);
  EXPECT_EQ(plan.commands[1].target, "wrist");
  EXPECT_EQ(plan.commands[1].values, (std::vector<double>{0.1, 0.3}));
  EXPECT_EQ(plan.commands[3].start_time.time(), start + 500ms);
  EXPECT_EQ(plan.commands[3].velocities, (std::vector<double>{3, 1}));
}

TEST(TrajectoryToCommands, KeepsOnlyTheLastPastPointAndSendsItNow) {
  const RobotModel m = Chain();
  const auto t = Trajectory({"lift"}, {{.positions = {0.1}, .time_from_start = 0s},
                                       {.positions = {0.2}, .time_from_start = 1s},
                                       {.positions = {0.3}, .time_from_start = 2s}});
  const auto plan = TrajectoryToCommands(m, t, TimePoint(100s), TimePoint(101500ms));
  EXPECT_EQ(plan.points_skipped, 1u);
  ASSERT_EQ(plan.commands.size(), 2u);
  EXPECT_EQ(plan.commands[0].values, std::vector<double>{0.2});
  EXPECT_EQ(plan.commands[0].start_time.time(), TimePoint(101500ms));
  EXPECT_EQ(plan.commands[1].start_time.time(), TimePoint(102s));
}

TEST(TrajectoryToCommands, RefusesABadTrajectoryWholeNamingTheField) {
  const RobotModel m = Chain();
  const TrajectoryMessage::Point p{.positions = {0.1}};
  EXPECT_THAT(Refusal(m, Trajectory({}, {p})), HasSubstr("joint_names is empty"));
  EXPECT_THAT(Refusal(m, Trajectory({"lift"}, {})), HasSubstr("no points"));
  EXPECT_THAT(Refusal(m, Trajectory({"elbow"}, {p})),
              HasSubstr("joint_names[0] 'elbow': robot 'chain' has no joint"));
  EXPECT_THAT(Refusal(m, Trajectory({"lift", "lift"}, {{.positions = {0, 0}}})),
              HasSubstr("'lift' is named twice"));
  EXPECT_THAT(Refusal(m, Trajectory({"wrist/0"}, {p})),
              HasSubstr("joint 'wrist' has 2 dofs; name all of them"));
  EXPECT_THAT(Refusal(m, Trajectory({"lift"}, {{.positions = {0.1, 0.2}}})),
              HasSubstr("points[0].positions has 2 values for 1 joint names"));
  EXPECT_THAT(Refusal(m, Trajectory({"lift"}, {{.positions = {0.1}, .velocities = {1, 2}}})),
              HasSubstr("points[0].velocities has 2 values"));
  EXPECT_THAT(Refusal(m, Trajectory({"lift"}, {{.positions = {NAN}}})),
              HasSubstr("points[0].positions[0] is nan"));
  EXPECT_THAT(Refusal(m, Trajectory({"lift"}, {{.positions = {0.1}, .time_from_start = 1s},
                                               {.positions = {0.2}, .time_from_start = 1s}})),
              HasSubstr("points[1].time_from_start (1 s) is not after the previous point's"));
  EXPECT_THAT(Refusal(m, Trajectory({"lift"}, {{.positions = {0.1}, .time_from_start = -1s}})),
              HasSubstr("points[0].time_from_start is negative"));
}

TEST(TrajectoryToCommands, RefusesWhatCheckCommandRefusesBeforeSendingAnything) {
  RobotModelBuilder b("ptu");
  b.AddLink(Link{.name = "base"}).AddLink(Link{.name = "head"});
  Joint pan{.name = "pan", .servo_types = ServoType::kSpeed};  // takes no set-point
  pan.dofs = {Dof{}};
  b.AddJoint(pan, "base", "head");
  EXPECT_THAT(Refusal(b.Build(), Trajectory({"pan"}, {{.positions = {0.1}}})),
              HasSubstr("points[0]: JOINT_SETPOINT"));
}

TEST(TwistToCommand, MapsToSetSpeedOfTheBaseAndSaysWhatItIgnores) {
  std::string note;
  const Command d = TwistToCommand(BaseType::kDifferential, {0.5, 0.1, 0}, {0, 0, 0.3}, &note);
  EXPECT_EQ(d.type, CommandType::kSetSpeed);
  EXPECT_EQ(d.values, (std::vector<double>{0.5, 0.3}));
  EXPECT_THAT(note, HasSubstr("linear.y"));
  const Command h = TwistToCommand(BaseType::kHolonomic, {0.5, 0.1, 0}, {0, 0, 0.3}, &note);
  EXPECT_EQ(h.values, (std::vector<double>{0.5, 0.1, 0.3}));
  EXPECT_EQ(note, "");
  EXPECT_THROW(TwistToCommand(BaseType::kFixed, {0.1, 0, 0}, {0, 0, 0}, &note), Error);
  EXPECT_THROW(TwistToCommand(BaseType::kDifferential, {INFINITY, 0, 0}, {0, 0, 0}, &note), Error);
}

// The URDF written from a configuration imports back to the same kinematics.
TEST(ModelToUrdf, ImportsBackToTheSameKinematicsForAUrdfRobot) {
  const RobotModel original = LoadUrdfFile(kPioneer).model;
  const std::string urdf = ModelToUrdf(original);
  EXPECT_THAT(urdf, HasSubstr("<joint name=\"pan\" type=\"revolute\">"));
  const RobotModel back = ParseUrdf(urdf).model;
  ASSERT_EQ(back.num_dofs(), original.num_dofs());
  Kinematics a(original), b(back);
  Eigen::VectorXd q = Eigen::VectorXd::LinSpaced(original.num_dofs(), -0.4, 0.5);
  a.Update(q);
  b.Update(q);
  for (const Link& link : original.links()) {
    const auto i = original.LinkIndex(link.name);
    EXPECT_TRUE(a.link_pose(i).isApprox(b.link_pose(back.LinkIndex(link.name)), 1e-9)) << link.name;
  }
}

TEST(ModelToUrdf, WritesJointsAUrdfCannotExpressAsFloating) {
  const std::string urdf = ModelToUrdf(Chain());
  EXPECT_THAT(urdf, HasSubstr("<joint name=\"wrist\" type=\"floating\">"));
  EXPECT_THAT(urdf, HasSubstr("<joint name=\"lift\" type=\"prismatic\">"));
  EXPECT_THAT(urdf, HasSubstr("<joint name=\"mount\" type=\"fixed\">"));
}

}  // namespace
}  // namespace robotalk::ros2
