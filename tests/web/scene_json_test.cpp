// Tests of what robotalk-web tells the page: the model as JSON and the world
// poses it computes from a state sample.
#include "scene_json.h"
#include "json_text.h"

#include "robotalk/error.h"
#include "robotalk/kinematics.h"
#include "robotalk/urdf_import.h"
#include "test_paths.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

namespace robotalk::web {
namespace {

RobotModel Pioneer() { return LoadUrdfFile(testing::ProjectModel("pioneer2dx_pantilt.urdf")).model; }

StateSample SampleFor(const RobotModel& m, const Eigen::VectorXd& q, double x, double y, double theta) {
  StateSample s;
  s.robot = m.name();
  s.sample = 7;
  s.server_time = TimePoint(std::chrono::microseconds(1'500'000));
  s.period = std::chrono::microseconds(33'000);
  s.positions.assign(q.data(), q.data() + q.size());
  s.velocities.assign(q.size(), 0.0);
  s.efforts.assign(q.size(), 0.0);
  s.base = {.x = x, .y = y, .theta = theta};
  return s;
}

double Yaw(const Eigen::Isometry3d& x) { return std::atan2(x.linear()(1, 0), x.linear()(0, 0)); }

TEST(EquivalentInertiaBox, RecoversTheSidesOfAUniformBox) {
  Link l{.name = "box", .mass = 2.0};
  const double a = 0.4, b = 0.2, c = 0.1;
  l.inertia = Eigen::Vector3d(b * b + c * c, a * a + c * c, a * a + b * b).asDiagonal();
  l.inertia *= l.mass / 12.0;
  const InertiaBox box = EquivalentInertiaBox(l);
  std::vector<double> sides{box.sides.x(), box.sides.y(), box.sides.z()};
  std::sort(sides.begin(), sides.end());
  EXPECT_NEAR(sides[0], c, 1e-12);
  EXPECT_NEAR(sides[1], b, 1e-12);
  EXPECT_NEAR(sides[2], a, 1e-12);
  // The box's longest side lies along the link's x axis.
  const Eigen::Vector3d longest =
      box.rotation * Eigen::Vector3d::Unit(static_cast<int>(
                         std::max_element(box.sides.data(), box.sides.data() + 3) - box.sides.data()));
  EXPECT_NEAR(std::abs(longest.x()), 1.0, 1e-9);
}

TEST(EquivalentInertiaBox, GivesTheMinimumSideToAMasslessLink) {
  const InertiaBox box = EquivalentInertiaBox(Link{.name = "frame"}, 0.05);
  EXPECT_EQ(box.sides, Eigen::Vector3d::Constant(0.05));
}

TEST(ModelToJson, ListsLinksJointsDofNamesAndEveryJointCentre) {
  const RobotModel m = Pioneer();
  const nlohmann::json j = ModelToJson(m);
  EXPECT_EQ(j["name"], m.name());
  EXPECT_EQ(j["links"].size(), m.links().size());
  EXPECT_EQ(j["joints"].size(), m.joints().size());
  EXPECT_EQ(j["dof_names"].size(), static_cast<size_t>(m.num_dofs()));
  EXPECT_NE(std::find(j["dof_names"].begin(), j["dof_names"].end(), "pan"), j["dof_names"].end());
  size_t points = 0;
  for (const auto& l : j["links"]) points += l["points"].size();
  EXPECT_EQ(points, 2 * m.joints().size());  // one on the parent, one on the child
  // A continuous wheel has no limits: null as sent, since JSON has no infinity.
  const std::string dump = JsonText(j);
  EXPECT_EQ(dump.find("inf"), std::string::npos);
  EXPECT_NE(dump.find("null"), std::string::npos);
}

TEST(StatePoser, PutsTheBaseAtTheSamplesXYThetaWithoutFrames) {
  RobotModel m = Pioneer();
  RobotModelBuilder b(m.name());  // the same robot without control frames
  for (const Link& l : m.links()) b.AddLink(l);
  for (const Joint& jt : m.joints()) {
    Joint copy = jt;
    copy.mimic.reset();
    b.AddJoint(copy, m.link(jt.parent_link).name, m.link(jt.child_link).name);
  }
  for (const RootLink& r : m.roots()) b.SetRoot(m.link(r.link).name, r.pose_in_world, r.base);
  const RobotModel bare = b.Build();
  StatePoser poser(bare);
  const auto s = SampleFor(bare, Eigen::VectorXd::Zero(bare.num_dofs()), 1.0, 2.0, 0.5);
  const Eigen::Isometry3d root = poser.RootPose(s);
  EXPECT_NEAR(root.translation().x(), 1.0, 1e-12);
  EXPECT_NEAR(root.translation().y(), 2.0, 1e-12);
  EXPECT_NEAR(root.translation().z(), bare.roots().front().pose_in_world.translation.z(), 1e-12);
  EXPECT_NEAR(Yaw(root), 0.5, 1e-12);
}

TEST(StatePoser, RecoversATiltedRootFromAControlFramePose) {
  const RobotModel m = Pioneer();
  ASSERT_FALSE(m.frames().empty());
  Eigen::VectorXd q = Eigen::VectorXd::Zero(m.num_dofs());
  q[m.dof_offset(m.JointIndex("pan"))] = 0.4;
  q[m.dof_offset(m.JointIndex("tilt"))] = -0.2;
  Eigen::Isometry3d truth = Eigen::Isometry3d::Identity();
  truth.translation() << 0.7, -0.3, 0.21;
  truth.linear() =
      (Eigen::AngleAxisd(1.1, Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(0.05, Eigen::Vector3d::UnitY()))
          .toRotationMatrix();
  Kinematics kin(m);
  std::vector<Eigen::Isometry3d> roots{truth};
  kin.Update(q, roots);
  auto s = SampleFor(m, q, truth.translation().x(), truth.translation().y(), Yaw(truth));
  for (size_t f = 0; f < m.frames().size(); ++f) {
    const Eigen::Isometry3d p = kin.frame_pose(static_cast<int>(f));
    const Eigen::Quaterniond r(p.linear());
    s.frame_poses.push_back(
        {p.translation().x(), p.translation().y(), p.translation().z(), r.w(), r.x(), r.y(), r.z()});
  }
  StatePoser poser(m);
  const Eigen::Isometry3d root = poser.RootPose(s);
  EXPECT_TRUE(root.isApprox(truth, 1e-9)) << root.matrix() << "\nvs\n" << truth.matrix();
  // Every link pose on the page is the project's forward kinematics of the sample.
  const nlohmann::json j = poser.Pose(s);
  EXPECT_EQ(j["sample"], 7);
  EXPECT_DOUBLE_EQ(j["t"].get<double>(), 1.5);
  ASSERT_EQ(j["links"].size(), m.links().size());
  for (size_t l = 0; l < m.links().size(); ++l) {
    const Eigen::Vector3d p = kin.link_pose(static_cast<int>(l)).translation();
    for (int i = 0; i < 3; ++i) EXPECT_NEAR(j["links"][l][static_cast<size_t>(i)].get<double>(), p[i], 1e-6);
  }
}

TEST(StatePoser, RefusesASampleWithTheWrongNumberOfDofs) {
  const RobotModel m = Pioneer();
  StatePoser poser(m);
  auto s = SampleFor(m, Eigen::VectorXd::Zero(m.num_dofs()), 0, 0, 0);
  s.positions.pop_back();
  EXPECT_THROW(poser.Pose(s), ProtocolError);
}

TEST(DofNames, NamesEachDofOfAMultiDofJointWithItsIndex) {
  RobotModelBuilder b("u");
  b.AddLink({.name = "a", .mass = 1, .inertia = Eigen::Matrix3d::Identity()});
  b.AddLink({.name = "b", .mass = 1, .inertia = Eigen::Matrix3d::Identity()});
  Joint u{.name = "wrist"};
  u.dofs = {Dof{.axis = Eigen::Vector3d::UnitX()}, Dof{.axis = Eigen::Vector3d::UnitY()}};
  b.AddJoint(u, "a", "b");
  b.SetRoot("a", Pose{});
  EXPECT_EQ(DofNames(b.Build()), (std::vector<std::string>{"wrist/0", "wrist/1"}));
}

}  // namespace
}  // namespace robotalk::web
