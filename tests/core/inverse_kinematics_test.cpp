// Tests of InverseKinematics (robotalk-core/spec/src/inverse_kinematics.cpp): a
// planar 2-link arm against its closed form, unreachable goals, limits, masks,
// mimics, bad input, and random reachable poses of the iiwa14.
#include "robotalk/inverse_kinematics.h"

#include "robotalk/error.h"
#include "robotalk/kinematics.h"
#include "robotalk/urdf_import.h"
#include "test_paths.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>
#include <stdexcept>
#include <vector>

namespace robotalk {
namespace {

using Eigen::Vector3d;
constexpr double kPi = std::numbers::pi;
constexpr double kL1 = 0.5, kL2 = 0.4;  // the planar arm's link lengths, m

Dof Revolute(double lower, double upper) {
  return Dof{.type = DofType::kRevolute,
             .axis = Vector3d::UnitZ(),
             .limits = {.lower = lower, .upper = upper, .velocity = 1.0}};
}

// A planar arm about z: shoulder at the base, elbow 0.5 m out (it bends one
// way only, 0..2.5 rad), tool frame 0.4 m beyond; `elbow_servo` sets what the
// elbow accepts. With `wrist`, a third joint 0.4 m beyond the elbow follows it
// (q = 0.5 q_elbow + 0.1) and the tool sits 0.2 m beyond the wrist.
RobotModel PlanarArm(ServoTypes elbow_servo = ServoTypes::All(), bool wrist = false) {
  RobotModelBuilder b("arm");
  b.AddLink({.name = "base"}).AddLink({.name = "upper"}).AddLink({.name = "lower"});
  b.AddJoint(Joint{.name = "shoulder", .dofs = {Revolute(-kPi, kPi)}, .servo_types = ServoTypes::All()},
             "base", "upper");
  b.AddJoint(
      Joint{
          .name = "elbow", .inboard = {kL1, 0, 0}, .dofs = {Revolute(0.0, 2.5)}, .servo_types = elbow_servo},
      "upper", "lower");
  std::string tool_link = "lower";
  double tool_x = kL2;
  if (wrist) {
    b.AddLink({.name = "hand"});
    b.AddJoint(Joint{.name = "wrist", .inboard = {kL2, 0, 0}, .dofs = {Revolute(-kPi, kPi)}}, "lower",
               "hand");
    b.SetMimic("wrist", "elbow", 0.5, 0.1);
    tool_link = "hand";
    tool_x = 0.2;
  }
  b.AddControlFrame(ControlFrame{.name = "tool",
                                 .pose_in_link = {.translation = {tool_x, 0, 0}},
                                 .servo_types = ServoType::kSetPoint},
                    tool_link);
  b.AddControlFrame(ControlFrame{.name = "plate", .servo_types = ServoType::kSetPoint}, "base");
  return b.Build();
}

Eigen::Isometry3d FramePoseAt(const RobotModel& model, int frame, const Eigen::VectorXd& q) {
  Kinematics kin(model);
  kin.Update(q);
  return kin.frame_pose(frame);
}

Eigen::Quaterniond Yaw(double a) { return Eigen::Quaterniond(Eigen::AngleAxisd(a, Vector3d::UnitZ())); }

void ExpectWithinLimits(const RobotModel& model, const Eigen::VectorXd& q) {
  for (int j = 0; j < static_cast<int>(model.joints().size()); ++j) {
    for (size_t k = 0; k < model.joint(j).dofs.size(); ++k) {
      const double v = q[model.dof_offset(j) + static_cast<int>(k)];
      EXPECT_GE(v, model.joint(j).dofs[k].limits.lower) << model.joint(j).name;
      EXPECT_LE(v, model.joint(j).dofs[k].limits.upper) << model.joint(j).name;
    }
  }
}

TEST(InverseKinematics, PlanarArmReachesAReachablePointAsTheClosedFormSays) {
  const RobotModel arm = PlanarArm();
  InverseKinematics ik(arm);
  const int tool = arm.FrameIndex("tool");
  // Goal: the point (0.6, 0.3) with the tool along yaw 1.2 rad. Closed form:
  // cos q2 = (x² + y² − l1² − l2²) / (2 l1 l2), q2 >= 0 (the elbow's limits),
  // q1 = atan2(y, x) − atan2(l2 sin q2, l1 + l2 cos q2), and then the yaw
  // q1 + q2 must be the goal's.
  const double x = 0.6, y = 0.3;
  const double q2 = std::acos((x * x + y * y - kL1 * kL1 - kL2 * kL2) / (2 * kL1 * kL2));
  const double q1 = std::atan2(y, x) - std::atan2(kL2 * std::sin(q2), kL1 + kL2 * std::cos(q2));
  const InverseKinematics::Result r =
      ik.Solve(tool, Vector3d(x, y, 0), Yaw(q1 + q2), Eigen::VectorXd::Zero(2));
  EXPECT_TRUE(r.within_tolerance);
  EXPECT_LE(r.position_error, InverseKinematics::kPositionTolerance);
  EXPECT_LE(r.orientation_error, InverseKinematics::kOrientationTolerance);
  EXPECT_GT(r.iterations, 0);
  EXPECT_NEAR(ik.solution()[0], q1, 2e-3);
  EXPECT_NEAR(ik.solution()[1], q2, 2e-3);
  const Eigen::Isometry3d reached = FramePoseAt(arm, tool, ik.solution());
  EXPECT_NEAR((reached.translation() - Vector3d(x, y, 0)).norm(), r.position_error, 1e-12);
}

TEST(InverseKinematics, UnreachablePointGivesTheClosestPointAndItsResidual) {
  const RobotModel arm = PlanarArm();
  InverseKinematics ik(arm);
  const int tool = arm.FrameIndex("tool");
  const InverseKinematics::Result r =
      ik.Solve(tool, Vector3d(2.0, 0, 0), Eigen::Quaterniond::Identity(), Eigen::VectorXd::Zero(2));
  EXPECT_FALSE(r.within_tolerance);
  // Stretched out along x: 0.9 m long, 1.1 m short of the goal.
  EXPECT_NEAR(r.position_error, 1.1, 1e-3);
  EXPECT_NEAR(r.orientation_error, 0.0, 1e-2);
  const Eigen::Isometry3d reached = FramePoseAt(arm, tool, ik.solution());
  EXPECT_NEAR(reached.translation().x(), 0.9, 1e-3);
  EXPECT_NEAR(reached.translation().y(), 0.0, 1e-3);
}

TEST(InverseKinematics, PositionLimitsAreRespected) {
  const RobotModel arm = PlanarArm();
  InverseKinematics ik(arm);
  const int tool = arm.FrameIndex("tool");
  // The pose of the mirrored elbow (q2 = −0.8) is out of the elbow's range
  // 0..2.5: the position and the yaw together admit no other solution.
  Eigen::VectorXd mirrored(2);
  mirrored << 0.5, -0.8;
  const Eigen::Isometry3d goal = FramePoseAt(arm, tool, mirrored);
  const InverseKinematics::Result r =
      ik.Solve(tool, goal.translation(), Eigen::Quaterniond(goal.linear()), Eigen::Vector2d(0.2, 0.5));
  EXPECT_FALSE(r.within_tolerance);
  ExpectWithinLimits(arm, ik.solution());
  EXPECT_GT(r.position_error + r.orientation_error, 1e-2);
}

TEST(InverseKinematics, OnlyTheDofsOfTheMaskMove) {
  const RobotModel arm = PlanarArm();
  InverseKinematics ik(arm);
  const int tool = arm.FrameIndex("tool");
  const std::vector<std::uint8_t> shoulder_only = {1, 0};
  // Reachable with the shoulder alone (elbow at its start, 0.4 rad).
  const Eigen::Vector2d start(0.0, 0.4);
  const Eigen::Isometry3d goal = FramePoseAt(arm, tool, Eigen::Vector2d(0.9, 0.4));
  InverseKinematics::Result r =
      ik.Solve(tool, goal.translation(), Eigen::Quaterniond(goal.linear()), start, {}, shoulder_only);
  EXPECT_TRUE(r.within_tolerance);
  EXPECT_NEAR(ik.solution()[0], 0.9, 2e-3);
  EXPECT_EQ(ik.solution()[1], 0.4);
  // Not reachable without the elbow: the elbow still stays where it was.
  const Eigen::Isometry3d bent = FramePoseAt(arm, tool, Eigen::Vector2d(0.3, 1.5));
  r = ik.Solve(tool, bent.translation(), Eigen::Quaterniond(bent.linear()), start, {}, shoulder_only);
  EXPECT_FALSE(r.within_tolerance);
  EXPECT_EQ(ik.solution()[1], 0.4);
}

TEST(InverseKinematics, DefaultMaskHoldsTheSetPointJointsBetweenTheFrameAndItsRoot) {
  const RobotModel arm = PlanarArm(ServoType::kSpeed);  // the elbow takes no set-points
  InverseKinematics ik(arm);
  const int tool = arm.FrameIndex("tool");
  EXPECT_EQ(std::vector<std::uint8_t>(ik.default_mask(tool).begin(), ik.default_mask(tool).end()),
            (std::vector<std::uint8_t>{1, 0}));
  EXPECT_TRUE(ik.HasMovableDofs(tool));
  EXPECT_FALSE(ik.HasMovableDofs(arm.FrameIndex("plate")));  // on the root: nothing moves it
  const Eigen::Isometry3d goal = FramePoseAt(arm, tool, Eigen::Vector2d(0.3, 1.5));
  ik.Solve(tool, goal.translation(), Eigen::Quaterniond(goal.linear()), Eigen::Vector2d(0.0, 0.7));
  EXPECT_EQ(ik.solution()[1], 0.7);
}

TEST(InverseKinematics, MimicJointFollowsItsLeader) {
  const RobotModel arm = PlanarArm(ServoTypes::All(), /*wrist=*/true);
  InverseKinematics ik(arm);
  const int tool = arm.FrameIndex("tool");
  EXPECT_EQ(ik.default_mask(tool)[2], 0);  // the mimic is not moved on its own
  Eigen::VectorXd q_goal(3);
  q_goal << 0.3, 1.0, 0.5 * 1.0 + 0.1;
  const Eigen::Isometry3d goal = FramePoseAt(arm, tool, q_goal);
  Eigen::VectorXd start(3);
  start << 0.0, 0.2, 0.0;  // the wrist out of step: the solver applies the mimic
  const InverseKinematics::Result r =
      ik.Solve(tool, goal.translation(), Eigen::Quaterniond(goal.linear()), start);
  EXPECT_TRUE(r.within_tolerance) << r.position_error << " m, " << r.orientation_error << " rad";
  EXPECT_DOUBLE_EQ(ik.solution()[2], 0.5 * ik.solution()[1] + 0.1);
  EXPECT_NEAR(ik.solution()[1], 1.0, 5e-3);
}

TEST(InverseKinematics, RootPosesMoveTheGoalWithTheBase) {
  const RobotModel arm = PlanarArm();
  InverseKinematics ik(arm);
  const int tool = arm.FrameIndex("tool");
  Eigen::Isometry3d root = Eigen::Isometry3d::Identity();
  root.translation() << 1.0, -0.5, 0.2;
  root.linear() = Yaw(0.7).toRotationMatrix();
  const Eigen::Isometry3d goal = root * FramePoseAt(arm, tool, Eigen::Vector2d(-0.4, 1.1));
  const std::vector<Eigen::Isometry3d> roots = {root};
  const InverseKinematics::Result r =
      ik.Solve(tool, goal.translation(), Eigen::Quaterniond(goal.linear()), Eigen::VectorXd::Zero(2), roots);
  EXPECT_TRUE(r.within_tolerance);
  EXPECT_NEAR(ik.solution()[0], -0.4, 2e-3);
  EXPECT_NEAR(ik.solution()[1], 1.1, 2e-3);
}

TEST(InverseKinematics, BadInputThrowsNamingTheArgument) {
  const RobotModel arm = PlanarArm();
  InverseKinematics ik(arm);
  const Eigen::Quaterniond id = Eigen::Quaterniond::Identity();
  const Eigen::VectorXd q = Eigen::VectorXd::Zero(2);
  try {
    ik.Solve(0, Vector3d::Zero(), id, Eigen::VectorXd::Zero(3));
    FAIL() << "no error";
  } catch (const robotalk::Error& e) {
    EXPECT_NE(std::string(e.what()).find("q_start has 3 entries, expected 2"), std::string::npos) << e.what();
  }
  const std::vector<std::uint8_t> mask = {1};
  EXPECT_THROW(ik.Solve(0, Vector3d::Zero(), id, q, {}, mask), robotalk::Error);
  EXPECT_THROW(ik.Solve(0, Vector3d(NAN, 0, 0), id, q), robotalk::Error);
  EXPECT_THROW(ik.Solve(0, Vector3d::Zero(), Eigen::Quaterniond(0, 0, 0, 0), q), robotalk::Error);
  EXPECT_THROW(ik.Solve(7, Vector3d::Zero(), id, q), LookupError);
  EXPECT_THROW(ik.default_mask(-1), LookupError);
}

// Random reachable poses of the iiwa14's flange (+10 cm): the goal is the FK
// of a random q within the limits (fixed seed); the solver starts from that q
// perturbed by up to ±0.5 rad per joint (DLS is local: from far away a 7-dof
// arm may settle in a local optimum, which is then answered MODIFIED).
TEST(InverseKinematics, Iiwa14SolvesRandomReachablePoses) {
  ROBOTALK_REQUIRE_SHARED_ROBOTS();
  const RobotModel iiwa = LoadUrdfFile(testing::SharedRobot("iiwa14.urdf")).model;
  std::vector<ControlFrame> frames(iiwa.frames().begin(), iiwa.frames().end());
  const int tool = static_cast<int>(frames.size());
  frames.push_back(ControlFrame{.name = "tool",
                                .parent_link = iiwa.LinkIndex("iiwa_link_7"),
                                .pose_in_link = {.translation = {0, 0, 0.1}},
                                .servo_types = ServoType::kSetPoint});
  const RobotModel model("iiwa14_tool", {iiwa.links().begin(), iiwa.links().end()},
                         {iiwa.joints().begin(), iiwa.joints().end()}, frames,
                         {iiwa.roots().begin(), iiwa.roots().end()});
  ASSERT_EQ(model.num_dofs(), 7);
  InverseKinematics ik(model);
  std::mt19937 rng(42);
  std::uniform_real_distribution<double> unit(0.0, 1.0), nudge(-0.5, 0.5);
  constexpr int kPoses = 50;
  int solved = 0;
  for (int n = 0; n < kPoses; ++n) {
    Eigen::VectorXd q_goal(7), start(7);
    for (int i = 0; i < 7; ++i) {
      const DofLimits& lim =
          model.joint(model.JointIndex("iiwa_joint_" + std::to_string(i + 1))).dofs[0].limits;
      // Within 90 % of each range, so that a perturbed start is mostly inside.
      const double mid = 0.5 * (lim.lower + lim.upper), half = 0.45 * (lim.upper - lim.lower);
      q_goal[i] = mid + half * (2 * unit(rng) - 1);
      start[i] = q_goal[i] + nudge(rng);
    }
    const Eigen::Isometry3d goal = FramePoseAt(model, tool, q_goal);
    const InverseKinematics::Result r =
        ik.Solve(tool, goal.translation(), Eigen::Quaterniond(goal.linear()), start);
    ExpectWithinLimits(model, ik.solution());
    if (r.within_tolerance) {
      ++solved;
      const Eigen::Isometry3d reached = FramePoseAt(model, tool, ik.solution());
      EXPECT_LE((reached.translation() - goal.translation()).norm(), InverseKinematics::kPositionTolerance);
      EXPECT_LE(Eigen::AngleAxisd(reached.linear() * goal.linear().transpose()).angle(),
                InverseKinematics::kOrientationTolerance);
    }
  }
  EXPECT_EQ(solved, kPoses);
}

}  // namespace
}  // namespace robotalk
