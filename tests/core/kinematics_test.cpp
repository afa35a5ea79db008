#include "robotalk/kinematics.h"

#include "robotalk/error.h"
#include "robotalk/urdf_import.h"
#include "test_paths.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <limits>
#include <new>
#include <numbers>
#include <random>

#include "support/allocation_counter.h"  // g_allocations

namespace robotalk {
namespace {

using Eigen::Vector3d;
using ::testing::HasSubstr;
constexpr double kTol = 1e-12;
constexpr double kPi = std::numbers::pi;

Link Body(const std::string& name, double mass = 1.0, const Vector3d& com = Vector3d::Zero()) {
  Link link{.name = name, .mass = mass, .com = com};
  link.inertia = Eigen::Matrix3d::Identity() * 0.01 * mass;
  return link;
}

Dof Revolute(const Vector3d& axis = Vector3d::UnitZ()) {
  return Dof{.type = DofType::kRevolute, .axis = axis};
}
Dof Prismatic(const Vector3d& axis) { return Dof{.type = DofType::kPrismatic, .axis = axis}; }

Joint MakeJoint(const std::string& name, std::vector<Dof> dofs, const Vector3d& inboard = Vector3d::Zero(),
                const Vector3d& outboard = Vector3d::Zero()) {
  return Joint{.name = name, .inboard = inboard, .outboard = outboard, .dofs = std::move(dofs)};
}

Eigen::Quaterniond Rot(double angle, const Vector3d& axis) {
  return Eigen::Quaterniond(Eigen::AngleAxisd(angle, axis.normalized()));
}

// base -(shoulder, z)-> upper -(elbow, z)-> lower, tool frame at the tip.
// Link frames sit on the joints; the COMs are placed off them (with y and z
// components) so that inboard/outboard have to cancel them correctly.
RobotModel PlanarArm(double l1, double l2, bool offset_coms) {
  const Vector3d c0 = offset_coms ? Vector3d(0.1, 0.2, 0.3) : Vector3d::Zero();
  const Vector3d c1 = offset_coms ? Vector3d(0.4, -0.1, 0.05) : Vector3d::Zero();
  const Vector3d c2 = offset_coms ? Vector3d(0.2, 0.1, -0.2) : Vector3d::Zero();
  RobotModelBuilder b("planar");
  b.AddLink(Body("base", 1, c0)).AddLink(Body("upper", 1, c1)).AddLink(Body("lower", 1, c2));
  b.AddJoint(MakeJoint("shoulder", {Revolute()}, -c0, -c1), "base", "upper");
  b.AddJoint(MakeJoint("elbow", {Revolute()}, Vector3d(l1, 0, 0) - c1, -c2), "upper", "lower");
  b.AddControlFrame(ControlFrame{.name = "tool", .pose_in_link = {.translation = {l2, 0, 0}}}, "lower");
  return b.Build();
}

void ExpectPlanarArmMatchesClosedForm(bool offset_coms) {
  const double l1 = 0.7, l2 = 0.45;
  const RobotModel model = PlanarArm(l1, l2, offset_coms);
  Kinematics kin(model);
  for (const auto& [q1, q2] :
       {std::pair{0.0, 0.0}, {0.3, -0.8}, {-2.1, 1.4}, {kPi / 2, kPi / 2}, {3.0, 3.0}}) {
    SCOPED_TRACE(::testing::Message() << "q = (" << q1 << ", " << q2 << ")");
    kin.Update(Eigen::Vector2d(q1, q2));
    const double c1 = std::cos(q1), s1 = std::sin(q1), c12 = std::cos(q1 + q2), s12 = std::sin(q1 + q2);
    const Eigen::Isometry3d tool = kin.frame_pose(0);
    EXPECT_TRUE(tool.translation().isApprox(Vector3d(l1 * c1 + l2 * c12, l1 * s1 + l2 * s12, 0), kTol))
        << tool.translation().transpose();
    EXPECT_TRUE(tool.linear().isApprox(Rot(q1 + q2, Vector3d::UnitZ()).toRotationMatrix(), kTol));

    Jacobian expected = Jacobian::Zero(6, 2);
    expected.row(0) << -l1 * s1 - l2 * s12, -l2 * s12;
    expected.row(1) << l1 * c1 + l2 * c12, l2 * c12;
    expected.row(5) << 1, 1;
    EXPECT_TRUE(kin.FrameJacobian(0).isApprox(expected, kTol)) << kin.FrameJacobian(0);
  }
}

TEST(Kinematics, PlanarTwoLinkArmMatchesClosedForm) { ExpectPlanarArmMatchesClosedForm(false); }

TEST(Kinematics, PlanarTwoLinkArmWithOffsetComsStillMatchesClosedForm) {
  ExpectPlanarArmMatchesClosedForm(true);
}

TEST(Kinematics, StartsAtZeroPositions) {
  const RobotModel model = PlanarArm(1, 1, false);
  Kinematics kin(model);
  EXPECT_TRUE(kin.frame_pose(0).translation().isApprox(Vector3d(2, 0, 0), kTol));
}

TEST(Kinematics, PrismaticJointMovesChildAlongItsAxisRotatedByRest) {
  RobotModelBuilder b("slider");
  b.AddLink(Body("base")).AddLink(Body("carriage"));
  Joint slide = MakeJoint("slide", {Prismatic(Vector3d::UnitX())}, Vector3d(0, 0, 1));
  slide.rest = Rot(kPi / 2, Vector3d::UnitZ());  // joint x axis = world y axis
  b.AddJoint(slide, "base", "carriage");
  const RobotModel model = b.Build();
  Kinematics kin(model);
  for (const double q : {0.0, 0.25, -1.5}) {
    kin.Update(Eigen::VectorXd::Constant(1, q));
    EXPECT_TRUE(kin.link_pose(1).translation().isApprox(Vector3d(0, q, 1), kTol));
    EXPECT_TRUE(kin.link_pose(1).linear().isApprox(slide.rest.toRotationMatrix(), kTol));
    Jacobian expected = Jacobian::Zero(6, 1);
    expected(1, 0) = 1;
    EXPECT_TRUE(kin.PointJacobian(1, Vector3d(0.3, 0.2, 0.1)).isApprox(expected, kTol));
  }
}

TEST(Kinematics, PanTiltJointPointsCameraWhereHandComputationSays) {
  const double h = 1.2, d = 0.1;
  RobotModelBuilder b("ptu");
  b.AddLink(Body("base")).AddLink(Body("head", 0.5));
  b.AddJoint(
      MakeJoint("pan_tilt", {Revolute(Vector3d::UnitZ()), Revolute(Vector3d::UnitY())}, Vector3d(0, 0, h)),
      "base", "head");
  b.AddControlFrame(ControlFrame{.name = "camera", .pose_in_link = {.translation = {d, 0, 0}}}, "head");
  const RobotModel model = b.Build();
  Kinematics kin(model);
  const double pan = 0.6, tilt = 0.4;  // tilt about y looks down
  kin.Update(Eigen::Vector2d(pan, tilt));
  const Eigen::Isometry3d camera = kin.frame_pose(0);
  const Vector3d expected(d * std::cos(pan) * std::cos(tilt), d * std::sin(pan) * std::cos(tilt),
                          h - d * std::sin(tilt));
  EXPECT_TRUE(camera.translation().isApprox(expected, kTol)) << camera.translation().transpose();
  const Eigen::Matrix3d r = (Rot(pan, Vector3d::UnitZ()) * Rot(tilt, Vector3d::UnitY())).toRotationMatrix();
  EXPECT_TRUE(camera.linear().isApprox(r, kTol));
  // The tilt axis is the pan-rotated y axis, through the joint centre.
  const Jacobian jac = kin.FrameJacobian(0);
  const Vector3d tilt_axis(-std::sin(pan), std::cos(pan), 0);
  EXPECT_TRUE(jac.col(1).tail<3>().isApprox(tilt_axis, kTol));
  EXPECT_TRUE(jac.col(1).head<3>().isApprox(tilt_axis.cross(expected - Vector3d(0, 0, h)), kTol));
  EXPECT_TRUE(jac.col(0).tail<3>().isApprox(Vector3d::UnitZ(), kTol));
}

TEST(Kinematics, RootPoseMovesEverythingRigidly) {
  const RobotModel model = PlanarArm(0.7, 0.45, true);
  Kinematics kin(model);
  const Eigen::Vector2d q(0.3, -1.1);
  kin.Update(q);
  std::vector<Eigen::Isometry3d> before;
  for (int l = 0; l < 3; ++l) before.push_back(kin.link_pose(l));
  const Eigen::Isometry3d tool_before = kin.frame_pose(0);
  const Vector3d com_before = kin.CenterOfMass();

  Eigen::Isometry3d root = Eigen::Isometry3d::Identity();
  root.translate(Vector3d(1, -2, 0.5)).rotate(Rot(0.7, Vector3d(1, 2, 3)));
  kin.Update(q, std::span(&root, 1));
  for (int l = 0; l < 3; ++l)
    EXPECT_TRUE(kin.link_pose(l).isApprox(root * before[static_cast<size_t>(l)], kTol));
  EXPECT_TRUE(kin.frame_pose(0).isApprox(root * tool_before, kTol));
  EXPECT_TRUE(kin.CenterOfMass().isApprox(root * com_before, kTol));
  // Without root poses the model's own (identity) pose applies again.
  kin.Update(q);
  EXPECT_TRUE(kin.frame_pose(0).isApprox(tool_before, kTol));
}

TEST(Kinematics, UsesTheModelRootPoseByDefault) {
  RobotModelBuilder b("mounted");
  b.AddLink(Body("base")).AddLink(Body("arm"));
  b.AddJoint(MakeJoint("j", {Revolute()}, Vector3d(1, 0, 0)), "base", "arm");
  const Pose mount{.translation = {0, 0, 2}, .rotation = Rot(kPi / 2, Vector3d::UnitZ())};
  b.SetRoot("base", mount);
  const RobotModel model = b.Build();
  Kinematics kin(model);
  EXPECT_TRUE(kin.link_pose(0).isApprox(mount.ToIsometry(), kTol));
  EXPECT_TRUE(kin.link_pose(1).translation().isApprox(Vector3d(0, 1, 2), kTol));
}

TEST(Kinematics, PosesEachRootOfAMultiRootModel) {
  RobotModelBuilder b("two_arms");
  b.AddLink(Body("left_base"))
      .AddLink(Body("left_arm"))
      .AddLink(Body("right_base"))
      .AddLink(Body("right_arm"));
  b.AddJoint(MakeJoint("left_j", {Revolute()}, Vector3d(0.5, 0, 0)), "left_base", "left_arm");
  b.AddJoint(MakeJoint("right_j", {Revolute()}, Vector3d(0.5, 0, 0)), "right_base", "right_arm");
  b.AddControlFrame(ControlFrame{.name = "left_tip", .pose_in_link = {.translation = {1, 0, 0}}}, "left_arm");
  b.AddControlFrame(ControlFrame{.name = "right_tip", .pose_in_link = {.translation = {1, 0, 0}}},
                    "right_arm");
  b.SetRoot("left_base", Pose{.translation = {0, 1, 0}});
  b.SetRoot("right_base", Pose{.translation = {0, -1, 0}});
  const RobotModel model = b.Build();
  ASSERT_EQ(model.roots().size(), 2u);
  Kinematics kin(model);
  kin.Update(Eigen::Vector2d(kPi / 2, 0));
  EXPECT_TRUE(kin.frame_pose(model.FrameIndex("left_tip")).translation().isApprox(Vector3d(0.5, 2, 0), kTol));
  EXPECT_TRUE(
      kin.frame_pose(model.FrameIndex("right_tip")).translation().isApprox(Vector3d(1.5, -1, 0), kTol));
  // Each tip depends only on its own arm's dof.
  const Jacobian left = kin.FrameJacobian(model.FrameIndex("left_tip"));
  EXPECT_TRUE(left.col(1).isZero());
  EXPECT_TRUE(left.col(0).isApprox((Jacobian(6, 1) << -1, 0, 0, 0, 0, 1).finished(), kTol));

  std::vector<Eigen::Isometry3d> roots(2, Eigen::Isometry3d::Identity());
  roots[1].translation() = Vector3d(5, 0, 0);
  kin.Update(Eigen::Vector2d(0, 0), roots);
  EXPECT_TRUE(kin.frame_pose(0).translation().isApprox(Vector3d(1.5, 0, 0), kTol));
  EXPECT_TRUE(kin.frame_pose(1).translation().isApprox(Vector3d(6.5, 0, 0), kTol));
}

TEST(Kinematics, FixedJointAppliesItsConstantTransform) {
  RobotModelBuilder b("fixed");
  b.AddLink(Body("base")).AddLink(Body("arm")).AddLink(Body("flange", 0.2, Vector3d(0, 0, 0.05)));
  b.AddJoint(MakeJoint("j", {Revolute()}), "base", "arm");
  Joint weld = MakeJoint("weld", {}, Vector3d(1, 0, 0), Vector3d(0, 0, -0.05));
  weld.rest = Rot(kPi / 2, Vector3d::UnitY());
  b.AddJoint(weld, "arm", "flange");
  const RobotModel model = b.Build();
  ASSERT_EQ(model.num_dofs(), 1);
  Kinematics kin(model);
  kin.Update(Eigen::VectorXd::Constant(1, kPi / 2));
  // flange COM + outboard = 0: the flange frame sits on the weld, 1 m along the arm.
  EXPECT_TRUE(kin.link_pose(2).translation().isApprox(Vector3d(0, 1, 0), kTol));
  EXPECT_TRUE(kin.link_pose(2).linear().isApprox(
      (Rot(kPi / 2, Vector3d::UnitZ()) * weld.rest).toRotationMatrix(), kTol));
  // The revolute dof above the weld still moves a point on the flange.
  const Jacobian jac = kin.PointJacobian(2, Vector3d::Zero());
  EXPECT_TRUE(jac.col(0).isApprox((Jacobian(6, 1) << -1, 0, 0, 0, 0, 1).finished(), kTol));
}

TEST(Kinematics, CenterOfMassIsTheMassWeightedMeanOfLinkComs) {
  RobotModelBuilder b("com");
  const Vector3d base_com(0, 0, 0.1), arm_com(0.5, 0, 0);
  b.AddLink(Body("base", 2, base_com)).AddLink(Body("arm", 1, arm_com)).AddLink(Body("marker", 0));
  // Joint at the base frame origin; the arm frame sits on it.
  b.AddJoint(MakeJoint("j", {Revolute()}, -base_com, -arm_com), "base", "arm");
  b.AddJoint(MakeJoint("m", {}, -arm_com + Vector3d(3, 0, 0)), "arm", "marker");
  const RobotModel model = b.Build();
  EXPECT_DOUBLE_EQ(model.total_mass(), 3);
  Kinematics kin(model);
  kin.Update(Eigen::VectorXd::Constant(1, kPi / 2));
  EXPECT_TRUE(kin.CenterOfMass().isApprox(Vector3d(0, 0.5 / 3, 0.2 / 3), kTol))
      << kin.CenterOfMass().transpose();
}

TEST(Kinematics, MasslessRobotHasZeroCenterOfMass) {
  RobotModelBuilder b("ghost");
  b.AddLink(Body("a", 0)).AddLink(Body("b", 0));
  b.AddJoint(MakeJoint("j", {Prismatic(Vector3d::UnitX())}), "a", "b");
  b.SetRoot("a", Pose{.translation = {1, 2, 3}});
  const RobotModel model = b.Build();
  Kinematics kin(model);
  kin.Update(Eigen::VectorXd::Constant(1, 0.5));
  EXPECT_EQ(kin.CenterOfMass(), Vector3d::Zero());
}

TEST(Kinematics, ApplyMimicsSetsFollowersFromLeaders) {
  RobotModelBuilder b("gripper");
  b.AddLink(Body("palm")).AddLink(Body("left")).AddLink(Body("right")).AddLink(Body("wrist_link"));
  b.AddJoint(MakeJoint("wrist", {Revolute(), Revolute(Vector3d::UnitY())}), "palm", "wrist_link");
  b.AddJoint(MakeJoint("left", {Prismatic(Vector3d::UnitY())}), "wrist_link", "left");
  b.AddJoint(MakeJoint("right", {Prismatic(Vector3d::UnitY())}), "wrist_link", "right");
  b.SetMimic("right", "left", -2.0, 0.1);
  const RobotModel model = b.Build();
  Eigen::VectorXd q(4);
  q << 0.5, -0.5, 0.03, 99;
  ApplyMimics(model, q);
  EXPECT_EQ(q, Eigen::Vector4d(0.5, -0.5, 0.03, -2.0 * 0.03 + 0.1));
  Eigen::VectorXd short_q(3);
  EXPECT_THROW(ApplyMimics(model, short_q), robotalk::Error);
}

// Expects `f` to throw robotalk::Error whose message contains every fragment.
template <typename F>
void ExpectInvalidArgument(F f, std::initializer_list<const char*> fragments) {
  try {
    f();
    ADD_FAILURE() << "no exception";
  } catch (const robotalk::Error& e) {
    for (const char* fragment : fragments) EXPECT_THAT(e.what(), HasSubstr(fragment));
  }
}

TEST(Kinematics, UpdateRejectsBadInputWithHelpfulMessages) {
  const RobotModel model = PlanarArm(1, 1, false);
  Kinematics kin(model);
  ExpectInvalidArgument([&] { kin.Update(Eigen::Vector3d(0, 0, 0)); },
                        {"Kinematics::Update", "'planar'", "q has 3 entries, expected 2"});
  ExpectInvalidArgument([&] { kin.Update(Eigen::Vector2d(0, std::nan(""))); }, {"q[1] is nan"});
  ExpectInvalidArgument([&] { kin.Update(Eigen::Vector2d(std::numeric_limits<double>::infinity(), 0)); },
                        {"q[0] is inf"});
  std::vector<Eigen::Isometry3d> two_roots(2, Eigen::Isometry3d::Identity());
  ExpectInvalidArgument([&] { kin.Update(Eigen::Vector2d(0, 0), two_roots); },
                        {"2 root poses given, expected 1"});
  Eigen::Isometry3d bad_root = Eigen::Isometry3d::Identity();
  bad_root.translation().x() = std::nan("");
  ExpectInvalidArgument([&] { kin.Update(Eigen::Vector2d(0, 0), std::span(&bad_root, 1)); },
                        {"root pose 0 (link 'base') is not finite"});
}

TEST(Kinematics, AccessorsThrowLookupErrorForBadIndices) {
  const RobotModel model = PlanarArm(1, 1, false);
  Kinematics kin(model);
  EXPECT_THROW(kin.link_pose(3), LookupError);
  EXPECT_THROW(kin.link_pose(-1), LookupError);
  EXPECT_THROW(kin.frame_pose(1), LookupError);
  EXPECT_THROW(kin.FrameJacobian(-1), LookupError);
  EXPECT_THROW(kin.PointJacobian(7, Vector3d::Zero()), LookupError);
}

TEST(Kinematics, UpdateDoesNotAllocate) {
  const RobotModel model = PlanarArm(1, 1, true);
  Kinematics kin(model);
  const Eigen::Vector2d q(0.1, 0.2);
  const Eigen::Isometry3d root = Eigen::Isometry3d::Identity();
  const long before = g_allocations;
  kin.Update(q);
  kin.Update(q, std::span(&root, 1));
  const Eigen::Isometry3d pose = kin.link_pose(2);
  EXPECT_EQ(g_allocations, before);
  EXPECT_TRUE(pose.matrix().allFinite());
}

// --- Finite-difference checks -------------------------------------------------

// Random positions within limits; unlimited dofs within ±π (or ±1 m).
Eigen::VectorXd RandomPositions(const RobotModel& model, std::mt19937& rng) {
  Eigen::VectorXd q(model.num_dofs());
  for (int j = 0; j < static_cast<int>(model.joints().size()); ++j) {
    const auto& dofs = model.joint(j).dofs;
    for (size_t k = 0; k < dofs.size(); ++k) {
      const double span = dofs[k].type == DofType::kRevolute ? kPi : 1.0;
      const double lo = std::max(dofs[k].limits.lower, -span), hi = std::min(dofs[k].limits.upper, span);
      q[model.dof_offset(j) + static_cast<int>(k)] = std::uniform_real_distribution<double>(lo, hi)(rng);
    }
  }
  return q;
}

// Central differences of a point's world position and of its link's
// orientation (as a rotation vector), one dof at a time.
Jacobian NumericalJacobian(Kinematics& kin, int link, const Vector3d& point, const Eigen::VectorXd& q) {
  constexpr double h = 1e-6;
  Jacobian jac(6, q.size());
  for (Eigen::Index i = 0; i < q.size(); ++i) {
    Eigen::VectorXd qp = q, qm = q;
    qp[i] += h;
    qm[i] -= h;
    kin.Update(qp);
    const Eigen::Isometry3d xp = kin.link_pose(link);
    kin.Update(qm);
    const Eigen::Isometry3d xm = kin.link_pose(link);
    const Eigen::AngleAxisd dr(xp.linear() * xm.linear().transpose());
    jac.col(i) << (xp * point - xm * point) / (2 * h), dr.angle() * dr.axis() / (2 * h);
  }
  kin.Update(q);
  return jac;
}

// Checks PointJacobian of an off-origin point on every link at a few random q.
void ExpectJacobiansMatchFiniteDifferences(const RobotModel& model, unsigned seed) {
  std::mt19937 rng(seed);
  Kinematics kin(model);
  const Vector3d point(0.1, -0.05, 0.2);
  for (int trial = 0; trial < 3; ++trial) {
    const Eigen::VectorXd q = RandomPositions(model, rng);
    for (int link = 0; link < static_cast<int>(model.links().size()); ++link) {
      kin.Update(q);
      const Jacobian analytic = kin.PointJacobian(link, point);
      const Jacobian numeric = NumericalJacobian(kin, link, point, q);
      const double scale = std::max(1.0, analytic.cwiseAbs().maxCoeff());
      EXPECT_LE((analytic - numeric).cwiseAbs().maxCoeff(), 1e-6 * scale)
          << model.name() << " link '" << model.link(link).name << "' trial " << trial << "\nanalytic\n"
          << analytic << "\nnumeric\n"
          << numeric;
    }
  }
}

// A random tree of multi-dof joints mixing revolute and prismatic dofs, with
// rest rotations and offset COMs: exercises what 1-dof URDF robots do not.
TEST(Kinematics, JacobianMatchesFiniteDifferencesOnARandomMultiDofTree) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1, 1);
  auto random_vector = [&] { return Vector3d(u(rng), u(rng), u(rng)); };
  RobotModelBuilder b("random_tree");
  b.AddLink(Body("l0", 1, random_vector()));
  for (int i = 1; i < 12; ++i) {
    b.AddLink(Body("l" + std::to_string(i), 1, random_vector()));
    std::vector<Dof> dofs;
    const int n = i % 4;  // 0 (fixed) to 3 dofs
    for (int k = 0; k < n; ++k) {
      const Vector3d axis = random_vector().normalized();
      dofs.push_back(rng() % 3 == 0 ? Prismatic(axis) : Revolute(axis));
    }
    Joint joint = MakeJoint("j" + std::to_string(i), dofs, random_vector(), random_vector());
    joint.rest = Rot(u(rng) * kPi, random_vector());
    b.AddJoint(joint, "l" + std::to_string(static_cast<int>(rng() % static_cast<unsigned>(i))),
               "l" + std::to_string(i));
  }
  b.SetRoot("l0", Pose{.translation = random_vector(), .rotation = Rot(1.0, random_vector())});
  ExpectJacobiansMatchFiniteDifferences(b.Build(), 11);
}

class KinematicsOnSharedRobot : public ::testing::TestWithParam<const char*> {};

TEST_P(KinematicsOnSharedRobot, JacobianMatchesFiniteDifferences) {
  ROBOTALK_REQUIRE_SHARED_ROBOTS();
  const UrdfImportResult imported = LoadUrdfFile(testing::SharedRobot(GetParam()));
  ASSERT_GT(imported.model.num_dofs(), 0);
  ExpectJacobiansMatchFiniteDifferences(imported.model, 2024);
}

INSTANTIATE_TEST_SUITE_P(RealRobots, KinematicsOnSharedRobot,
                         ::testing::Values("iiwa14.urdf", "atlas.urdf", "ur5.urdf", "romeo.urdf", "pr2.urdf",
                                           "pioneer_lx_ptu_jaco2.urdf"),
                         [](const auto& info) {
                           std::string name = info.param;
                           return name.substr(0, name.find('.'));
                         });

}  // namespace
}  // namespace robotalk
