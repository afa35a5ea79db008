// Tests of the walking controller's pure part (drivers/ode_sim/walking):
// footstep plans within the step limits that reach their goals, ZMP preview
// control tracking its reference, a whole walk's ZMP inside the support
// polygon of the planned steps, and the leg IK on the simple humanoid.
#include "robotalk/urdf_import.h"
#include "test_paths.h"
#include "walking/dcm_stabilizer.h"
#include "walking/footstep_planner.h"
#include "walking/leg_ik.h"
#include "walking/walk_pattern.h"
#include "walking/zmp_preview.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>

namespace robotalk::walking {
namespace {

constexpr double kPi = std::numbers::pi;

// Every step of a plan within the limits, seen from the centre before it.
void ExpectWithinLimits(const Pose2& start, const std::vector<PlannedStep>& plan, const GaitParams& g) {
  Pose2 c = start;
  for (size_t i = 0; i < plan.size(); ++i) {
    const Pose2& n = plan[i].centre;
    const double co = std::cos(c.theta), si = std::sin(c.theta);
    const double dx = co * (n.x - c.x) + si * (n.y - c.y), dy = -si * (n.x - c.x) + co * (n.y - c.y);
    EXPECT_LE(dx, g.step_forward + 1e-9) << "step " << i;
    EXPECT_GE(dx, -g.step_back - 1e-9) << "step " << i;
    EXPECT_LE(std::abs(dy), g.step_side + 1e-9) << "step " << i;
    EXPECT_GE(dy * SideSign(plan[i].step.side), -1e-9) << "step " << i << " steps toward the stance foot";
    EXPECT_LE(std::abs(Wrap(n.theta - c.theta)), g.step_yaw + 1e-9) << "step " << i;
    if (i > 0) {
      EXPECT_NE(plan[i].step.side, plan[i - 1].step.side) << "feet alternate";
    }
    c = n;
  }
}

TEST(FootstepPlanner, TwentySeededGoalsAreReachedWithinTheStepLimits) {
  const GaitParams g;
  std::mt19937 rng(42);
  std::uniform_real_distribution<double> r(0, 2), a(-kPi, kPi);
  for (int i = 0; i < 20; ++i) {
    const double d = r(rng), bearing = a(rng);
    const Pose2 goal{d * std::cos(bearing), d * std::sin(bearing), a(rng)};
    bool reached = false;
    const std::vector<PlannedStep> plan = PlanFootsteps({}, goal, g, 400, &reached);
    ASSERT_TRUE(reached) << "goal " << i;
    ExpectWithinLimits({}, plan, g);
    const Pose2& end = plan.back().centre;
    EXPECT_NEAR(end.x, goal.x, 1e-9);
    EXPECT_NEAR(end.y, goal.y, 1e-9);
    EXPECT_NEAR(Wrap(end.theta - goal.theta), 0, 1e-9);
    // Both feet end around the goal.
    const Footstep& a1 = plan[plan.size() - 1].step;
    const Footstep& a2 = plan[plan.size() - 2].step;
    EXPECT_NE(a1.side, a2.side);
    for (const Footstep* f : {&a1, &a2}) {
      const Pose2 want = FootAt(goal, f->side, g);
      EXPECT_NEAR(std::hypot(f->pose.x - want.x, f->pose.y - want.y), 0, 1e-9);
    }
    // Turn, walk, turn: a 2 m goal takes at most ~ 2/0.1 + 2 pi/0.25 + a few steps.
    EXPECT_LT(plan.size(), 60u);
  }
}

TEST(FootstepPlanner, AGoalToTheLeftStepsLeftFirstAndOnlyOutward) {
  const GaitParams g;
  const std::vector<PlannedStep> plan = PlanFootsteps({}, {0, 0.12, 0}, g);
  ASSERT_GE(plan.size(), 3u);
  EXPECT_EQ(plan[0].step.side, Side::kLeft);
  ExpectWithinLimits({}, plan, g);
  EXPECT_TRUE(PlanFootsteps({1, 2, 3}, {1, 2, 3}, g).empty()) << "already there";
}

TEST(FootstepPlanner, StepByClampsAndSaysSo) {
  const GaitParams g;
  bool clamped = false;
  const Pose2 p = StepBy({}, 1.0, 0.0, 0.0, Side::kLeft, g, &clamped);
  EXPECT_TRUE(clamped);
  EXPECT_NEAR(p.x, g.step_forward, 1e-12);
  StepBy({}, 0.05, 0.0, 0.1, Side::kLeft, g, &clamped);
  EXPECT_FALSE(clamped);
  const Pose2 q = StepBy({}, 0.0, -0.03, 0.0, Side::kLeft, g, &clamped);
  EXPECT_TRUE(clamped) << "a left swing cannot step right";
  EXPECT_EQ(q.y, 0.0);
}

TEST(ZmpPreview, TheZmpFollowsAStepOfItsReferenceAndTheCoMSettlesThere) {
  ZmpPreview p(0.005, 0.7, 9.81, 1.6);
  EXPECT_EQ(p.horizon_samples(), 320);
  p.Reset(0);
  std::vector<double> future(320);
  double worst_before = 0;
  for (int k = 0; k < 1200; ++k) {  // the reference steps to 0.1 m at t = 2 s
    for (int j = 0; j < 320; ++j) future[static_cast<size_t>(j)] = (k + j + 1) * 0.005 >= 2.0 ? 0.1 : 0.0;
    const double now = k * 0.005 >= 2.0 ? 0.1 : 0.0;
    p.Step(now, future);
    if (k * 0.005 < 1.0) worst_before = std::max(worst_before, std::abs(p.zmp()));
  }
  EXPECT_LT(worst_before, 1e-3) << "the preview starts moving well before the step, not a second early";
  EXPECT_NEAR(p.state()(0), 0.1, 1e-3);
  EXPECT_NEAR(p.zmp(), 0.1, 1e-4);
  EXPECT_NEAR(p.state()(1), 0.0, 1e-3);
}

// A whole walk: the model's ZMP never leaves the support polygon of the
// planned steps (with a margin), and the CoM ends over the final stance.
void WalkAndCheck(const Pose2& goal) {
  const GaitParams g;
  WalkPattern w(g, 0.001, 5, 9.81);
  w.Reset({}, Eigen::Vector2d(g.ankle_x + g.zmp_x, 0));
  const std::vector<PlannedStep> plan = PlanFootsteps({}, goal, g);
  std::vector<Footstep> steps;
  std::vector<Pose2> centres;
  for (const PlannedStep& p : plan) {
    steps.push_back(p.step);
    centres.push_back(p.centre);
  }
  w.Append(steps, centres);
  int ticks = 0;
  while (!w.standing() && ticks < 200000) {
    w.Tick();
    ++ticks;
    ASSERT_TRUE(w.InSupport(w.zmp(), 0.01)) << "t=" << w.time() << " zmp " << w.zmp().transpose();
  }
  ASSERT_TRUE(w.standing());
  for (int i = 0; i < 1500; ++i) w.Tick();
  const Eigen::Vector2d want = goal.Apply(g.ankle_x + g.zmp_x, 0);
  EXPECT_NEAR((w.com() - want).norm(), 0, 5e-3);
  EXPECT_NEAR(Wrap(w.foot(Side::kLeft).theta - goal.theta), 0, 1e-9);
}

TEST(WalkPattern, TheZmpStaysInTheSupportPolygonOnWalksToFiveGoals) {
  for (const Pose2& goal : {Pose2{1.0, 0, 0}, Pose2{0.5, 0.5, 1.0}, Pose2{-0.3, 0.2, -2.0}, Pose2{0, 0.15, 0},
                            Pose2{0.1, -0.1, 3.0}}) {
    WalkAndCheck(goal);
  }
}

TEST(WalkPattern, TheCoMSettlesOverTheFinalStanceSoonAfterTheLastShift) {
  const GaitParams g;
  WalkPattern w(g, 0.001, 5, 9.81);
  w.Reset({}, Eigen::Vector2d(g.ankle_x + g.zmp_x, 0));
  const Pose2 goal{0.3, 0.1, 0.4};
  const std::vector<PlannedStep> plan = PlanFootsteps({}, goal, g);
  std::vector<Footstep> steps;
  std::vector<Pose2> centres;
  for (const PlannedStep& p : plan) {
    steps.push_back(p.step);
    centres.push_back(p.centre);
  }
  w.Append(steps, centres);
  EXPECT_FALSE(w.settled(2e-3)) << "a walk is scheduled";
  int ticks = 0;
  while (!w.standing() && ticks < 100000) {
    EXPECT_FALSE(w.settled(2e-3));
    w.Tick();
    ++ticks;
  }
  const Eigen::Vector2d want = goal.Apply(g.ankle_x + g.zmp_x, 0);
  const double at_standing = (w.com() - want).norm();
  int more = 0;
  while (!w.settled(2e-3) && more < 3000) {
    w.Tick();
    ++more;
  }
  EXPECT_TRUE(w.settled(2e-3));
  EXPECT_LT(more * 0.001, 1.5) << "settles within 1.5 s of standing";
  EXPECT_LT((w.com() - want).norm(), 2e-3);
  EXPECT_GT(at_standing, (w.com() - want).norm()) << "the CoM was still on its way when the shift ended";
}

// STOP in single support (the step in the air and one more) and in double
// support (one more step): the ZMP stays inside the feet with a margin, the
// reference never jumps, and the walk ends within two steps, feet side by side.
void StopAt(int tick) {
  const GaitParams g;
  WalkPattern w(g, 0.001, 5, 9.81);
  w.Reset({}, Eigen::Vector2d(g.ankle_x + g.zmp_x, 0));
  const std::vector<PlannedStep> plan = PlanFootsteps({}, {2, 0, 0}, g);
  std::vector<Footstep> steps;
  std::vector<Pose2> centres;
  for (const PlannedStep& p : plan) {
    steps.push_back(p.step);
    centres.push_back(p.centre);
  }
  w.Append(steps, centres);
  for (int i = 0; i < tick; ++i) w.Tick();
  const bool in_air = !w.double_support();
  const double before = w.time();
  const int started = w.started_steps();
  w.StopSoon();
  EXPECT_LE(w.unstarted_steps(), 1);
  Eigen::Vector2d ref = w.zmp_ref();
  while (!w.standing()) {
    w.Tick();
    ASSERT_TRUE(w.InSupport(w.zmp(), 0.01)) << "stop at tick " << tick << ", t=" << w.time();
    ASSERT_LT((w.zmp_ref() - ref).norm(), 1e-3) << "stop at tick " << tick << ", t=" << w.time();
    ref = w.zmp_ref();
  }
  EXPECT_LE(w.started_steps() - started, 1) << "in the air: " << in_air;
  EXPECT_LE(w.time() - before, 2 * g.step_period() + g.end_shift);
  EXPECT_TRUE(w.double_support());
  const Pose2 l = w.foot(Side::kLeft), r = w.foot(Side::kRight);
  EXPECT_NEAR(std::hypot(l.x - r.x, l.y - r.y), g.foot_separation, 1e-9) << "feet side by side";
}

TEST(WalkPattern, StopSoonEndsWithinTwoStepsInDoubleSupport) {
  // Steps start every 1.1 s from 1.8 s: single support 0.8 s, double 0.3 s.
  for (int tick : {3300, 3800, 3950, 5000}) StopAt(tick);
}

// Replanning at any instant (issue 26, item 2): a command at every phase of
// the gait. The reference ZMP never jumps (at most a shift's slope per tick),
// the model's ZMP stays inside the planned support with a margin, and a stop
// ends standing with the feet side by side.
struct Sweep {
  GaitParams g;
  WalkPattern w{g, 0.001, 5, 9.81};
  Eigen::Vector2d ref;
  double worst_jump = 0;
  double worst_outside = 0;  // m the model's ZMP came closer than the margin to the support's edge

  Sweep() {
    w.Reset({}, Eigen::Vector2d(g.ankle_x + g.zmp_x, 0));
    ref = w.zmp_ref();
  }
  void Goto(const Pose2& goal) {
    const WalkPattern::Splice from = w.DropUnstarted();
    std::vector<Footstep> steps;
    std::vector<Pose2> centres;
    for (const PlannedStep& p :
         PlanFootsteps(from.centre, goal, g, 400, nullptr, from.side_free ? nullptr : &from.next)) {
      steps.push_back(p.step);
      centres.push_back(p.centre);
    }
    w.Append(steps, centres);
  }
  // SETSPEED's queue (as the ode driver keeps it): forward steps appended
  // whenever fewer than 3.2 s are planned.
  void Queue(double dx) {
    while (w.planned_ahead() < 3.2) {
      const WalkPattern::Splice at = w.AppendPoint();
      const Side next = at.side_free ? Side::kLeft : at.next;
      const Pose2 c = StepBy(at.centre, dx, 0, 0, next, g);
      w.Append({Footstep{next, FootAt(c, next, g)}}, {c});
    }
  }
  void Run(double seconds, double queue_dx = 0) {
    for (int i = 0; i < static_cast<int>(seconds * 1000); ++i) {
      if (queue_dx != 0) Queue(queue_dx);
      w.Tick();
      worst_jump = std::max(worst_jump, (w.zmp_ref() - ref).norm());
      ref = w.zmp_ref();
      if (!w.InSupport(w.zmp(), 0.01)) worst_outside = std::max(worst_outside, w.time());
    }
  }
  void ExpectStoppedSideBySide(const std::string& what) {
    for (int i = 0; i < 10000 && !w.settled(2e-3); ++i) Run(0.001);
    EXPECT_TRUE(w.standing()) << what;
    const Pose2 l = w.foot(Side::kLeft), r = w.foot(Side::kRight);
    EXPECT_NEAR(std::hypot(l.x - r.x, l.y - r.y), g.foot_separation, 1e-6) << what << ": feet side by side";
    // A shift moves the reference foot to foot in double_support: the steepest slope.
    EXPECT_LT(worst_jump, 1.5e-3) << what << ": the reference ZMP jumped";
    EXPECT_EQ(worst_outside, 0) << what << ": the model's ZMP left the support (last at t=" << worst_outside
                                << ")";
  }
};

TEST(WalkPattern, StopThenGotoAtEveryPhaseKeepsTheZmpContinuousAndInside) {
  for (int ms = 0; ms <= 2000; ms += 100) {
    Sweep s;
    s.Goto({1.5, 0, 0});
    s.Run(0.3 + ms * 1e-3);
    s.w.StopSoon();
    s.Run(0.1);
    s.Goto({1.5, 0, 0});  // STOP then GOTO 0.1 s later (the 1.3 s / 1.4 s)
    s.Run(4.0);
    s.w.StopSoon();  // ... and a STOP, a long pause, a GOTO again (its 2.3 s / 3.5 s)
    s.Run(1.2);
    s.Goto({0.5, 0.3, 1.0});
    for (int i = 0; i < 60000 && !s.w.settled(2e-3); ++i) s.Run(0.001);
    EXPECT_TRUE(s.w.settled(2e-3)) << ms;
    s.ExpectStoppedSideBySide("stop at " + std::to_string(300 + ms) + " ms");
    EXPECT_NEAR(s.w.final_centre().x, 0.5, 1e-9);
  }
}

TEST(WalkPattern, SpeedZeroAndBackAtEveryPhaseKeepsTheZmpContinuousAndInside) {
  for (int ms = 0; ms <= 2000; ms += 100) {
    Sweep s;
    s.Run(0.5, 0.1);  // SETSPEED 0.09 m/s
    s.Run(ms * 1e-3, 0.1);
    s.w.StopSoon();  // SETSPEED 0
    s.Run(1.0);
    s.w.DropUnstarted();  // SETSPEED again
    s.Run(4.0, 0.1);
    s.w.StopSoon();
    s.ExpectStoppedSideBySide("speed 0 at " + std::to_string(500 + ms) + " ms");
    EXPECT_GT(s.w.final_centre().x, 0.15) << "it walked; speed 0 at " << 500 + ms << " ms";
  }
}

TEST(WalkPattern, AStopInTheFirstShiftOfWeightShiftsBackWithoutAJump) {
  // The walk starts with start_lead (1 s) standing, then the 0.8 s shift onto
  // the first stance foot: a STOP there completes the shift and shifts back.
  for (int ms = 900; ms <= 1750; ms += 50) {
    Sweep s;
    s.Goto({1.0, 0, 0});
    s.Run(ms * 1e-3);
    const int started = s.w.started_steps();
    s.w.StopSoon();
    s.ExpectStoppedSideBySide("stop at " + std::to_string(ms) + " ms");
    EXPECT_EQ(s.w.started_steps(), started) << "no step was taken";
  }
}

TEST(WalkPattern, AWalkCommandChangesNothingWithinThePreviewLead) {
  // The reference over the next start_lead seconds is the same whatever is
  // appended or dropped: the preview saw it coming.
  for (int ms = 0; ms <= 3000; ms += 150) {
    Sweep a, b;
    for (Sweep* s : {&a, &b}) {
      s->Goto({2.0, 0, 0});
      s->Run(ms * 1e-3);
    }
    b.Goto({-0.5, 0.5, 2.0});
    for (int i = 0; i < static_cast<int>(a.g.start_lead * 1000) - 1; ++i) {
      a.Run(0.001);
      b.Run(0.001);
      ASSERT_LT((a.w.zmp_ref() - b.w.zmp_ref()).norm(), 1e-12) << ms << " ms, tick " << i;
    }
  }
}

// The DCM stabilizer (issue 26, item 1) on a simulated linear inverted
// pendulum: the ZMP it commands is where the pendulum's ZMP goes (ideal
// ankles), a push is a sudden CoM velocity.
std::vector<Eigen::Vector2d> Rect(double x0, double x1, double y0, double y1) {
  return {{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}};  // counter-clockwise
}

// Step adjustment (balance): the foot in the air lands where it is moved,
// forward or outward but never inward of its plan, within reach; the ZMP
// reference stays continuous, inside the support, and moves with the landed foot.
TEST(WalkPattern, AdjustLandingMovesTheFootInTheAirAndTheReferenceWithIt) {
  Sweep s;
  s.Goto({1.5, 0, 0});
  while (s.w.time_to_landing() == 0 || s.w.started_steps() < 2) s.Run(0.001);
  s.Run(0.1);  // early in the second step's swing
  EXPECT_TRUE(s.w.AdjustLanding({0, 0}, 0.5).isZero()) << "no offset, no change";
  const Side swing = Other(s.w.support_side());
  const Pose2 stance = s.w.foot(s.w.support_side());
  // Inward (toward the stance foot) is refused; forward is taken.
  const Eigen::Vector2d inward(0.06, -SideSign(swing) * 0.05);
  const Eigen::Vector2d applied = s.w.AdjustLanding(inward, 0.5);
  EXPECT_NEAR(applied.x(), 0.06, 1e-9);
  EXPECT_NEAR(applied.y(), 0, 1e-9) << "never nearer to the stance foot than planned";
  const Eigen::Vector2d far = s.w.AdjustLanding({0.4, 0}, 0.25);
  s.Run(s.w.time_to_landing() + 0.001);
  const Pose2 landed = s.w.foot(swing);
  EXPECT_NEAR(std::hypot(landed.x - stance.x, landed.y - stance.y), 0.25, 1e-6) << "within reach";
  EXPECT_GT(far.x(), 0.06);
  EXPECT_LT(s.worst_jump, 2e-3) << "the reference moves on continuously";
  s.Run(0.5);
  const Eigen::Vector2d landed_zmp = landed.Apply(s.g.zmp_x, 0);
  EXPECT_LT((s.w.zmp_ref() - landed_zmp).norm(), (s.w.zmp_ref() - stance.Apply(s.g.zmp_x, 0)).norm())
      << "the weight shifts onto the foot where it landed";
  double outside = 0;  // the reference's time outside the support (the preview's model ZMP may
                       // cut a corner after so late a change: the stabilizer clamps its command)
  for (int i = 0; i < 60000 && !s.w.settled(2e-3); ++i) {
    s.Run(0.001);
    if (!s.w.InSupport(s.w.zmp_ref(), 0)) outside = s.w.time();
  }
  EXPECT_TRUE(s.w.standing());
  EXPECT_LT(s.worst_jump, 2e-3);
  EXPECT_EQ(outside, 0) << "the reference ZMP left the support at t=" << outside;
}

TEST(DcmStabilizer, ClampToPolygonKeepsInsidePointsAndClampsOthersToTheShrunkEdge) {
  const auto sq = Rect(-1, 1, -1, 1);
  EXPECT_TRUE(ClampToPolygon({0.5, 0.2}, sq, 0.1).isApprox(Eigen::Vector2d(0.5, 0.2)));
  EXPECT_TRUE(ClampToPolygon({3, 0.2}, sq, 0.1).isApprox(Eigen::Vector2d(0.9, 0.2)));
  EXPECT_TRUE(ClampToPolygon({3, 3}, sq, 0.1).isApprox(Eigen::Vector2d(0.9, 0.9)));
  EXPECT_TRUE(ClampToPolygon({0.95, 0}, sq, 0.1).isApprox(Eigen::Vector2d(0.9, 0)));
  EXPECT_TRUE(ClampToPolygon({5, 0}, Rect(0, 0.1, 0, 0.1), 0.2).isApprox(Eigen::Vector2d(0.05, 0.05)))
      << "thinner than twice the margin: the centroid";
}

struct Lipm {
  double zc = 0.6, g = 9.81, dt = 0.001;
  Eigen::Vector2d c = Eigen::Vector2d::Zero(), v = Eigen::Vector2d::Zero();
  void Step(const Eigen::Vector2d& p) {
    v += g / zc * (c - p) * dt;
    c += v * dt;
  }
};

// Standing on both soles with the CoM over `ref`, pushed to `v0`; returns
// the CoM's distance from `ref` after 3 s (stabilized or open loop).
double AfterPush(const Eigen::Vector2d& v0, bool stabilized, bool* saturated = nullptr) {
  Lipm m;
  const Eigen::Vector2d ref(0.03, 0);
  m.c = ref;
  m.v = v0;
  const DcmStabilizer s(m.zc, m.g);
  const auto support = Rect(-0.09, 0.15, -0.15, 0.15);
  const Eigen::Vector2d zero = Eigen::Vector2d::Zero();
  for (int i = 0; i < 3000; ++i) {
    const DcmStabilizer::Output o = s.Update(m.c, m.v, ref, zero, ref, support, 0);
    if (saturated) *saturated = *saturated || o.saturated;
    EXPECT_LE(o.zmp.x(), 0.15 - 0.01 + 1e-9);
    m.Step(stabilized ? o.zmp : ref);
    if ((m.c - ref).norm() > 1) break;
  }
  return (m.c - ref).norm();
}

TEST(DcmStabilizer, TheAnklesRecoverAPushTheOpenLoopPlanFallsFrom) {
  // The ankles hold the DCM while it stays over the sole: 0.11 m ahead of
  // the CoM's 0.03 m at most (0.15 m toe, 0.01 m margin), so v0 < 0.11 w = 0.44 m/s.
  for (const Eigen::Vector2d& v0 :
       {Eigen::Vector2d(0.35, 0), Eigen::Vector2d(-0.2, 0), Eigen::Vector2d(0, 0.4)}) {
    EXPECT_LT(AfterPush(v0, true), 1e-3) << v0.transpose();
    EXPECT_GT(AfterPush(v0, false), 0.3) << v0.transpose() << ": the open-loop plan does not recover";
  }
  bool saturated = false;
  EXPECT_GT(AfterPush({0.6, 0}, true, &saturated), 0.3) << "beyond the sole, ankles alone cannot";
  EXPECT_TRUE(saturated);
}

TEST(DcmStabilizer, BeyondTheAnklesAStepToTheCapturePointRecovers) {
  // On one foot, the other about to land in place (0.3 s), pushed forward
  // at 0.6 m/s: the ankles saturate; landing the foot where the stabilizer
  // says catches the DCM, landing it as planned does not.
  for (const bool adjust : {true, false}) {
    Lipm m;
    const Eigen::Vector2d foot(0.03, 0);
    m.c = foot;
    m.v = {0.6, 0.1};
    const DcmStabilizer s(m.zc, m.g);
    const Eigen::Vector2d zero = Eigen::Vector2d::Zero();
    Eigen::Vector2d offset = Eigen::Vector2d::Zero();
    for (int i = 0; i < 300; ++i) {
      const auto support = Rect(foot.x() - 0.12, foot.x() + 0.12, -0.06, 0.06);
      const DcmStabilizer::Output o = s.Update(m.c, m.v, foot, zero, foot, support, 0.3 - i * m.dt);
      if (i == 0) {
        EXPECT_TRUE(o.saturated);
        offset = o.step_offset;
      }
      m.Step(o.zmp);
    }
    EXPECT_GT(offset.x(), 0.2) << "step forward, where the push carries the DCM";
    const Eigen::Vector2d landed = foot + (adjust ? offset : Eigen::Vector2d::Zero());
    for (int i = 0; i < 3000; ++i) {
      const auto support = Rect(landed.x() - 0.12, landed.x() + 0.12, landed.y() - 0.06, landed.y() + 0.06);
      m.Step(s.Update(m.c, m.v, landed, zero, landed, support, 0).zmp);
      if ((m.c - landed).norm() > 1) break;
    }
    if (adjust) {
      EXPECT_LT((m.c - landed).norm(), 0.01) << "captured";
    } else {
      EXPECT_GT((m.c - landed).norm(), 0.3) << "the planned foothold does not capture it";
    }
  }
}

// ComOffset: the ZMP command on a position-controlled robot. The robot here
// is the LIPM whose ground reaction comes from servos that track the CoM
// reference (the plan plus the offset) with stiffness kp and damping kd per
// unit mass: p = c - (ref'' + kp (ref - c) + kd (ref' - c')) / w^2, lagging
// 20 ms and limited to the soles (the CoP the stabilizer measures). Returns
// the CoM's largest excursion from the plan after a push to v0, and checks
// that it came back.
double PushedExcursion(double v0, bool stabilized, double kp_over_w2) {
  Lipm m;
  const Eigen::Vector2d ref(0.03, 0), zero = Eigen::Vector2d::Zero();
  m.c = ref;
  m.v = Eigen::Vector2d(v0, 0);
  const DcmStabilizer s(m.zc, m.g);
  const double w2 = s.omega() * s.omega(), kp = kp_over_w2 * w2, kd = std::sqrt(2 * kp);
  ComOffset offset(s.omega());
  const auto support = Rect(-0.09, 0.15, -0.15, 0.15);
  Eigen::Vector2d cop = ref, accel = zero;
  double worst = 0;
  for (int i = 0; i < 3000; ++i) {
    if (stabilized) {
      const Eigen::Vector2d before = offset.velocity();
      offset.Update(s.Update(m.c, m.v, ref, zero, ref, support, 0), m.c, ref, ref, &cop, m.dt);
      accel = (offset.velocity() - before) / m.dt;
      EXPECT_LE(offset.offset().cwiseAbs().maxCoeff(), ComOffsetGains{}.max_offset + 1e-12) << "bounded";
    }
    const Eigen::Vector2d wanted =
        m.c - (accel + kp * (ref + offset.offset() - m.c) + kd * (offset.velocity() - m.v)) / w2;
    cop += (ClampToPolygon(wanted, support, 0) - cop) * (m.dt / 0.02);
    m.Step(cop);
    worst = std::max(worst, (m.c - ref).norm());
    if (worst > 1) break;
  }
  EXPECT_LT((m.c - ref).norm(), 2e-3)
      << "recovered: v0 " << v0 << (stabilized ? ", stabilized" : ", open loop");
  return worst;
}

TEST(ComOffset, WithCompliantServosTheStabilizerHoldsAPushAsTheStiffestAnklesWould) {
  for (const double v0 : {0.2, 0.3, -0.3}) {
    const double stiff = PushedExcursion(v0, false, 4.0);  // servos 4x gravity's toppling stiffness
    const double soft = PushedExcursion(v0, false, 0.5), stabilized = PushedExcursion(v0, true, 0.5);
    EXPECT_LT(stabilized, 1.25 * stiff) << v0;
    EXPECT_LT(stabilized, 0.7 * soft) << v0 << ": the soft servos alone let the CoM run farther";
  }
}

TEST(ComOffset, WithThePlanTrackedTheOffsetReturnsToZeroAndMeasuredCopCorrectsALaggingZmp) {
  const DcmStabilizer s(0.6, 9.81);
  ComOffset offset(s.omega());
  const Eigen::Vector2d ref(0.03, 0.01), zero = Eigen::Vector2d::Zero();
  const auto support = Rect(-0.09, 0.15, -0.15, 0.15);
  // A perfectly tracked offset (the CoM is the reference plus the offset), nudged away.
  for (int i = 0; i < 2000; ++i) {
    const Eigen::Vector2d c = ref + offset.offset() + (i == 0 ? Eigen::Vector2d(0.01, -0.01) : zero);
    const Eigen::Vector2d v = offset.velocity();
    offset.Update(s.Update(c, v, ref, zero, ref, support, 0), c, ref, ref, nullptr, 1e-3);
  }
  EXPECT_LT(offset.offset().norm(), 1e-3) << "back to the plan";
  EXPECT_LT(offset.velocity().norm(), 1e-3);
  // The CoP feedback: the ZMP commanded ahead of the measured one accelerates the CoM reference back.
  offset.Reset();
  DcmStabilizer::Output o;
  o.zmp = Eigen::Vector2d(0.05, 0);
  const Eigen::Vector2d cop(0.0, 0);
  offset.Update(o, o.zmp, o.zmp, o.zmp, &cop, 1e-3);
  EXPECT_LT(offset.velocity().x(), 0);
  EXPECT_THROW(ComOffset(0.0), std::invalid_argument);
  EXPECT_THROW(ComOffset(3.0, ComOffsetGains{.max_offset = -1}), std::invalid_argument);
}

TEST(ComOffset, SwitchedOffTheOffsetReturnsToThePlanSmoothly) {
  // push_balance=stabilizer: the stabilizer runs only while a push's stop
  // holds; then Relax takes its offset back to the plan over tau.
  const DcmStabilizer s(0.6, 9.81);
  ComOffset offset(s.omega());
  DcmStabilizer::Output o;
  o.zmp = Eigen::Vector2d(-0.05, 0.04);  // the command behind and left of the CoM: the reference moves
  const Eigen::Vector2d zero = Eigen::Vector2d::Zero();
  for (int i = 0; i < 300; ++i) offset.Update(o, zero, zero, zero, nullptr, 1e-3);
  const Eigen::Vector2d held = offset.offset();
  ASSERT_GT(held.cwiseAbs().minCoeff(), 0.005);
  constexpr double kTau = 0.5;
  Eigen::Vector2d last = held;
  double worst_step = 0;
  for (int i = 0; i < 500; ++i) {
    const Eigen::Vector2d now = offset.Relax(1e-3, kTau);
    worst_step = std::max(worst_step, (now - last).cwiseAbs().maxCoeff());
    last = now;
  }
  for (int k = 0; k < 2; ++k) EXPECT_NEAR(last[k] / held[k], std::exp(-1.0), 0.01) << k;
  EXPECT_LE(worst_step, ComOffsetGains{}.max_speed * 1e-3 + 1e-15);
  EXPECT_NEAR(offset.velocity().x(), -last.x() / kTau, 0.01 * std::abs(last.x() / kTau));
  for (int i = 0; i < 5000; ++i) offset.Relax(1e-3, kTau);
  EXPECT_LT(offset.offset().norm(), 1e-6);
  EXPECT_THROW(offset.Relax(1e-3, 0), std::invalid_argument);
  EXPECT_THROW(offset.Relax(-1e-3, kTau), std::invalid_argument);
}

TEST(LegIk, TheSimpleHumanoidsSolesReachTheirTargetsAndTheCoMIsAboveTheFeet) {
  const RobotModel m = LoadUrdfFile(testing::ProjectModel("simple_humanoid.urdf")).model;
  const int lf = m.LinkIndex("left_foot"), rf = m.LinkIndex("right_foot");
  LegIk ik(m, {lf, rf}, {Eigen::Vector3d(0, 0, -0.07), Eigen::Vector3d(0, 0, -0.07)});
  int legs = 0;
  for (std::uint8_t b : ik.leg_mask()) legs += b;
  EXPECT_EQ(legs, 12);
  Eigen::VectorXd q = Eigen::VectorXd::Zero(m.num_dofs());
  q[m.dof_offset(m.JointIndex("left_knee"))] = 0.5;
  q[m.dof_offset(m.JointIndex("right_knee"))] = 0.5;
  Eigen::Isometry3d pelvis = Eigen::Isometry3d::Identity();
  pelvis.translation() = Eigen::Vector3d(0.02, 0.01, 0.72);
  pelvis.linear() = Eigen::AngleAxisd(0.1, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  std::array<Eigen::Isometry3d, 2> soles{Eigen::Isometry3d::Identity(), Eigen::Isometry3d::Identity()};
  soles[0].translation() = Eigen::Vector3d(0.05, 0.10, 0.02);
  soles[0].linear() = Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  soles[1].translation() = Eigen::Vector3d(-0.03, -0.08, 0.0);
  EXPECT_LT(ik.Solve(pelvis, soles, q), 1e-3);
  for (int s = 0; s < 2; ++s) {
    const Eigen::Isometry3d got = pelvis * ik.SoleInPelvis(s, q);
    EXPECT_NEAR((got.translation() - soles[static_cast<size_t>(s)].translation()).norm(), 0, 1e-3);
    EXPECT_NEAR(Eigen::AngleAxisd(got.linear().transpose() * soles[static_cast<size_t>(s)].linear()).angle(),
                0, 1e-2);
  }
  EXPECT_GT(q[m.dof_offset(m.JointIndex("left_knee"))], 0.1) << "knees stay bent forward";
  const Eigen::Vector3d com = ik.ComInPelvis(q);
  EXPECT_LT(std::abs(com.x()), 0.05);
  EXPECT_LT(std::abs(com.y()), 0.02);
}

}  // namespace
}  // namespace robotalk::walking
