// Tests of the gait derived from the model (drivers/ode_sim/walking/
// gait_limits.h): the simple humanoid's leg measured from its URDF, the
// derived gait's speeds above the floor (0.25 m/s forward, 0.1 m/s
// sideways, 0.5 rad/s turning), every rule's bound respected, the soles
// kept apart when turning, and plans with the derived gait within it.
#include "walking/gait_limits.h"
#include "robotalk/urdf_import.h"
#include "test_paths.h"
#include "walking/footstep_planner.h"
#include "walking/walk_pattern.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>
#include <random>

namespace robotalk::walking {
namespace {

// The simple humanoid's walking geometry, as the ode driver fills it (the
// sole 24 x 12 cm, 3 cm ahead of the ankle; ankles 18 cm apart; pelvis
// 0.7254 m above the soles: 7 % knee drop of 0.78 m).
// A walking geometry as the ode driver fills it from the model: the sole
// (front and back of the ankle, half-width; the ZMP point in its middle), the
// ankles' separation and the CoM height.
GaitParams Geometry(double front, double back, double half_width, double separation, double com_height) {
  GaitParams g;
  g.foot_front = front;
  g.foot_back = back;
  g.foot_half_width = half_width;
  g.zmp_x = (front - back) / 2;
  g.foot_separation = separation;
  g.com_height = com_height;
  return g;
}

struct Humanoid {
  RobotModel model = LoadUrdfFile(testing::ProjectModel("simple_humanoid.urdf")).model;
  GaitParams base = Geometry(0.15, 0.09, 0.06, 0.18, 0.70);
  LegGeometry leg;
  Humanoid() {
    std::string why;
    leg = MeasureLeg(model, model.LinkIndex("left_foot"), -0.07, 0.78 * 0.93, &why);
    EXPECT_EQ(why, "");
  }
};

TEST(GaitLimits, TheSimpleHumanoidsLegIsMeasuredFromItsModel) {
  const Humanoid h;
  EXPECT_NEAR(h.leg.thigh, 0.30, 1e-9);
  EXPECT_NEAR(h.leg.shank, 0.30, 1e-9);
  EXPECT_NEAR(h.leg.hip_height, 0.78 * 0.93 - 0.11 - 0.07, 1e-9);
  EXPECT_NEAR(h.leg.hip_width, 0.18, 1e-9);
  EXPECT_NEAR(h.leg.hip_yaw, 0.8, 1e-9);
  EXPECT_NEAR(h.leg.hip_roll_out, 0.5, 1e-9);
  EXPECT_NEAR(h.leg.joint_speed, 3.0, 1e-9);
  std::string why;
  MeasureLeg(h.model, h.model.LinkIndex("head"), -0.07, 0.7, &why);
  EXPECT_NE(why, "") << "a head is no leg";
}

TEST(GaitLimits, TheDerivedGaitMeetsTheSpeedFloorWithinEveryBound) {
  const Humanoid h;
  GaitBounds b;
  const GaitParams g = DeriveGait(h.leg, h.base, 9.81, &b);
  const GaitSpeeds v = SpeedsOf(g);
  std::printf("derived: step %.2f back %.2f side %.2f yaw %.2f/%.2f ss %.2f ds %.2f height %.3f\n",
              g.step_forward, g.step_back, g.step_side, g.step_yaw, g.step_yaw_in, g.single_support,
              g.double_support, g.step_height);
  std::printf(
      "bounds: tc %.3f reach %.3f speed %.3f roll_side %.3f reach_side %.3f yaw %.3f sole %.3f/%.3f\n", b.tc,
      b.reach_step, b.speed_step, b.roll_side, b.reach_side, b.hip_yaw_turn, b.sole_turn, b.sole_turn_in);
  std::printf("speeds: forward %.3f m/s back %.3f side %.3f turn %.3f rad/s\n", v.forward, v.back, v.side,
              v.turn);
  EXPECT_GE(v.forward, 0.25);
  EXPECT_GE(v.side, 0.1);
  EXPECT_GE(v.turn, 0.5);
  EXPECT_LE(g.step_forward, std::min(b.reach_step, b.speed_step) + 1e-9);
  EXPECT_LE(g.step_yaw, std::min(b.hip_yaw_turn, b.sole_turn) + 1e-9);
  EXPECT_LE(g.step_yaw_in, b.sole_turn_in + 1e-9);
  EXPECT_LE(g.step_side, std::min({b.roll_side, b.reach_side, b.sole_side}) + 1e-9);
  EXPECT_GE(g.single_support, 1.5 * b.tc);
  // The geometry is the base's.
  EXPECT_EQ(g.foot_separation, h.base.foot_separation);
  EXPECT_EQ(g.com_height, h.base.com_height);
  // The slow gait is the old one.
  const GaitSpeeds slow = SpeedsOf(SlowGait(h.base));
  EXPECT_NEAR(slow.forward, 0.10 / 1.1, 1e-9);
}

TEST(GaitLimits, ShorterLegsOrSlowerJointsGiveASlowerGait) {
  const Humanoid h;
  const GaitSpeeds v = SpeedsOf(DeriveGait(h.leg, h.base, 9.81));
  LegGeometry slow_joints = h.leg;
  slow_joints.joint_speed = 1.5;
  EXPECT_LT(SpeedsOf(DeriveGait(slow_joints, h.base, 9.81)).forward, v.forward);
  LegGeometry deep = h.leg;
  deep.hip_height = 0.58;  // nearly straight: little reach left
  EXPECT_LT(DeriveGait(deep, h.base, 9.81).step_forward, DeriveGait(h.leg, h.base, 9.81).step_forward);
  LegGeometry stiff_yaw = h.leg;
  stiff_yaw.hip_yaw = 0.05;
  EXPECT_LE(DeriveGait(stiff_yaw, h.base, 9.81).step_yaw, 2 * 0.8 * 0.05 + 1e-9);
}

// Atlas's legs (0.8 m, 12 rad/s joints): only the reach bounded its step,
// and it fell on it (docs/ode_sim.md). The step is at most kMaxStepOfLeg
// (0.37) of thigh + shank whatever the joints' speed allows.
TEST(GaitLimits, FastJointsOnLongLegsStepAtMostAMeasuredShareOfTheLeg) {
  const Humanoid h;
  LegGeometry fast = h.leg;
  fast.joint_speed = 12;
  GaitBounds b;
  const GaitParams g = DeriveGait(fast, h.base, 9.81, &b);
  EXPECT_NEAR(b.speed_step, b.reach_step, 1e-6) << "the joints' speed no longer bounds the step";
  EXPECT_GT(b.reach_step, b.leg_step);
  EXPECT_NEAR(b.leg_step, 0.37 * (fast.thigh + fast.shank), 1e-12);
  EXPECT_LE(g.step_forward, b.leg_step);
  EXPECT_GT(g.step_forward, b.leg_step - 0.0100001);
  // The simple humanoid's own step is bounded by its joints' speed, as before.
  GaitBounds own;
  EXPECT_DOUBLE_EQ(DeriveGait(h.leg, h.base, 9.81, &own).step_forward, 0.22);
  EXPECT_LT(own.speed_step, own.leg_step);
}

// The sideways step is bounded by the sole's lateral support as well as by
// the hip roll and the reach: a sideways swing pushes the stance sole's
// centre of pressure to its edge. Atlas (a 0.8 m leg whose hip roll allows
// 0.23 m, on a 12.5 cm sole) rocked on its sole's edge after such steps and
// fell in the turning steps that followed (docs/ode_sim.md); its side step is
// now at most 1.34 sole widths: 0.16 m. The simple humanoid's stays 0.16 m.
TEST(GaitLimits, SideStepsStayWithinWhatTheSolesWidthSupports) {
  const Humanoid h;
  GaitBounds own;
  const GaitParams simple = DeriveGait(h.leg, h.base, 9.81, &own);
  EXPECT_DOUBLE_EQ(simple.step_side, 0.16);
  EXPECT_NEAR(own.sole_side, 1.34 * 0.12, 1e-12);
  // Atlas's leg and sole, as its driver measures them.
  const LegGeometry atlas{.thigh = 0.377,
                          .shank = 0.422,
                          .hip_height = 0.73,
                          .hip_width = 0.223,
                          .hip_yaw = 0.174,
                          .hip_roll_out = 0.5236,
                          .joint_speed = 12};
  const GaitParams base = Geometry(0.1728, 0.0876, 0.0626, 0.223, 1.17);
  GaitBounds b;
  const GaitParams g = DeriveGait(atlas, base, 9.81, &b);
  EXPECT_GT(std::min(b.roll_side, b.reach_side), 0.23) << "the hip roll and reach allow more";
  EXPECT_NEAR(b.sole_side, 1.34 * 2 * 0.0626, 1e-12);
  EXPECT_DOUBLE_EQ(g.step_side, 0.16);
  EXPECT_DOUBLE_EQ(g.step_forward, 0.29) << "the other bounds are unchanged";
  // A narrower sole under the simple humanoid's leg: a shorter side step.
  GaitParams narrow = h.base;
  narrow.foot_half_width = 0.04;
  EXPECT_DOUBLE_EQ(DeriveGait(h.leg, narrow, 9.81).step_side, 0.10);
}

TEST(GaitLimits, TurningStepsKeepTheSolesApart) {
  const Humanoid h;
  const GaitParams g = DeriveGait(h.leg, h.base, 9.81);
  EXPECT_GT(SoleClearance(FootAt({}, Side::kLeft, g), FootAt({}, Side::kRight, g), g), 0.05);
  EXPECT_LT(SoleClearance(FootAt({}, Side::kLeft, g), FootAt({0.05, 0, 0}, Side::kLeft, g), g), 0)
      << "overlapping soles";
  // A turn in place, either foot first, either way: every double support clear.
  for (const double dir : {1.0, -1.0}) {
    for (const Side first : {Side::kLeft, Side::kRight}) {
      Pose2 feet[2] = {FootAt({}, Side::kLeft, g), FootAt({}, Side::kRight, g)};
      Pose2 c;
      Side swing = first;
      for (int i = 0; i < 12; ++i) {
        c = StepBy(c, 0, 0, dir * 10, swing, g);
        feet[static_cast<int>(swing)] = FootAt(c, swing, g);
        EXPECT_GE(SoleClearance(feet[0], feet[1], g), 0.0099) << "step " << i;
        swing = Other(swing);
      }
      EXPECT_NEAR(std::abs(c.theta), std::abs(Wrap(dir * 6 * (g.step_yaw + g.step_yaw_in))), 1e-9);
    }
  }
}

TEST(GaitLimits, PlansWithTheDerivedGaitReachTheirGoals) {
  const Humanoid h;
  const GaitParams g = DeriveGait(h.leg, h.base, 9.81);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> pos(-2.0, 2.0), yaw(-std::numbers::pi, std::numbers::pi);
  for (int i = 0; i < 20; ++i) {
    const Pose2 goal{pos(rng), pos(rng), yaw(rng)};
    bool reached = false;
    const auto plan = PlanFootsteps({}, goal, g, 400, &reached);
    EXPECT_TRUE(reached) << i;
    ASSERT_FALSE(plan.empty());
    EXPECT_NEAR(plan.back().centre.x, goal.x, 1e-9);
  }
}

// The preview keeps up with the derived gait's shorter double support: on
// walks forward, sideways and turning the model's ZMP stays 1 cm inside the
// support polygon of the planned steps.
TEST(GaitLimits, TheDerivedGaitsZmpStaysInsideTheSupport) {
  const Humanoid h;
  const GaitParams g = DeriveGait(h.leg, h.base, 9.81);
  for (const Pose2& goal : {Pose2{2.0, 0.3, 0.5}, Pose2{0, 0.6, 0}, Pose2{0, 0, 3.0}}) {
    WalkPattern w(g, 0.001, 5, 9.81);
    w.Reset({}, Eigen::Vector2d(g.ankle_x + g.zmp_x, 0));
    std::vector<Footstep> steps;
    std::vector<Pose2> centres;
    for (const PlannedStep& p : PlanFootsteps({}, goal, g)) {
      steps.push_back(p.step);
      centres.push_back(p.centre);
    }
    w.Append(steps, centres);
    for (int ticks = 0; !w.standing() && ticks < 100000; ++ticks) {
      w.Tick();
      ASSERT_TRUE(w.InSupport(w.zmp(), 0.01))
          << "goal " << goal.x << "," << goal.y << "," << goal.theta << " t=" << w.time();
    }
    EXPECT_TRUE(w.standing());
  }
}

}  // namespace
}  // namespace robotalk::walking
