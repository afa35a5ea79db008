#include "robotalk/robot_model.h"
#include "robotalk/error.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>

namespace robotalk {
namespace {

using ::testing::HasSubstr;

Link Body(const std::string& name, double mass = 1.0) {
  Link link{.name = name, .mass = mass};
  link.inertia = Eigen::Matrix3d::Identity() * 0.01 * mass;
  return link;
}

Joint Revolute(const std::string& name, Eigen::Vector3d axis = Eigen::Vector3d::UnitZ()) {
  Joint j{.name = name};
  j.dofs.push_back(Dof{.type = DofType::kRevolute, .axis = axis, .limits = {-1, 1, 2, 10}});
  j.servo_types = ServoTypes::All();
  return j;
}

// base -> upper -> lower, with a tool frame on `lower`.
RobotModelBuilder TwoLinkArm() {
  RobotModelBuilder b("arm");
  b.AddLink(Body("base", 0)).AddLink(Body("upper")).AddLink(Body("lower"));
  b.AddJoint(Revolute("shoulder"), "base", "upper").AddJoint(Revolute("elbow"), "upper", "lower");
  b.AddControlFrame(ControlFrame{.name = "tool", .servo_types = ServoType::kSetPoint}, "lower");
  return b;
}

// Expects Build() to throw ModelError whose message contains every fragment.
template <typename... Fragments>
void ExpectModelError(const RobotModelBuilder& b, Fragments... fragments) {
  try {
    b.Build();
    ADD_FAILURE() << "Build() accepted an invalid model";
  } catch (const ModelError& e) {
    for (const char* fragment : {fragments...}) EXPECT_THAT(e.what(), HasSubstr(fragment));
  }
}

TEST(RobotModel, LooksUpElementsByNameAndIndex) {
  RobotModel m = TwoLinkArm().Build();
  EXPECT_EQ(m.name(), "arm");
  EXPECT_EQ(m.LinkIndex("lower"), 2);
  EXPECT_EQ(m.JointIndex("elbow"), 1);
  EXPECT_EQ(m.FrameIndex("tool"), 0);
  EXPECT_EQ(m.link(2).name, "lower");
  EXPECT_EQ(m.joint(1).name, "elbow");
  EXPECT_EQ(m.frame(0).parent_link, 2);
  EXPECT_EQ(m.FindJoint("wrist"), std::nullopt);
  EXPECT_THROW(m.JointIndex("wrist"), LookupError);
  EXPECT_THROW(m.link(3), LookupError);
  EXPECT_THROW(m.joint(-1), LookupError);
}

TEST(RobotModel, CountsDofsAndOffsetsInJointOrder) {
  RobotModelBuilder b = TwoLinkArm();
  Joint pan_tilt = Revolute("pan_tilt");
  pan_tilt.dofs.push_back(Dof{.type = DofType::kRevolute, .axis = Eigen::Vector3d::UnitY()});
  b.AddLink(Body("head")).AddJoint(pan_tilt, "base", "head");
  RobotModel m = b.Build();
  EXPECT_EQ(m.num_dofs(), 4);
  EXPECT_EQ(m.dof_offset(0), 0);
  EXPECT_EQ(m.dof_offset(1), 1);
  EXPECT_EQ(m.dof_offset(2), 2);
}

TEST(RobotModel, MakesEveryParentlessLinkAFixedRoot) {
  RobotModelBuilder b = TwoLinkArm();
  b.AddLink(Body("loose"));
  RobotModel m = b.Build();
  ASSERT_EQ(m.roots().size(), 2u);
  EXPECT_EQ(m.roots()[0].link, 0);
  EXPECT_EQ(m.roots()[1].link, 3);
  EXPECT_EQ(m.roots()[1].base, BaseType::kFixed);
  EXPECT_EQ(m.root_of(2), 0);
  EXPECT_EQ(m.parent_joint(0), -1);
  EXPECT_EQ(m.parent_joint(2), 1);
}

TEST(RobotModel, AFramesChainIsItsJointsUpToTheRootChildFirst) {
  RobotModelBuilder b = TwoLinkArm();
  b.AddLink(Body("loose"));
  b.AddControlFrame(ControlFrame{.name = "shoulder_plate", .servo_types = ServoType::kSetPoint}, "upper");
  b.AddControlFrame(ControlFrame{.name = "floor", .servo_types = ServoType::kSetPoint}, "loose");
  RobotModel m = b.Build();
  EXPECT_THAT(m.frame_chain(m.FrameIndex("tool")), ::testing::ElementsAre(1, 0));
  EXPECT_THAT(m.frame_chain(m.FrameIndex("shoulder_plate")), ::testing::ElementsAre(0));
  EXPECT_TRUE(m.frame_chain(m.FrameIndex("floor")).empty());
}

TEST(RobotModel, KeepsDeclaredRootPoseAndBaseType) {
  RobotModelBuilder b = TwoLinkArm();
  Pose pose{.translation = {1, 2, 0}, .rotation = Eigen::Quaterniond::Identity()};
  b.SetRoot("base", pose, BaseType::kDifferential);
  RobotModel m = b.Build();
  ASSERT_EQ(m.roots().size(), 1u);
  EXPECT_EQ(m.roots()[0].base, BaseType::kDifferential);
  EXPECT_EQ(m.roots()[0].pose_in_world, pose);
}

TEST(RobotModel, OrdersJointsParentsBeforeChildren) {
  // Declared child-first: the elbow comes before the shoulder.
  RobotModelBuilder b("arm");
  b.AddLink(Body("lower")).AddLink(Body("upper")).AddLink(Body("base", 0));
  b.AddJoint(Revolute("elbow"), "upper", "lower").AddJoint(Revolute("shoulder"), "base", "upper");
  RobotModel m = b.Build();
  std::vector<int> order(m.topological_joint_order().begin(), m.topological_joint_order().end());
  EXPECT_EQ(order, (std::vector<int>{1, 0}));
}

TEST(RobotModel, SumsTotalMass) { EXPECT_DOUBLE_EQ(TwoLinkArm().Build().total_mass(), 2.0); }

TEST(RobotModel, RejectsDuplicateNames) {
  RobotModelBuilder b = TwoLinkArm();
  b.AddLink(Body("upper"));
  ExpectModelError(b, "duplicate link name 'upper'");
  RobotModelBuilder c = TwoLinkArm();
  c.AddLink(Body("extra")).AddJoint(Revolute("elbow"), "base", "extra");
  ExpectModelError(c, "duplicate joint name 'elbow'");
  RobotModelBuilder d = TwoLinkArm();
  d.AddControlFrame(ControlFrame{.name = "tool"}, "upper");
  ExpectModelError(d, "duplicate control frame name 'tool'");
}

// Review 13: a name is shown wherever the model is (robotalk describe's
// table, query lines, robotalk-ros2's log, logplay): a model from the wire
// (CONFIG, in open mode anyone's) or from a URDF (&#x1b; is a valid XML
// character reference to urdfdom's parser) put its terminal escapes and line
// breaks on the terminal raw. Every name (robot, link, joint, control frame)
// is refused with a control character (C0, DEL, C1 encoded in UTF-8), the
// refusal naming it escaped; UTF-8 text is kept.
TEST(RobotModel, RefusesANameWithAControlCharacterNamingItEscaped) {
  RobotModelBuilder b = TwoLinkArm();
  b.AddLink(Body("up\x1b]0;owned\x07per"));
  ExpectModelError(b, "link name 'up\\x1b]0;owned\\x07per'", "control character");
  RobotModelBuilder c = TwoLinkArm();
  c.AddLink(Body("extra")).AddJoint(Revolute("el\nbow"), "base", "extra");
  ExpectModelError(c, "joint name 'el\\x0abow'", "control character");
  RobotModelBuilder d = TwoLinkArm();
  d.AddControlFrame(ControlFrame{.name = "to\xc2\x9bol"}, "upper");
  ExpectModelError(d, "control frame name 'to\\xc2\\x9bol'", "control character");
  RobotModelBuilder e("arm\r");
  e.AddLink(Body("base"));
  ExpectModelError(e, "robot name 'arm\\x0d'", "control character");
  RobotModelBuilder f("bra\xc3\xa7o");  // UTF-8 text is a name
  f.AddLink(Body("\xc3\xa9paule"));
  EXPECT_NO_THROW(f.Build());
}

// Review 14: a name is text shown by a terminal, the page (JSON replaces
// bytes that are not UTF-8 with U+FFFD: two names became one), Foxglove and
// ROS 2 (a JointState whose names are not UTF-8). Every name must be UTF-8
// (no overlong form, surrogate, lone continuation byte or truncated
// character) and hold no line or paragraph separator (U+2028, U+2029) nor
// bidirectional control (U+061C, U+200E, U+200F, U+202A-U+202E,
// U+2066-U+2069: a name shown reordered, "Trojan Source"); the refusal names
// it in printable ASCII. Other UTF-8 text is a name.
TEST(RobotModel, RefusesANameThatIsNotUtf8TextOrHoldsALineSeparatorOrABidiControl) {
  const std::vector<std::pair<std::string, std::string>> bad = {
      {"a\xff", "'a\\xff'"},                             // no UTF-8 byte
      {"a\xc0\xaf", "'a\\xc0\\xaf'"},                    // overlong '/'
      {"a\xe0\x80\xaf", "'a\\xe0\\x80\\xaf'"},           // overlong '/', 3 bytes
      {"a\x80z", "'a\\x80z'"},                           // a lone continuation byte
      {"a\x9b", "'a\\x9b'"},                             // a lone C1 CSI byte
      {"a\xc3", "'a\\xc3'"},                             // truncated
      {"a\xed\xa0\x80", "'a\\xed\\xa0\\x80'"},           // a surrogate
      {"a\xf4\x90\x80\x80", "'a\\xf4\\x90\\x80\\x80'"},  // past U+10FFFF
      {"a\xe2\x80\xa8z", "'a\\xe2\\x80\\xa8z'"},         // U+2028
      {"a\xe2\x80\xaez", "'a\\xe2\\x80\\xaez'"},         // U+202E right-to-left override
      {"a\xe2\x81\xa6z", "'a\\xe2\\x81\\xa6z'"},         // U+2066 left-to-right isolate
      {"a\xe2\x80\x8fz", "'a\\xe2\\x80\\x8fz'"},         // U+200F right-to-left mark
  };
  for (const auto& [name, shown] : bad) {
    RobotModelBuilder b = TwoLinkArm();
    b.AddLink(Body(name));
    ExpectModelError(b, ("link name " + shown).c_str());
    RobotModelBuilder c = TwoLinkArm();
    c.AddLink(Body("extra")).AddJoint(Revolute(name), "base", "extra");
    ExpectModelError(c, ("joint name " + shown).c_str());
  }
  RobotModelBuilder f("\xe9\x96\xa2\xe7\xaf\x80");  // UTF-8 text is a name (BMP, 4 bytes, Hebrew)
  f.AddLink(Body("\xf0\x9f\xa4\x96")).AddLink(Body("\xd7\x96\xd7\x95\xd7\xa2"));
  EXPECT_NO_THROW(f.Build());
}

TEST(RobotModel, RejectsAJointNamingAnUnknownLink) {
  RobotModelBuilder b = TwoLinkArm();
  b.AddJoint(Revolute("wrist"), "lower", "hand");
  ExpectModelError(b, "joint 'wrist'", "unknown child link 'hand'");
  RobotModelBuilder c = TwoLinkArm();
  c.AddControlFrame(ControlFrame{.name = "cam"}, "head");
  ExpectModelError(c, "control frame 'cam'", "unknown parent link 'head'");
}

TEST(RobotModel, RejectsALinkWithTwoParentJoints) {
  RobotModelBuilder b = TwoLinkArm();
  b.AddJoint(Revolute("second_parent"), "base", "lower");
  ExpectModelError(b, "not a tree", "link 'lower' has two parent joints", "'elbow'", "'second_parent'");
}

TEST(RobotModel, RejectsACycle) {
  RobotModelBuilder b("loop");
  b.AddLink(Body("root", 0)).AddLink(Body("a")).AddLink(Body("b"));
  b.AddJoint(Revolute("ab"), "a", "b").AddJoint(Revolute("ba"), "b", "a");
  ExpectModelError(b, "cycle", "'a'", "'b'");
}

TEST(RobotModel, RejectsAModelWithoutRoot) {
  RobotModelBuilder b("ring");
  b.AddLink(Body("a")).AddLink(Body("b"));
  b.AddJoint(Revolute("ab"), "a", "b").AddJoint(Revolute("ba"), "b", "a");
  ExpectModelError(b, "no root link");
}

TEST(RobotModel, RejectsAJointWithMoreThanSixDofs) {
  RobotModelBuilder b = TwoLinkArm();
  Joint j = Revolute("too_many");
  for (int i = 0; i < 6; ++i) j.dofs.push_back(j.dofs.front());
  b.AddLink(Body("extra")).AddJoint(j, "base", "extra");
  ExpectModelError(b, "joint 'too_many'", "7 dofs", "at most 6");
}

TEST(RobotModel, RejectsZeroAndNonUnitAxes) {
  RobotModelBuilder b = TwoLinkArm();
  b.AddLink(Body("extra")).AddJoint(Revolute("zero", Eigen::Vector3d::Zero()), "base", "extra");
  ExpectModelError(b, "joint 'zero' dof 0", "zero axis");
  RobotModelBuilder c = TwoLinkArm();
  c.AddLink(Body("extra")).AddJoint(Revolute("long", {0, 0, 2}), "base", "extra");
  ExpectModelError(c, "joint 'long' dof 0", "not a unit vector");
}

TEST(RobotModel, RejectsLowerLimitAboveUpper) {
  RobotModelBuilder b = TwoLinkArm();
  Joint j = Revolute("inverted");
  j.dofs[0].limits.lower = 2.0;
  j.dofs[0].limits.upper = -2.0;
  b.AddLink(Body("extra")).AddJoint(j, "base", "extra");
  ExpectModelError(b, "joint 'inverted'", "lower limit 2", "above upper limit -2");
}

TEST(RobotModel, RejectsNonPositiveVelocityOrEffortLimit) {
  RobotModelBuilder b = TwoLinkArm();
  Joint j = Revolute("stuck");
  j.dofs[0].limits.velocity = 0;
  b.AddLink(Body("extra")).AddJoint(j, "base", "extra");
  ExpectModelError(b, "joint 'stuck'", "velocity limit");
}

TEST(RobotModel, RejectsNegativeMass) {
  RobotModelBuilder b = TwoLinkArm();
  b.AddLink(Body("ghost", -1.0));
  ExpectModelError(b, "link 'ghost'", "negative mass");
}

TEST(RobotModel, RejectsNonPositiveDefiniteInertiaForALinkWithMass) {
  RobotModelBuilder b = TwoLinkArm();
  Link flat = Body("flat");
  flat.inertia(2, 2) = 0;
  b.AddLink(flat);
  ExpectModelError(b, "link 'flat'", "not positive-definite");
}

TEST(RobotModel, AcceptsAMasslessLinkWithoutInertia) {
  RobotModelBuilder b = TwoLinkArm();
  b.AddLink(Body("frame_only", 0.0));
  EXPECT_NO_THROW(b.Build());
}

TEST(RobotModel, RejectsNonFiniteNumbers) {
  RobotModelBuilder b = TwoLinkArm();
  Link bad = Body("nan_com");
  bad.com.x() = std::nan("");
  b.AddLink(bad);
  ExpectModelError(b, "link 'nan_com'", "not finite");
  RobotModelBuilder c = TwoLinkArm();
  Joint j = Revolute("nan_limit");
  j.dofs[0].limits.upper = std::nan("");
  c.AddLink(Body("extra")).AddJoint(j, "base", "extra");
  ExpectModelError(c, "joint 'nan_limit'", "NaN");
}

TEST(RobotModel, ValidatesMimicJoints) {
  RobotModelBuilder ok = TwoLinkArm();
  ok.SetMimic("elbow", "shoulder", -0.5, 0.1);
  RobotModel m = ok.Build();
  ASSERT_TRUE(m.joint(1).mimic.has_value());
  EXPECT_EQ(m.joint(1).mimic->leader_joint, 0);

  RobotModelBuilder self = TwoLinkArm();
  self.SetMimic("elbow", "elbow", 1, 0);
  ExpectModelError(self, "joint 'elbow'", "the joint itself");

  RobotModelBuilder unknown = TwoLinkArm();
  unknown.SetMimic("elbow", "wrist", 1, 0);
  ExpectModelError(unknown, "joint 'elbow'", "unknown joint 'wrist'");

  RobotModelBuilder fixed_leader = TwoLinkArm();
  fixed_leader.AddLink(Body("extra")).AddJoint(Joint{.name = "weld"}, "base", "extra");
  fixed_leader.SetMimic("elbow", "weld", 1, 0);
  ExpectModelError(fixed_leader, "joint 'elbow'", "1-dof");
}

TEST(RobotModel, RejectsARootThatHasAParent) {
  RobotModelBuilder b = TwoLinkArm();
  b.SetRoot("upper", Pose{});
  ExpectModelError(b, "root link 'upper' has a parent joint 'shoulder'");
}

TEST(RobotModel, ComparesEqualOnlyWhenEveryFieldMatches) {
  RobotModel a = TwoLinkArm().Build();
  RobotModel b = TwoLinkArm().Build();
  EXPECT_EQ(a, b);
  RobotModelBuilder changed = TwoLinkArm();
  changed.SetRoot("base", Pose{.translation = {0, 0, 1e-12}, .rotation = Eigen::Quaterniond::Identity()});
  EXPECT_FALSE(a == changed.Build());
}

TEST(ServoTypes, ParsesAndPrintsEveryType) {
  EXPECT_EQ(ServoTypes::Parse("setpoint speed").bits(), 3);
  EXPECT_EQ(ServoTypes::Parse("position,velocity|effort"), ServoTypes::All());
  EXPECT_EQ(ServoTypes::Parse("none"), ServoTypes());
  EXPECT_EQ(ServoTypes::All().ToString(), "setpoint speed force");
  EXPECT_EQ(ServoTypes().ToString(), "none");
  EXPECT_THROW(ServoTypes::Parse("setpiont"), ModelError);
}

TEST(BaseType, ParsesTheNamesItPrints) {
  for (BaseType t : {BaseType::kFixed, BaseType::kDifferential, BaseType::kHolonomic, BaseType::kFloating}) {
    EXPECT_EQ(ParseBaseType(ToString(t)), t);
  }
  EXPECT_THROW(ParseBaseType("tracked"), ModelError);
}

}  // namespace
}  // namespace robotalk
