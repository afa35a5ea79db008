// URDF import from inline XML: every joint type, the frame conventions, the
// <robotalk> block, mimic handling, massless-chain merging and the defect
// policy of docs/urdf_import.md.
#include "robotalk/urdf_import.h"

#include "robotalk/error.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

namespace robotalk {
namespace {

using std::numbers::pi;

std::string Robot(const std::string& body) { return "<robot name=\"r\">" + body + "</robot>"; }

std::string Links(std::initializer_list<const char*> names) {
  std::string s;
  for (const char* n : names) s += std::string("<link name=\"") + n + "\"/>";
  return s;
}

std::string JointXml(const std::string& name, const std::string& type, const std::string& parent,
                     const std::string& child, const std::string& extra = "") {
  return "<joint name=\"" + name + "\" type=\"" + type + "\"><parent link=\"" + parent +
         "\"/><child link=\"" + child + "\"/>" + extra + "</joint>";
}

const std::string kLimit = "<limit lower=\"-1\" upper=\"2\" effort=\"3\" velocity=\"4\"/>";

std::string TwoLinks(const std::string& type, const std::string& extra) {
  return Robot(Links({"a", "b"}) + JointXml("j", type, "a", "b", extra));
}

UrdfImportResult Import(const std::string& xml, UrdfImportOptions options = {}) {
  return ParseUrdf(xml, options, "test.urdf");
}

// The UrdfError message of importing `xml`, or "" when it imports.
std::string ErrorOf(const std::string& xml, UrdfImportOptions options = {}) {
  try {
    Import(xml, options);
  } catch (const UrdfError& e) {
    return e.what();
  }
  return "";
}

bool HasWarning(const UrdfImportResult& r, const std::string& part) {
  for (const std::string& w : r.warnings) {
    if (w.find(part) != std::string::npos) return true;
  }
  return false;
}

#define EXPECT_REFUSED(xml, part)                                           \
  do {                                                                      \
    const std::string message_ = ErrorOf(xml);                              \
    EXPECT_NE(message_.find("test.urdf: "), std::string::npos) << message_; \
    EXPECT_NE(message_.find(part), std::string::npos) << message_;          \
  } while (0)

// X_parent_child(q) as model_types.h defines it.
Eigen::Isometry3d JointTransform(const RobotModel& m, const Joint& j, const std::vector<double>& q) {
  Eigen::Isometry3d x = Eigen::Isometry3d::Identity();
  x.translate(m.link(j.parent_link).com + j.inboard);
  x.rotate(j.rest);
  for (size_t k = 0; k < j.dofs.size(); ++k) {
    if (j.dofs[k].type == DofType::kRevolute) {
      x.rotate(Eigen::AngleAxisd(q[k], j.dofs[k].axis));
    } else {
      x.translate(q[k] * j.dofs[k].axis);
    }
  }
  x.translate(-(m.link(j.child_link).com + j.outboard));
  return x;
}

// --- joint types and conventions -------------------------------------------

TEST(UrdfImport, KeepsTheFileOrderOfLinksAndJoints) {
  const auto r =
      Import(Robot(Links({"zeta", "alpha", "mid"}) + JointXml("z_joint", "fixed", "zeta", "alpha") +
                   JointXml("a_joint", "fixed", "zeta", "mid")));
  ASSERT_EQ(r.model.links().size(), 3u);
  EXPECT_EQ(r.model.link(0).name, "zeta");
  EXPECT_EQ(r.model.link(1).name, "alpha");
  EXPECT_EQ(r.model.link(2).name, "mid");
  EXPECT_EQ(r.model.joint(0).name, "z_joint");
  EXPECT_EQ(r.model.joint(1).name, "a_joint");
  EXPECT_TRUE(r.warnings.empty());
}

TEST(UrdfImport, ConvertsARevoluteJointToOneRevoluteDof) {
  const auto r =
      Import(TwoLinks("revolute", "<origin xyz=\"1 2 3\" rpy=\"0 0 1.5\"/><axis xyz=\"0 1 0\"/>" + kLimit));
  const Joint& j = r.model.joint(0);
  ASSERT_EQ(j.dofs.size(), 1u);
  EXPECT_EQ(j.dofs[0].type, DofType::kRevolute);
  EXPECT_EQ(j.dofs[0].axis, Eigen::Vector3d::UnitY());
  EXPECT_EQ(j.dofs[0].limits, (DofLimits{.lower = -1, .upper = 2, .velocity = 4, .effort = 3}));
  EXPECT_TRUE(j.rest.isApprox(Eigen::Quaterniond(Eigen::AngleAxisd(1.5, Eigen::Vector3d::UnitZ()))));
  EXPECT_EQ(j.inboard, Eigen::Vector3d(1, 2, 3));
  EXPECT_EQ(j.servo_types, ServoTypes(ServoType::kSetPoint) | ServoType::kSpeed | ServoType::kForce);
  EXPECT_TRUE(r.warnings.empty());
}

TEST(UrdfImport, GivesAContinuousJointInfinitePositionLimits) {
  const auto r = Import(TwoLinks("continuous", "<limit effort=\"3\" velocity=\"4\"/>"));
  const DofLimits& l = r.model.joint(0).dofs.at(0).limits;
  EXPECT_EQ(l.lower, -DofLimits::kInf);
  EXPECT_EQ(l.upper, DofLimits::kInf);
  EXPECT_EQ(l.velocity, 4);
  EXPECT_EQ(l.effort, 3);
  EXPECT_TRUE(r.warnings.empty());
}

TEST(UrdfImport, ConvertsAPrismaticJointToOnePrismaticDof) {
  const auto r = Import(TwoLinks("prismatic", "<axis xyz=\"0 0 1\"/>" + kLimit));
  const Joint& j = r.model.joint(0);
  ASSERT_EQ(j.dofs.size(), 1u);
  EXPECT_EQ(j.dofs[0].type, DofType::kPrismatic);
  EXPECT_EQ(j.dofs[0].axis, Eigen::Vector3d::UnitZ());
}

TEST(UrdfImport, GivesAFixedJointNoDofsAndNoServoTypes) {
  const auto r = Import(TwoLinks("fixed", "<origin xyz=\"0 0 1\"/>"));
  EXPECT_TRUE(r.model.joint(0).dofs.empty());
  EXPECT_TRUE(r.model.joint(0).servo_types.empty());
}

TEST(UrdfImport, ConvertsAPlanarJointToTwoPrismaticDofsAndOneRevolute) {
  const auto r = Import(TwoLinks("planar", "<axis xyz=\"0 0 1\"/>"));
  const Joint& j = r.model.joint(0);
  ASSERT_EQ(j.dofs.size(), 3u);
  EXPECT_EQ(j.dofs[0].type, DofType::kPrismatic);
  EXPECT_EQ(j.dofs[0].axis, Eigen::Vector3d::UnitX());
  EXPECT_EQ(j.dofs[1].type, DofType::kPrismatic);
  EXPECT_EQ(j.dofs[1].axis, Eigen::Vector3d::UnitY());
  EXPECT_EQ(j.dofs[2].type, DofType::kRevolute);
  EXPECT_EQ(j.dofs[2].axis, Eigen::Vector3d::UnitZ());
  EXPECT_EQ(j.dofs[0].limits, DofLimits{});
}

TEST(UrdfImport, SpansThePlaneNormalToAnObliquePlanarAxis) {
  const auto r = Import(TwoLinks("planar", "<axis xyz=\"1 1 0\"/>"));
  const Joint& j = r.model.joint(0);
  const Eigen::Vector3d n = Eigen::Vector3d(1, 1, 0).normalized();
  EXPECT_NEAR(j.dofs[0].axis.dot(n), 0, 1e-12);
  EXPECT_NEAR(j.dofs[1].axis.dot(n), 0, 1e-12);
  EXPECT_NEAR(j.dofs[0].axis.dot(j.dofs[1].axis), 0, 1e-12);
  EXPECT_TRUE(j.dofs[2].axis.isApprox(n));
  EXPECT_TRUE(HasWarning(r, "normalised"));
}

TEST(UrdfImport, ConvertsAFloatingJointToThreeTranslationsThenThreeRotations) {
  const auto r = Import(TwoLinks("floating", ""));
  const Joint& j = r.model.joint(0);
  ASSERT_EQ(j.dofs.size(), 6u);
  for (int k = 0; k < 6; ++k) {
    EXPECT_EQ(j.dofs[static_cast<size_t>(k)].type, k < 3 ? DofType::kPrismatic : DofType::kRevolute);
    EXPECT_EQ(j.dofs[static_cast<size_t>(k)].axis, Eigen::Vector3d::Unit(k % 3));
  }
  EXPECT_EQ(j.servo_types, ServoTypes(ServoType::kSetPoint) | ServoType::kSpeed);
  EXPECT_TRUE(r.warnings.empty());
}

TEST(UrdfImport, RotatesTheInertiaIntoLinkAxesAndKeepsItSymmetric) {
  const auto r = Import(
      Robot("<link name=\"a\"><inertial><origin xyz=\"0.1 0.2 0.3\" rpy=\"0 0 1.5707963267948966\"/><mass "
            "value=\"2\"/>"
            "<inertia ixx=\"1\" ixy=\"0.1\" ixz=\"0\" iyy=\"2\" iyz=\"0\" izz=\"3\"/></inertial></link>"));
  const Link& l = r.model.link(0);
  EXPECT_EQ(l.mass, 2);
  EXPECT_EQ(l.com, Eigen::Vector3d(0.1, 0.2, 0.3));
  EXPECT_EQ(l.inertia, l.inertia.transpose());
  Eigen::Matrix3d expected;  // a quarter turn about z swaps x and y
  expected << 2, -0.1, 0, -0.1, 1, 0, 0, 0, 3;
  EXPECT_TRUE(l.inertia.isApprox(expected, 1e-12)) << l.inertia;
}

TEST(UrdfImport, PlacesJointsRelativeToTheCentresOfMass) {
  const auto r = Import(
      Robot("<link name=\"a\"><inertial><origin xyz=\"0.1 0 0\"/><mass value=\"1\"/>"
            "<inertia ixx=\"1\" ixy=\"0\" ixz=\"0\" iyy=\"1\" iyz=\"0\" izz=\"1\"/></inertial></link>"
            "<link name=\"b\"><inertial><origin xyz=\"0 0 0.5\"/><mass value=\"1\"/>"
            "<inertia ixx=\"1\" ixy=\"0\" ixz=\"0\" iyy=\"1\" iyz=\"0\" izz=\"1\"/></inertial></link>" +
            JointXml("j", "revolute", "a", "b", "<origin xyz=\"1 0 0\" rpy=\"0.3 0 0\"/>" + kLimit)));
  const Joint& j = r.model.joint(0);
  EXPECT_TRUE(j.inboard.isApprox(Eigen::Vector3d(0.9, 0, 0)));
  EXPECT_EQ(j.outboard, Eigen::Vector3d(0, 0, -0.5));
  // The child's link frame sits at the joint: X(0) maps the child origin to the joint origin.
  const Eigen::Isometry3d x = JointTransform(r.model, j, {0.0});
  EXPECT_TRUE(x.translation().isApprox(Eigen::Vector3d(1, 0, 0)));
}

TEST(UrdfImport, TreatsAMissingInertialAsAMasslessLinkWithoutWarning) {
  const auto r = Import(TwoLinks("fixed", ""));
  EXPECT_EQ(r.model.link(0).mass, 0);
  EXPECT_EQ(r.model.link(0).inertia, Eigen::Matrix3d::Zero());
  EXPECT_TRUE(r.warnings.empty());
}

TEST(UrdfImport, ReplacesTheRobotNameWhenAsked) {
  EXPECT_EQ(Import(TwoLinks("fixed", ""), {.robot_name = "other"}).model.name(), "other");
  EXPECT_EQ(Import(TwoLinks("fixed", "")).model.name(), "r");
}

// --- repaired defects -------------------------------------------------------

TEST(UrdfImport, SwapsInvertedLimitsWithAWarning) {
  const auto r =
      Import(TwoLinks("revolute", "<limit lower=\"2.775\" upper=\"-2.775\" effort=\"1\" velocity=\"1\"/>"));
  EXPECT_EQ(r.model.joint(0).dofs[0].limits.lower, -2.775);
  EXPECT_EQ(r.model.joint(0).dofs[0].limits.upper, 2.775);
  EXPECT_TRUE(HasWarning(r, "joint 'j': lower limit 2.775 > upper -2.775; swapped"));
}

TEST(UrdfImport, NormalisesANonUnitAxisWithAWarning) {
  const auto r = Import(TwoLinks("revolute", "<axis xyz=\"0 0 2\"/>" + kLimit));
  EXPECT_EQ(r.model.joint(0).dofs[0].axis, Eigen::Vector3d::UnitZ());
  EXPECT_TRUE(HasWarning(r, "joint 'j': axis (0 0 2) is not a unit vector"));
}

TEST(UrdfImport, NormalisesANearlyUnitAxisSilently) {
  const auto r = Import(TwoLinks("revolute", "<axis xyz=\"0 0.7071067 0.7071067\"/>" + kLimit));
  EXPECT_NEAR(r.model.joint(0).dofs[0].axis.norm(), 1, 1e-15);
  EXPECT_TRUE(r.warnings.empty());
}

TEST(UrdfImport, IgnoresLimitsOnAFixedJointWithAWarning) {
  const auto r = Import(TwoLinks("fixed", "<limit lower=\"0\" upper=\"0\" effort=\"0\" velocity=\"0\"/>"));
  EXPECT_TRUE(r.model.joint(0).dofs.empty());
  EXPECT_TRUE(HasWarning(r, "joint 'j': <limit> on a fixed joint ignored"));
}

TEST(UrdfImport, IgnoresLowerAndUpperOnAContinuousJointWithAWarning) {
  const auto r =
      Import(TwoLinks("continuous", "<limit lower=\"-6.28\" upper=\"6.28\" effort=\"1\" velocity=\"1\"/>"));
  EXPECT_EQ(r.model.joint(0).dofs[0].limits.upper, DofLimits::kInf);
  EXPECT_TRUE(HasWarning(r, "joint 'j': lower/upper limits on a continuous joint ignored"));
}

TEST(UrdfImport, TakesZeroVelocityAndEffortAsUnlimitedWithAWarning) {
  const auto r =
      Import(TwoLinks("revolute", "<limit lower=\"-1\" upper=\"1\" effort=\"0\" velocity=\"0\"/>"));
  const DofLimits& l = r.model.joint(0).dofs[0].limits;
  EXPECT_EQ(l.velocity, DofLimits::kInf);
  EXPECT_EQ(l.effort, DofLimits::kInf);
  EXPECT_TRUE(HasWarning(r, "joint 'j': velocity limit 0"));
  EXPECT_TRUE(HasWarning(r, "joint 'j': effort limit 0"));
  // Without a known effort bound the joint takes no force commands.
  EXPECT_EQ(r.model.joint(0).servo_types, ServoTypes(ServoType::kSetPoint) | ServoType::kSpeed);
}

TEST(UrdfImport, WarnsWhenAContinuousJointHasNoLimit) {
  const auto r = Import(TwoLinks("continuous", ""));
  EXPECT_EQ(r.model.joint(0).dofs[0].limits, DofLimits{});
  EXPECT_TRUE(HasWarning(r, "joint 'j': no <limit>"));
}

TEST(UrdfImport, WarnsWhenALimitLacksLowerOrUpper) {
  const auto r = Import(TwoLinks("revolute", "<limit upper=\"1\" effort=\"1\" velocity=\"1\"/>"));
  EXPECT_EQ(r.model.joint(0).dofs[0].limits.lower, 0);
  EXPECT_TRUE(HasWarning(r, "joint 'j': <limit> lacks lower"));
}

// --- refused files ----------------------------------------------------------

TEST(UrdfImport, RefusesAZeroAxis) {
  EXPECT_REFUSED(TwoLinks("revolute", "<axis xyz=\"0 0 0\"/>" + kLimit), "joint 'j': zero axis");
}

TEST(UrdfImport, RefusesNegativeMass) {
  EXPECT_REFUSED(
      Robot("<link name=\"heavy\"><inertial><mass value=\"-1\"/>"
            "<inertia ixx=\"1\" ixy=\"0\" ixz=\"0\" iyy=\"1\" iyz=\"0\" izz=\"1\"/></inertial></link>"),
      "link 'heavy': negative mass -1 kg");
}

TEST(UrdfImport, RefusesAMassiveLinkWithANonPositiveDefiniteInertia) {
  EXPECT_REFUSED(
      Robot("<link name=\"flat\"><inertial><mass value=\"1\"/>"
            "<inertia ixx=\"1\" ixy=\"0\" ixz=\"0\" iyy=\"1\" iyz=\"0\" izz=\"0\"/></inertial></link>"),
      "link 'flat': mass 1 kg but the inertia is not positive-definite");
}

TEST(UrdfImport, AcceptsAMasslessLinkWithAZeroInertia) {
  const auto r = Import(
      Robot("<link name=\"frame\"><inertial><mass value=\"0\"/>"
            "<inertia ixx=\"0\" ixy=\"0\" ixz=\"0\" iyy=\"0\" iyz=\"0\" izz=\"0\"/></inertial></link>"));
  EXPECT_TRUE(r.warnings.empty());
}

TEST(UrdfImport, RefusesALinkWithTwoParentJoints) {
  // urdfdom accepts this file and builds a tree whose walk never ends.
  EXPECT_REFUSED(Robot(Links({"a", "b", "c"}) + JointXml("ab", "fixed", "a", "b") +
                       JointXml("bc", "fixed", "b", "c") + JointXml("cb", "fixed", "c", "b")),
                 "link 'b' has two parent joints, 'ab' and 'cb'");
}

TEST(UrdfImport, RefusesACycle) {
  EXPECT_REFUSED(Robot(Links({"root", "b", "c"}) + JointXml("bc", "fixed", "b", "c") +
                       JointXml("cb", "fixed", "c", "b")),
                 "cycle through links 'b' <- 'c' <- 'b'");
}

TEST(UrdfImport, RefusesDuplicateLinkNames) {
  EXPECT_REFUSED(Robot(Links({"a", "a"})), "duplicate link name 'a'");
}

// Review 13: an XML character reference puts a control character in a name
// (urdfdom takes &#x1b;): refused, named escaped, as RobotModel refuses it.
TEST(UrdfImport, RefusesANameWithATerminalEscape) {
  EXPECT_REFUSED(Robot(Links({"a", "b"}) + JointXml("j&#x1b;]0;owned&#x7;", "fixed", "a", "b")),
                 "joint name 'j\\x1b]0;owned\\x07'");
}

TEST(UrdfImport, RefusesDuplicateJointNames) {
  EXPECT_REFUSED(
      Robot(Links({"a", "b", "c"}) + JointXml("j", "fixed", "a", "b") + JointXml("j", "fixed", "a", "c")),
      "duplicate joint name 'j'");
}

TEST(UrdfImport, RefusesAJointNamingAnUnknownLink) {
  EXPECT_REFUSED(Robot(Links({"a"}) + JointXml("j", "fixed", "a", "ghost")),
                 "joint 'j' (line 1): unknown child link 'ghost'");
}

TEST(UrdfImport, RefusesMalformedXmlWithItsLine) {
  EXPECT_REFUSED("<robot name=\"r\">\n<link name=\"a\">\n</robot>", "malformed XML at line");
}

TEST(UrdfImport, RefusesADocumentWithoutRobot) {
  EXPECT_REFUSED("<model name=\"r\"/>", "the root element is <model>, not <robot>");
}

TEST(UrdfImport, SaysWhatUrdfdomComplainedAboutAndKeepsStderrQuiet) {
  ::testing::internal::CaptureStderr();
  const std::string message = ErrorOf(TwoLinks("revolute", ""));
  const std::string err = ::testing::internal::GetCapturedStderr();
  EXPECT_NE(
      message.find("urdfdom rejected the file: Joint [j] is of type REVOLUTE but it does not specify limits"),
      std::string::npos)
      << message;
  EXPECT_EQ(err, "");
}

TEST(UrdfImport, RefusesAnInertialThatUrdfdomDropsWithAnError) {
  EXPECT_REFUSED(Robot("<link name=\"a\"><inertial><mass value=\"1\"/></inertial></link>"), "Link [a]");
}

TEST(UrdfImport, RefusesAMissingFile) {
  try {
    LoadUrdfFile("/nonexistent/robot.urdf");
    FAIL() << "no error";
  } catch (const UrdfError& e) {
    EXPECT_EQ(std::string(e.what()), "LoadUrdfFile: cannot open '/nonexistent/robot.urdf'");
  }
}

// --- strict mode ------------------------------------------------------------

TEST(UrdfImport, StrictModeTurnsEveryWarningIntoOneError) {
  const std::string xml = Robot(
      Links({"a", "b", "c"}) +
      JointXml("j", "revolute", "a", "b", "<limit lower=\"1\" upper=\"0\" effort=\"1\" velocity=\"1\"/>") +
      JointXml("k", "fixed", "a", "c", kLimit));
  const std::string message = ErrorOf(xml, {.strict = true});
  EXPECT_NE(message.find("test.urdf: strict import refuses 2 warning(s)"), std::string::npos) << message;
  EXPECT_NE(message.find("joint 'j': lower limit 1 > upper 0; swapped"), std::string::npos) << message;
  EXPECT_NE(message.find("joint 'k': <limit> on a fixed joint ignored"), std::string::npos) << message;
  EXPECT_EQ(Import(xml).warnings.size(), 2u);
}

TEST(UrdfImport, StrictModeAcceptsACleanFile) {
  EXPECT_NO_THROW(Import(TwoLinks("revolute", kLimit), {.strict = true}));
}

// --- mimic joints -----------------------------------------------------------

TEST(UrdfImport, RecordsAMimicJointWithoutServoTypes) {
  const auto r = Import(Robot(Links({"a", "b", "c"}) + JointXml("lead", "revolute", "a", "b", kLimit) +
                              JointXml("follow", "revolute", "a", "c",
                                       kLimit + "<mimic joint=\"lead\" multiplier=\"-2\" offset=\"0.5\"/>")));
  const Joint& j = r.model.joint(1);
  ASSERT_TRUE(j.mimic.has_value());
  EXPECT_EQ(*j.mimic, (Mimic{.leader_joint = 0, .multiplier = -2, .offset = 0.5}));
  EXPECT_TRUE(j.servo_types.empty());
  EXPECT_TRUE(r.warnings.empty());
}

TEST(UrdfImport, DropsAMimicOfAFixedJointWithAWarning) {
  const auto r = Import(Robot(Links({"a", "b", "c"}) + JointXml("lead", "fixed", "a", "b") +
                              JointXml("follow", "revolute", "a", "c", kLimit + "<mimic joint=\"lead\"/>")));
  EXPECT_FALSE(r.model.joint(1).mimic.has_value());
  EXPECT_FALSE(r.model.joint(1).servo_types.empty());
  EXPECT_TRUE(HasWarning(r, "joint 'follow': mimic of 'lead' needs a 1-dof leader; it has 0; mimic dropped"));
}

TEST(UrdfImport, DropsAMimicOfAnUnknownJointWithAWarning) {
  const auto r = Import(TwoLinks("revolute", kLimit + "<mimic joint=\"nobody\"/>"));
  EXPECT_FALSE(r.model.joint(0).mimic.has_value());
  EXPECT_TRUE(HasWarning(r, "joint 'j': mimic of 'nobody' names an unknown joint"));
}

TEST(UrdfImport, DropsAMimicOnAPlanarJointWithAWarning) {
  const auto r = Import(Robot(Links({"a", "b", "c"}) + JointXml("lead", "revolute", "a", "b", kLimit) +
                              JointXml("plane", "planar", "a", "c", "<mimic joint=\"lead\"/>")));
  EXPECT_FALSE(r.model.joint(1).mimic.has_value());
  EXPECT_TRUE(HasWarning(r, "joint 'plane': mimic of 'lead' needs a 1-dof joint"));
}

TEST(UrdfImport, FlattensAChainOfMimicsOntoTheFirstLeader) {
  const auto r = Import(Robot(Links({"a", "b", "c", "d"}) + JointXml("lead", "revolute", "a", "b", kLimit) +
                              JointXml("mid", "revolute", "a", "c",
                                       kLimit + "<mimic joint=\"lead\" multiplier=\"2\" offset=\"1\"/>") +
                              JointXml("end", "revolute", "a", "d",
                                       kLimit + "<mimic joint=\"mid\" multiplier=\"3\" offset=\"0.5\"/>")));
  ASSERT_TRUE(r.model.joint(2).mimic.has_value());
  EXPECT_EQ(*r.model.joint(2).mimic, (Mimic{.leader_joint = 0, .multiplier = 6, .offset = 3.5}));
  EXPECT_TRUE(HasWarning(r, "joint 'end': mimics 'mid', itself a mimic of 'lead'"));
}

// --- the <robotalk> block ---------------------------------------------------

const std::string kPanTilt =
    Links({"base", "pan_link", "head"}) +
    JointXml("pan", "revolute", "base", "pan_link",
             "<origin xyz=\"0 0 0.3\"/><axis xyz=\"0 0 1\"/>" + kLimit) +
    JointXml("tilt", "revolute", "pan_link", "head",
             "<origin xyz=\"0 0 0\" rpy=\"0 0 0.4\"/><axis xyz=\"0 1 0\"/>" + kLimit);

TEST(UrdfImport, ReadsControlFramesServoTypesAndTheBaseFromTheRobotalkBlock) {
  const auto r =
      Import(Robot(kPanTilt +
                   "<robotalk version=\"1\">"
                   "<base link=\"base\" type=\"differential\"><origin xyz=\"1 2 0\" rpy=\"0 0 0.5\"/></base>"
                   "<control_frame name=\"camera\" link=\"head\" servo=\"setpoint speed\">"
                   "<origin xyz=\"0 0 0.05\" rpy=\"0 0 0\"/></control_frame>"
                   "<control_frame name=\"marker\" link=\"base\"/>"
                   "<servo joint=\"pan\" types=\"setpoint\"/>"
                   "</robotalk>"));
  const RobotModel& m = r.model;
  ASSERT_EQ(m.frames().size(), 2u);
  EXPECT_EQ(m.frame(0).name, "camera");
  EXPECT_EQ(m.frame(0).parent_link, m.LinkIndex("head"));
  EXPECT_EQ(m.frame(0).pose_in_link.translation, Eigen::Vector3d(0, 0, 0.05));
  EXPECT_EQ(m.frame(0).servo_types, ServoTypes(ServoType::kSetPoint) | ServoType::kSpeed);
  EXPECT_EQ(m.frame(1).servo_types, ServoTypes(ServoType::kSetPoint));
  EXPECT_EQ(m.joint(m.JointIndex("pan")).servo_types, ServoTypes(ServoType::kSetPoint));
  ASSERT_EQ(m.roots().size(), 1u);
  EXPECT_EQ(m.roots()[0].base, BaseType::kDifferential);
  EXPECT_EQ(m.roots()[0].pose_in_world.translation, Eigen::Vector3d(1, 2, 0));
  EXPECT_TRUE(m.roots()[0].pose_in_world.rotation.isApprox(
      Eigen::Quaterniond(Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitZ()))));
  EXPECT_TRUE(r.warnings.empty());
}

TEST(UrdfImport, MakesTheRootAFixedBaseWithoutARobotalkBlock) {
  const auto r = Import(Robot(kPanTilt));
  EXPECT_EQ(r.model.roots()[0].base, BaseType::kFixed);
  EXPECT_EQ(r.model.roots()[0].pose_in_world, Pose{});
  EXPECT_TRUE(r.model.frames().empty());
}

TEST(UrdfImport, RefusesAnUnknownElementInTheRobotalkBlock) {
  EXPECT_REFUSED(Robot(kPanTilt + "<robotalk><control_fram name=\"x\" link=\"head\"/></robotalk>"),
                 "unknown element <control_fram>");
}

TEST(UrdfImport, RefusesAnUnknownAttributeInTheRobotalkBlock) {
  EXPECT_REFUSED(Robot(kPanTilt + "<robotalk><servo joint=\"pan\" type=\"speed\"/></robotalk>"),
                 "unknown attribute 'type'");
  EXPECT_REFUSED(
      Robot(kPanTilt +
            "<robotalk><control_frame name=\"c\" link=\"head\"><origin xyz=\"0 0 0\" rpy=\"0 0 0\" "
            "quat=\"1 0 0 0\"/></control_frame></robotalk>"),
      "unknown attribute 'quat'");
}

TEST(UrdfImport, RefusesAControlFrameOnAnUnknownLink) {
  EXPECT_REFUSED(Robot(kPanTilt + "<robotalk><control_frame name=\"camera\" link=\"hed\"/></robotalk>"),
                 "<control_frame name='camera'> (line 1): unknown link 'hed'");
}

TEST(UrdfImport, RefusesServoTypesForAnUnknownJoint) {
  EXPECT_REFUSED(Robot(kPanTilt + "<robotalk><servo joint=\"pann\" types=\"speed\"/></robotalk>"),
                 "unknown joint 'pann'");
}

TEST(UrdfImport, RefusesAnUnknownServoType) {
  EXPECT_REFUSED(Robot(kPanTilt + "<robotalk><servo joint=\"pan\" types=\"setpoint warp\"/></robotalk>"),
                 "unknown servo type 'warp'");
}

TEST(UrdfImport, RefusesServoTypesOnAFixedJoint) {
  EXPECT_REFUSED(Robot(Links({"a", "b"}) + JointXml("weld", "fixed", "a", "b") +
                       "<robotalk><servo joint=\"weld\" types=\"speed\"/></robotalk>"),
                 "<servo joint='weld'> (line 1): a fixed joint takes no servo commands");
}

TEST(UrdfImport, RefusesABaseOnALinkThatIsNotTheRoot) {
  EXPECT_REFUSED(Robot(kPanTilt + "<robotalk><base link=\"head\" type=\"holonomic\"/></robotalk>"),
                 "<base link='head'> (line 1): not the root link (the root is 'base')");
  EXPECT_REFUSED(Robot(kPanTilt + "<robotalk><base link=\"nowhere\" type=\"holonomic\"/></robotalk>"),
                 "<base link='nowhere'> (line 1): unknown link");
}

TEST(UrdfImport, RefusesAnUnknownBaseType) {
  EXPECT_REFUSED(Robot(kPanTilt + "<robotalk><base type=\"legged\"/></robotalk>"),
                 "unknown base type 'legged'");
}

TEST(UrdfImport, RefusesMalformedNumbersInTheRobotalkBlock) {
  EXPECT_REFUSED(Robot(kPanTilt + "<robotalk><control_frame name=\"c\" link=\"head\"><origin xyz=\"0 0\"/>"
                                  "</control_frame></robotalk>"),
                 "xyz='0 0' (line 1) is not three finite numbers");
}

TEST(UrdfImport, RefusesTwoRobotalkBlocks) {
  EXPECT_REFUSED(Robot(kPanTilt + "<robotalk/><robotalk/>"), "more than one <robotalk> block");
}

// --- merging massless chains ------------------------------------------------

TEST(UrdfImport, MergesAPanTiltChainIntoOneTwoDofJoint) {
  const auto plain = Import(Robot(kPanTilt));
  const auto merged = Import(Robot(kPanTilt), {.merge_massless_chains = true});
  ASSERT_EQ(merged.model.joints().size(), 1u);
  ASSERT_EQ(merged.model.links().size(), 2u);
  EXPECT_FALSE(merged.model.FindLink("pan_link").has_value());
  const Joint& j = merged.model.joint(0);
  EXPECT_EQ(j.name, "pan+tilt");
  ASSERT_EQ(j.dofs.size(), 2u);
  EXPECT_EQ(j.dofs[1].axis, Eigen::Vector3d::UnitY());
  // Same motion of the head for any (pan, tilt).
  const RobotModel& p = plain.model;
  for (const auto& q : std::vector<std::vector<double>>{{0, 0}, {0.7, -0.3}, {-1.0, 1.9}}) {
    const Eigen::Isometry3d chained =
        JointTransform(p, p.joint(0), {q[0]}) * JointTransform(p, p.joint(1), {q[1]});
    const Eigen::Isometry3d one = JointTransform(merged.model, j, q);
    EXPECT_TRUE(one.isApprox(chained, 1e-12)) << one.matrix() << "\n" << chained.matrix();
  }
}

TEST(UrdfImport, MergesLongerChainsAndKeepsTheOtherJoints) {
  const auto r = Import(Robot(Links({"a", "m1", "m2", "tip", "side"}) +
                              JointXml("j1", "revolute", "a", "m1", "<origin xyz=\"0 0 1\"/>" + kLimit) +
                              JointXml("j2", "prismatic", "m1", "m2", "<axis xyz=\"1 0 0\"/>" + kLimit) +
                              JointXml("side", "fixed", "a", "side") +
                              JointXml("j3", "continuous", "m2", "tip",
                                       "<axis xyz=\"0 1 0\"/><limit effort=\"1\" velocity=\"1\"/>")),
                        {.merge_massless_chains = true});
  ASSERT_EQ(r.model.joints().size(), 2u);
  EXPECT_EQ(r.model.joint(0).name, "j1+j2+j3");
  EXPECT_EQ(r.model.joint(0).dofs.size(), 3u);
  EXPECT_EQ(r.model.joint(1).name, "side");
  EXPECT_EQ(r.model.links().size(), 3u);
}

TEST(UrdfImport, DoesNotMergeAcrossALinkWithMass) {
  const std::string xml = Robot(
      "<link name=\"base\"/><link name=\"pan_link\"><inertial><mass value=\"0.1\"/>"
      "<inertia ixx=\"1\" ixy=\"0\" ixz=\"0\" iyy=\"1\" iyz=\"0\" izz=\"1\"/></inertial></link><link "
      "name=\"head\"/>" +
      JointXml("pan", "revolute", "base", "pan_link", kLimit) +
      JointXml("tilt", "revolute", "pan_link", "head", kLimit));
  EXPECT_EQ(Import(xml, {.merge_massless_chains = true}).model.joints().size(), 2u);
}

TEST(UrdfImport, DoesNotMergeWhenTheSecondJointIsOffset) {
  const std::string xml =
      Robot(Links({"base", "pan_link", "head"}) + JointXml("pan", "revolute", "base", "pan_link", kLimit) +
            JointXml("tilt", "revolute", "pan_link", "head", "<origin xyz=\"0 0 0.1\"/>" + kLimit));
  EXPECT_EQ(Import(xml, {.merge_massless_chains = true}).model.joints().size(), 2u);
}

TEST(UrdfImport, DoesNotMergeAcrossALinkCarryingAControlFrame) {
  const std::string xml =
      Robot(kPanTilt + "<robotalk><control_frame name=\"f\" link=\"pan_link\"/></robotalk>");
  EXPECT_EQ(Import(xml, {.merge_massless_chains = true}).model.joints().size(), 2u);
}

TEST(UrdfImport, GivesAMergedJointTheServoTypesBothJointsAccept) {
  const auto r = Import(Robot(kPanTilt + "<robotalk><servo joint=\"pan\" types=\"setpoint speed\"/>"
                                         "<servo joint=\"tilt\" types=\"speed force\"/></robotalk>"),
                        {.merge_massless_chains = true});
  EXPECT_EQ(r.model.joint(0).servo_types, ServoTypes(ServoType::kSpeed));
}

}  // namespace
}  // namespace robotalk
