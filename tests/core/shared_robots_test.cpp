// Every robot description in ../shared/robots imports and matches the counts
// of ../shared/robots/SOURCES.md; the project's own demo robot imports cleanly.
#include "robotalk/urdf_import.h"

#include "robotalk/error.h"
#include "test_paths.h"

#include <gtest/gtest.h>

#include <cctype>
#include <ostream>

namespace robotalk {
namespace {

using testing::ProjectModel;
using testing::SharedRobot;

// SOURCES.md's columns, joints counted by what they become: revolute and
// continuous give one revolute dof, prismatic one prismatic dof, fixed none,
// planar 3 and floating 6. SOURCES.md rounds masses to grams; these are the
// exact sums of the files' <mass> values.
struct SharedRobotCase {
  const char* file;
  size_t links;
  int revolute;  // revolute + continuous
  int prismatic;
  int fixed;
  int floating;
  int planar;
  const char* root;
  double mass;
};

std::ostream& operator<<(std::ostream& os, const SharedRobotCase& c) { return os << c.file; }

const SharedRobotCase kSharedRobots[] = {
    {"pioneer3dx.urdf", 11, 4, 0, 6, 0, 0, "base_link", 4.7402},
    {"pioneer_lx_ptu_jaco2.urdf", 39, 20, 0, 18, 0, 0, "base_link", 60.0},
    {"fanuc_m10ia.urdf", 9, 6, 0, 2, 0, 0, "base_link", 0.0},
    {"iiwa14.urdf", 11, 7, 0, 3, 0, 0, "base", 30.61},
    {"ur5.urdf", 11, 6, 0, 4, 0, 0, "world", 20.9939},
    {"atlas.urdf", 60, 30, 0, 29, 0, 0, "pelvis", 175.117964},
    {"romeo.urdf", 82, 55, 0, 26, 0, 0, "base_link", 40.52937},
    {"pr2.urdf", 82, 29, 1, 51, 0, 0, "base_footprint", 257.164323},
    {"full_robot_all_joint_types.urdf", 7, 2, 1, 1, 1, 1, "base_link", 13.5},
};

class SharedRobots : public ::testing::TestWithParam<SharedRobotCase> {};

TEST_P(SharedRobots, LoadsAndMatchesTheCountsOfSources) {
  ROBOTALK_REQUIRE_SHARED_ROBOTS();
  const SharedRobotCase& c = GetParam();
  const UrdfImportResult r = LoadUrdfFile(SharedRobot(c.file));
  const RobotModel& m = r.model;
  EXPECT_EQ(m.links().size(), c.links);
  int revolute = 0, prismatic = 0, fixed = 0, floating = 0, planar = 0;
  for (const Joint& j : m.joints()) {
    switch (j.dofs.size()) {
      case 0:
        ++fixed;
        break;
      case 1:
        ++(j.dofs[0].type == DofType::kRevolute ? revolute : prismatic);
        break;
      case 3:
        ++planar;
        break;
      case 6:
        ++floating;
        break;
      default:
        ADD_FAILURE() << "joint '" << j.name << "' has " << j.dofs.size() << " dofs";
    }
  }
  EXPECT_EQ(revolute, c.revolute);
  EXPECT_EQ(prismatic, c.prismatic);
  EXPECT_EQ(fixed, c.fixed);
  EXPECT_EQ(floating, c.floating);
  EXPECT_EQ(planar, c.planar);
  EXPECT_EQ(m.joints().size(), m.links().size() - 1);
  ASSERT_EQ(m.roots().size(), 1u);
  EXPECT_EQ(m.link(m.roots()[0].link).name, c.root);
  EXPECT_EQ(m.roots()[0].base, BaseType::kFixed);
  EXPECT_NEAR(m.total_mass(), c.mass, 1e-6);
}

TEST_P(SharedRobots, LoadsWithMergedChainsKeepingEveryDof) {
  ROBOTALK_REQUIRE_SHARED_ROBOTS();
  const SharedRobotCase& c = GetParam();
  const UrdfImportResult plain = LoadUrdfFile(SharedRobot(c.file));
  const UrdfImportResult merged = LoadUrdfFile(SharedRobot(c.file), {.merge_massless_chains = true});
  EXPECT_EQ(merged.model.num_dofs(), plain.model.num_dofs());
  EXPECT_NEAR(merged.model.total_mass(), plain.model.total_mass(), 1e-9);
}

INSTANTIATE_TEST_SUITE_P(Sources, SharedRobots, ::testing::ValuesIn(kSharedRobots),
                         [](const ::testing::TestParamInfo<SharedRobotCase>& info) {
                           std::string name = info.param.file;
                           name = name.substr(0, name.find('.'));
                           for (char& ch : name) {
                             if (!std::isalnum(static_cast<unsigned char>(ch))) ch = '_';
                           }
                           return name;
                         });

bool HasWarning(const UrdfImportResult& r, const std::string& part) {
  for (const std::string& w : r.warnings) {
    if (w.find(part) != std::string::npos) return true;
  }
  return false;
}

TEST(SharedRobot, PioneerLxPtuPanGetsItsInvertedLimitsSwappedWithAWarning) {
  ROBOTALK_REQUIRE_SHARED_ROBOTS();
  const UrdfImportResult r = LoadUrdfFile(SharedRobot("pioneer_lx_ptu_jaco2.urdf"));
  EXPECT_TRUE(HasWarning(r, "joint 'ptu_pan': lower limit 2.775 > upper -2.775; swapped"));
  const DofLimits& l = r.model.joint(r.model.JointIndex("ptu_pan")).dofs.at(0).limits;
  EXPECT_EQ(l.lower, -2.775);
  EXPECT_EQ(l.upper, 2.775);
}

TEST(SharedRobot, StrictModeRefusesPioneerLxNamingPtuPan) {
  ROBOTALK_REQUIRE_SHARED_ROBOTS();
  try {
    LoadUrdfFile(SharedRobot("pioneer_lx_ptu_jaco2.urdf"), {.strict = true});
    FAIL() << "strict import accepted pioneer_lx";
  } catch (const UrdfError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("pioneer_lx_ptu_jaco2.urdf: strict import refuses"), std::string::npos) << message;
    EXPECT_NE(message.find("'ptu_pan'"), std::string::npos) << message;
  }
}

TEST(SharedRobot, Pioneer3dxWithLegacyTagsLoadsWithoutWarnings) {
  ROBOTALK_REQUIRE_SHARED_ROBOTS();
  const UrdfImportResult r = LoadUrdfFile(SharedRobot("pioneer3dx.urdf"));
  EXPECT_TRUE(r.warnings.empty());
  EXPECT_EQ(r.model.num_dofs(), 4);
}

TEST(SharedRobot, Pr2KeepsItsTenGripperMimics) {
  ROBOTALK_REQUIRE_SHARED_ROBOTS();
  const UrdfImportResult r = LoadUrdfFile(SharedRobot("pr2.urdf"));
  int mimics = 0;
  for (const Joint& j : r.model.joints()) {
    if (!j.mimic) continue;
    ++mimics;
    EXPECT_TRUE(j.servo_types.empty()) << j.name;
  }
  EXPECT_EQ(mimics, 10);
}

TEST(SharedRobot, RomeoKeepsItsTwentyTwoFingerMimics) {
  ROBOTALK_REQUIRE_SHARED_ROBOTS();
  const UrdfImportResult r = LoadUrdfFile(SharedRobot("romeo.urdf"));
  int mimics = 0;
  for (const Joint& j : r.model.joints()) mimics += j.mimic ? 1 : 0;
  EXPECT_EQ(mimics, 22);
}

TEST(SharedRobot, FullRobotDropsTheMimicOnItsPlanarJoint) {
  ROBOTALK_REQUIRE_SHARED_ROBOTS();
  const UrdfImportResult r = LoadUrdfFile(SharedRobot("full_robot_all_joint_types.urdf"));
  EXPECT_TRUE(HasWarning(r, "mimic dropped"));
  for (const Joint& j : r.model.joints()) EXPECT_FALSE(j.mimic.has_value()) << j.name;
}

// --- the project's own demo robot ------------------------------------------

TEST(DemoRobot, Pioneer2dxPanTiltLoadsStrictlyWithoutWarnings) {
  const UrdfImportResult r = LoadUrdfFile(ProjectModel("pioneer2dx_pantilt.urdf"), {.strict = true});
  const RobotModel& m = r.model;
  EXPECT_TRUE(r.warnings.empty());
  EXPECT_EQ(m.name(), "pioneer2dx_pantilt");
  ASSERT_EQ(m.roots().size(), 1u);
  EXPECT_EQ(m.link(m.roots()[0].link).name, "base_link");
  EXPECT_EQ(m.roots()[0].base, BaseType::kDifferential);
  const ControlFrame& camera = m.frame(m.FrameIndex("camera"));
  EXPECT_EQ(camera.parent_link, m.LinkIndex("tilt_link"));
  EXPECT_EQ(m.num_dofs(), 4);
  const Joint& wheel = m.joint(m.JointIndex("left_wheel_joint"));
  EXPECT_EQ(wheel.dofs.at(0).limits.upper, DofLimits::kInf);
  EXPECT_EQ(wheel.servo_types, ServoTypes(ServoType::kSpeed));
  const DofLimits& pan = m.joint(m.JointIndex("pan")).dofs.at(0).limits;
  EXPECT_NEAR(pan.upper, 159.0 * 3.14159265358979 / 180.0, 1e-3);
}

TEST(DemoRobot, Pioneer2dxPanTiltHeadMergesIntoOneTwoDofJoint) {
  const UrdfImportResult r =
      LoadUrdfFile(ProjectModel("pioneer2dx_pantilt.urdf"), {.strict = true, .merge_massless_chains = true});
  const RobotModel& m = r.model;
  const Joint& head = m.joint(m.JointIndex("pan+tilt"));
  ASSERT_EQ(head.dofs.size(), 2u);
  EXPECT_EQ(head.dofs[0].axis, Eigen::Vector3d::UnitZ());
  EXPECT_EQ(head.dofs[1].axis, -Eigen::Vector3d::UnitY());
  EXPECT_EQ(m.link(head.parent_link).name, "ptu_base");
  EXPECT_EQ(m.link(head.child_link).name, "tilt_link");
  EXPECT_FALSE(m.FindLink("pan_link").has_value());
  EXPECT_EQ(head.servo_types, ServoTypes(ServoType::kSetPoint) | ServoType::kSpeed);
  EXPECT_EQ(m.num_dofs(), 4);
}

}  // namespace
}  // namespace robotalk
