// The walking simple humanoid's balance on ODE (issue 26, items 1 and 4):
// pushes on the pelvis (OdeDriver::PushForTesting), the DCM stabilizer
// through the arm swing, push recovery (regeneration, stop and stand, the
// capture stop, the stop's feet), a pushed GOTO, and foot damping. Simulated
// time only, deterministic with the seed. Split from ode_walk_test.cpp.
#include "ode_driver.h"
#include "ode_walker.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace robotalk {
namespace {

using testing::Goto;
using testing::ProjectModel;
using testing::RefusalOfWalker;
using testing::Walker;

// Walks `w` at full speed (SETSPEED 1 after 1 s standing) for 5.14 s, the
// seed-1 instant of robotalk-walk-sweep's table, then pushes its pelvis
// toward the left with `impulse` N s over 0.1 s.
void WalkAtFullSpeedThenPushLeft(Walker& w, double impulse) {
  w.Run(1.0);
  ASSERT_NE(w.Exec(CommandType::kSetSpeed, {1.0, 0.0}).signal, Signal::kError);
  w.Run(5.14);
  w.driver->PushForTesting(Eigen::Vector3d(0, impulse / 0.1, 0), FromSeconds(0.1));
}

// Pushes as a test input (issue 26, item 4): OdeDriver::PushForTesting, a
// 0.1 s push on the pelvis. Standing, the walker takes 15 N s from behind
// (robotalk-walk-sweep --push standing measured 20 N s survived and 25 fell,
// with and without the stabilizer: the ankles' limit, docs/ode_sim.md); 40 N s
// topples it, and the fall is detected and reported.
TEST(OdeWalk, APushOnThePelvisIsSurvivedOrReportedAsAFall) {
  for (const double impulse : {15.0, 40.0}) {
    Walker w;
    w.Run(2.0);
    w.driver->PushForTesting(Eigen::Vector3d(impulse / 0.1, 0, 0), FromSeconds(0.1));
    w.Run(4.0, [&] { return w.driver->walk_status()->fallen; });
    if (impulse < 20) {
      EXPECT_FALSE(w.driver->walk_status()->fallen) << impulse << " N s";
      EXPECT_EQ(w.driver->Fault(), "");
    } else {
      EXPECT_TRUE(w.driver->walk_status()->fallen) << impulse << " N s";
      EXPECT_NE(w.driver->Fault().find("fallen"), std::string::npos);
    }
  }
}

// Balance feedback (issue 26, item 1): walking at full speed, both arms
// swung together +-1 rad every 0.5 s. The open-loop pattern topples (the
// arms' reaction moves the CoM and the CoP off the plan); the DCM
// stabilizer, from the measured CoM and contact forces, keeps it upright,
// and its status shows the loop at work (the CoM reference offset from the
// plan's), zero when switched off.
TEST(OdeWalk, TheStabilizerKeepsAWalkerUpThroughTheArmSwingThatToppledTheOpenLoop) {
  for (const bool stabilized : {false, true}) {
    Walker w(ProjectModel("simple_humanoid.urdf"), {{"stabilizer", stabilized ? "true" : "false"}});
    w.Run(1.0);
    ASSERT_NE(w.Exec(CommandType::kSetSpeed, {1.0, 0.0}).signal, Signal::kError);
    w.Run(1.0);
    const RobotModel& m = w.driver->model();
    double largest_offset = 0;
    for (int i = 0; i < 12 && !w.driver->walk_status()->fallen; ++i) {
      for (const char* arm : {"left_shoulder_pitch", "right_shoulder_pitch"})
        w.Exec(CommandType::kJointSetPoint, {i % 2 == 0 ? 1.0 : -1.0}, m.JointIndex(arm));
      for (int k = 0; k < 5; ++k) {
        w.Run(0.1);
        largest_offset = std::max(largest_offset, w.driver->walk_status()->com_offset.norm());
      }
    }
    w.Run(1.0, [&] { return w.driver->walk_status()->fallen; });
    const walking::WalkStatus s = *w.driver->walk_status();
    if (stabilized) {
      EXPECT_FALSE(s.fallen) << "stabilized: tilt " << w.max_tilt;
      EXPECT_LT(w.max_tilt, 0.1);
      EXPECT_GT(largest_offset, 0.002) << "the balance loop moved the CoM reference";
      EXPECT_GT(s.steps_taken, 5);
    } else {
      EXPECT_TRUE(s.fallen) << "open loop: the arm swing toppled the walker before (tilt " << w.max_tilt
                            << ")";
      EXPECT_EQ(largest_offset, 0);
    }
  }
}

// Push recovery (option push_recovery, walking/push_recovery.h): walking at
// full speed unpushed it regenerates nothing; a 30 N s push from behind
// makes it regenerate the plan (the regeneration alone did not raise the
// impulse survived on ODE, docs/ode_sim.md, so survival is not asserted
// here; the stop is, in the next test); off, the count stays 0.
TEST(OdeWalk, PushRecoveryRegeneratesThePlanOnlyWhenPushed) {
  for (const double impulse : {0.0, 30.0}) {
    for (const char* on : {"true", "false"}) {
      Walker w(ProjectModel("simple_humanoid.urdf"), {{"push_recovery", on}});
      w.Run(1.0);
      ASSERT_NE(w.Exec(CommandType::kSetSpeed, {1.0, 0.0}).signal, Signal::kError);
      w.Run(3.0);
      if (impulse > 0) w.driver->PushForTesting(Eigen::Vector3d(impulse / 0.1, 0, 0), FromSeconds(0.1));
      w.Run(1.0, [&] { return w.driver->walk_status()->fallen; });
      const walking::WalkStatus s = *w.driver->walk_status();
      if (impulse == 0) {
        EXPECT_FALSE(s.fallen) << on;
      }
      EXPECT_EQ(s.recoveries > 0, impulse > 0 && std::string(on) == "true") << impulse << " N s, " << on;
    }
  }
}

// Push recovery's stop (walking/push_recovery.h, PushRecovery::Watch):
// walking at full speed, 10 N s toward the robot's left (the probe of
// robotalk-walk-sweep's table, docs/ode_sim.md "Pushes"); the open loop falls
// 4-5 s later, over its stance foot's toe; with push_recovery the walk
// stops, the robot stands and walks on after the hold. Both without the
// stabilizer (named): with it, measured, the stop holds but tilts 0.15 rad
// and has not walked on 3.5 s after the hold.
TEST(OdeWalk, PushRecoveryStopsAndStandsThroughAPushTheOpenLoopFallsTo) {
  for (const char* on : {"false", "true"}) {
    Walker w(ProjectModel("simple_humanoid.urdf"), {{"push_recovery", on}, {"stabilizer", "false"}});
    ASSERT_NO_FATAL_FAILURE(WalkAtFullSpeedThenPushLeft(w, 10));
    w.Run(2.5, [&] { return w.driver->walk_status()->fallen; });
    const int held = w.driver->walk_status()->steps_taken;  // stopped, standing (with push_recovery)
    w.Run(3.5, [&] { return w.driver->walk_status()->fallen; });
    const walking::WalkStatus s = *w.driver->walk_status();
    if (std::string(on) == "false") {
      EXPECT_TRUE(s.fallen) << "the open loop fell to this push before (tilt " << w.max_tilt << ")";
      EXPECT_EQ(s.push_stops, 0);
    } else {
      EXPECT_EQ(s.push_stops, 1) << "the status says the push stopped the walk";
      EXPECT_FALSE(s.fallen) << "tilt " << w.max_tilt;
      EXPECT_LT(w.max_tilt, 0.1);
      EXPECT_GT(s.steps_taken, held + 1) << "walks on after the hold (3 s from the push)";
    }
  }
}

// push_capture=true (off by default: measured on ODE it survives smaller
// pushes than the stop alone, docs/ode_sim.md, "Pushes"): the wiring — a
// push stops the walk and the stop is re-planned as a capture from the
// measured state; without the option never. Bad settings are refused.
TEST(OdeWalk, PushCaptureReplansThePushsStopOnlyWithTheOption) {
  for (const char* on : {"false", "true"}) {
    Walker w(ProjectModel("simple_humanoid.urdf"), {{"push_capture", on}});
    ASSERT_NO_FATAL_FAILURE(WalkAtFullSpeedThenPushLeft(w, 10));
    w.Run(1.5, [&] { return w.driver->walk_status()->fallen; });
    const walking::WalkStatus s = *w.driver->walk_status();
    EXPECT_EQ(s.push_stops, 1) << "push_capture=" << on;
    if (std::string(on) == "true") {
      EXPECT_GE(s.push_captures, 1) << "the stop re-planned as a capture";
    } else {
      EXPECT_EQ(s.push_captures, 0);
    }
  }
  const std::optional<std::string> alone =
      RefusalOfWalker({{"push_capture", "true"}, {"push_recovery", "false"}});
  ASSERT_TRUE(alone) << "push_capture without push_recovery accepted";
  EXPECT_NE(alone->find("push_recovery"), std::string::npos) << *alone;
  const std::optional<std::string> maybe = RefusalOfWalker({{"push_capture", "maybe"}});
  ASSERT_TRUE(maybe) << "push_capture=maybe accepted";
  EXPECT_NE(maybe->find("push_capture"), std::string::npos) << *maybe;
  // push_stop_feet (move, keep or still: the regeneration during the stop)
  const std::optional<std::string> sideways = RefusalOfWalker({{"push_stop_feet", "sideways"}});
  ASSERT_TRUE(sideways) << "push_stop_feet=sideways accepted";
  EXPECT_NE(sideways->find("push_stop_feet"), std::string::npos) << *sideways;
  const std::optional<std::string> keep_alone =
      RefusalOfWalker({{"push_stop_feet", "keep"}, {"push_recovery", "false"}});
  ASSERT_TRUE(keep_alone) << "push_stop_feet=keep without push_recovery accepted";
  EXPECT_NE(keep_alone->find("push_recovery"), std::string::npos) << *keep_alone;
  EXPECT_FALSE(RefusalOfWalker({{"push_stop_feet", "keep"}}));
}

// push_swing_reach (1 m/s by default; docs/ode_sim.md, "eighth session"): a
// push toward the left while the left foot swings (30 N s at 5.14 s into a
// walk at full speed, the sweep's seed-1 instant) moves that foot's landing
// outward in the air. Without the option the regenerations' moves add up to
// more than the legs follow: the foot lands ~10 cm inside its planned
// landing (and the robot falls); with 1 m/s within a few cm, and it stands.
// Without the stabilizer (named): with it, measured, the regenerations move
// that landing less: 2.5 and 2.0 cm outward of it, 0 and 1 m/s.
TEST(OdeWalk, PushSwingReachKeepsAMovedLandingWithinWhatTheSwingFootReaches) {
  for (const char* reach : {"0", "1.0"}) {
    Walker w(ProjectModel("simple_humanoid.urdf"), {{"push_swing_reach", reach}, {"stabilizer", "false"}});
    ASSERT_NO_FATAL_FAILURE(WalkAtFullSpeedThenPushLeft(w, 30));
    // The left foot in the air: its first touchdown after the push (planned height 0), 50 ms on.
    w.Run(1.0, [&] { return w.driver->walk_status()->foot_height[0] <= 0; });
    w.Run(0.05);
    const walking::WalkStatus s = *w.driver->walk_status();
    // Outward (the walk heads along x): the move the push asked for.
    const double miss = std::abs(s.foot[0].y - s.foot_measured[0].y);
    std::printf("push_swing_reach=%s: the left foot lands %.3f m (%.3f m outward) from its planned landing\n",
                reach, (s.foot[0].xy() - s.foot_measured[0].xy()).norm(), miss);
    w.Run(2.0, [&] { return w.driver->walk_status()->fallen; });
    if (std::string(reach) == "0") {
      EXPECT_GT(miss, 0.10);
    } else {
      EXPECT_LT(miss, 0.06);
      EXPECT_FALSE(w.driver->walk_status()->fallen) << "tilt " << w.max_tilt;
    }
  }
  const std::optional<std::string> alone =
      RefusalOfWalker({{"push_swing_reach", "2"}, {"push_recovery", "false"}});
  ASSERT_TRUE(alone) << "push_swing_reach without push_recovery accepted";
  EXPECT_NE(alone->find("push_recovery"), std::string::npos) << *alone;
  const std::optional<std::string> negative = RefusalOfWalker({{"push_swing_reach", "-1"}});
  ASSERT_TRUE(negative) << "push_swing_reach=-1 accepted";
  EXPECT_NE(negative->find("push_swing_reach"), std::string::npos) << *negative;
  EXPECT_FALSE(RefusalOfWalker({{"push_recovery", "false"}})) << "the default needs no push_recovery";
}

// push_balance (off by default; docs/ode_sim.md, "Pushes"): the wiring —
// walking unpushed nothing runs (no DCM reported, the ankles, the CoM
// reference and the soles' heights the plan's); pushed, the named feedback
// runs while the push's stop holds (forces: only the soles' force
// difference height; all three: also the stabilizer's DCM, ankle and CoM
// offsets) and afterwards returns to the plan. With the stabilizer off
// (named: with stabilizer=true it would run all the time). Bad settings are
// refused, and the stabilizer's part with the stabilizer on.
TEST(OdeWalk, PushBalanceRunsTheFeedbackOnlyWhileThePushsStopHolds) {
  for (const char* which : {"forces", "damping+stabilizer+forces"}) {
    const bool all = std::string(which) != "forces";
    Walker w(ProjectModel("simple_humanoid.urdf"), {{"push_balance", which}, {"stabilizer", "false"}});
    w.Run(1.0);
    ASSERT_NE(w.Exec(CommandType::kSetSpeed, {1.0, 0.0}).signal, Signal::kError);
    double unpushed = 0, held = 0, dcm_held = 0, offsets_held = 0;
    const auto offsets = [&] {
      const walking::WalkStatus s = *w.driver->walk_status();
      return std::max({s.ankle_offset[0].norm(), s.ankle_offset[1].norm(), s.com_offset.norm()});
    };
    const auto feedback = [&] {
      return std::max(offsets(), std::abs(w.driver->walk_status()->force_difference));
    };
    w.Run(5.14, [&] {
      unpushed = std::max({unpushed, feedback(), w.driver->walk_status()->dcm.norm()});
      return false;
    });
    w.driver->PushForTesting(Eigen::Vector3d(0, 10 / 0.1, 0), FromSeconds(0.1));
    w.Run(2.5, [&] {  // the hold: 3 s from the push
      held = std::max(held, feedback());
      offsets_held = std::max(offsets_held, offsets());
      dcm_held = std::max(dcm_held, w.driver->walk_status()->dcm.norm());
      return w.driver->walk_status()->fallen;
    });
    w.Run(3.5, [&] { return w.driver->walk_status()->fallen; });  // walking on, the offsets relaxed
    const walking::WalkStatus s = *w.driver->walk_status();
    EXPECT_FALSE(s.fallen) << which << ", tilt " << w.max_tilt;
    EXPECT_EQ(s.push_stops, 1) << which;
    EXPECT_EQ(unpushed, 0) << which << ": nothing runs before the push";
    EXPECT_GT(held, 1e-4) << which << ": the feedback ran during the hold";
    EXPECT_LT(feedback(), 0.2 * held) << which << ": back to the plan after the hold";
    EXPECT_EQ(s.dcm.norm(), 0) << which << ": no stabilizer after the hold";
    if (all) {
      EXPECT_GT(offsets_held, 1e-3) << "the ankles' and CoM's offsets moved during the hold";
      EXPECT_GT(dcm_held, 0) << "the stabilizer ran during the hold";
    } else {
      EXPECT_EQ(offsets_held, 0) << "forces moves only the soles' heights";
      EXPECT_EQ(dcm_held, 0);
    }
  }
  for (const char* wrong : {"hips", "damping+hips", "on"}) {
    const std::optional<std::string> bad = RefusalOfWalker({{"push_balance", wrong}});
    ASSERT_TRUE(bad) << "push_balance=" << wrong << " accepted";
    EXPECT_NE(bad->find("push_balance"), std::string::npos) << *bad;
  }
  EXPECT_FALSE(RefusalOfWalker({{"push_balance", "both"}, {"stabilizer", "false"}}));
  EXPECT_FALSE(RefusalOfWalker({{"push_recovery", "false"}}))
      << "the default push_balance (off) needs no push_recovery";
  EXPECT_TRUE(RefusalOfWalker({{"push_balance", ""}})) << "an empty push_balance";
  const std::optional<std::string> alone =
      RefusalOfWalker({{"push_balance", "damping"}, {"push_recovery", "false"}});
  ASSERT_TRUE(alone) << "push_balance without push_recovery accepted";
  EXPECT_NE(alone->find("push_recovery"), std::string::npos) << *alone;
  EXPECT_FALSE(RefusalOfWalker({{"push_balance", "stabilizer"}, {"stabilizer", "false"}}));
  EXPECT_FALSE(RefusalOfWalker({{"push_balance", "damping+forces"}})) << "no stabilizer part: accepted";
  EXPECT_FALSE(RefusalOfWalker({{"push_balance", "stabilizer"}}))
      << "push_balance's stabilizer part turns the default stabilizer off";
  // The stabilizer's part only while the stop holds, with the stabilizer on always: refused.
  for (const char* both : {"stabilizer", "both", "forces+stabilizer"}) {
    const std::optional<std::string> on = RefusalOfWalker({{"push_balance", both}, {"stabilizer", "true"}});
    ASSERT_TRUE(on) << "push_balance=" << both << " with stabilizer=true accepted";
    EXPECT_NE(on->find("stabilizer=false"), std::string::npos) << *on;
  }
}

// push_step_timing (off by default; docs/ode_sim.md, "Earlier and faster
// capture steps"): the wiring — walking unpushed it never re-plans; pushed
// toward the left (read in double support), 10 N s is left to the
// regeneration (the step's place alone catches it: no sooner landing), 30
// N s re-plans the next step from its lift-off until it lands, then no
// more. Bad settings are refused.
TEST(OdeWalk, PushStepTimingReplansOnlyTheStepInTheAirAfterAPush) {
  for (const double impulse : {10.0, 30.0}) {
    Walker w(ProjectModel("simple_humanoid.urdf"), {{"push_step_timing", "push"}});
    w.Run(1.0);
    ASSERT_NE(w.Exec(CommandType::kSetSpeed, {1.0, 0.0}).signal, Signal::kError);
    w.Run(5.14);
    EXPECT_EQ(w.driver->walk_status()->push_timings, 0) << "unpushed, nothing re-planned";
    EXPECT_EQ(w.driver->walk_status()->recoveries, 0);
    const int steps = w.driver->walk_status()->steps_taken;
    w.driver->PushForTesting(Eigen::Vector3d(0, impulse / 0.1, 0), FromSeconds(0.1));
    int first_step = -1, last_step = -1, timings = 0;
    w.Run(2.5, [&] {
      const walking::WalkStatus s = *w.driver->walk_status();
      if (s.push_timings > timings && first_step < 0) first_step = s.steps_taken;
      if (s.push_timings > timings) last_step = s.steps_taken;
      timings = s.push_timings;
      return s.fallen;
    });
    EXPECT_EQ(w.driver->walk_status()->push_stops, 1) << impulse;
    if (impulse < 20) {
      EXPECT_EQ(timings, 0) << "10 N s: the regeneration as ever";
      EXPECT_FALSE(w.driver->walk_status()->fallen);
      continue;
    }
    EXPECT_GE(timings, 1);
    // The step in the air at the push's reading (in double support: the next one).
    EXPECT_TRUE(first_step == steps || first_step == steps + 1) << first_step << " " << steps;
    EXPECT_EQ(last_step, first_step) << "only that step";
  }
  const std::optional<std::string> bad = RefusalOfWalker({{"push_step_timing", "soon"}});
  ASSERT_TRUE(bad) << "push_step_timing=soon accepted";
  EXPECT_NE(bad->find("push_step_timing"), std::string::npos) << *bad;
  const std::optional<std::string> alone =
      RefusalOfWalker({{"push_step_timing", "push"}, {"push_recovery", "false"}});
  ASSERT_TRUE(alone) << "push_step_timing without push_recovery accepted";
  EXPECT_NE(alone->find("push_recovery"), std::string::npos) << *alone;
  EXPECT_FALSE(RefusalOfWalker({{"push_step_timing", "always"}}));
  EXPECT_TRUE(RefusalOfWalker({{"push_min_swing", "-0.1"}}));
  EXPECT_TRUE(RefusalOfWalker({{"push_lift_reach", "-1"}}));
  EXPECT_TRUE(RefusalOfWalker({{"push_lift_reach", "1"}, {"push_recovery", "false"}}));
}

// Push recovery's stop during a GOTO (on by default): the walk stops, the
// robot stands through the hold, then the GOTO re-plans from where the push
// left it and still ends at its goal with SUCCESS (no reply before the hold
// is over), and no CoM offset while it holds.
void PushAGotoAndExpectItStopsOnceStandsAndArrives(const std::map<std::string, std::string>& options) {
  Walker w(ProjectModel("simple_humanoid.urdf"), options);
  w.Run(1.0);
  ASSERT_TRUE(w.Exec(CommandType::kGoto, {1.5, 0, 0}).in_progress);
  w.Run(3.0);
  ASSERT_TRUE(w.driver->walk_status()->stepping);
  const TimePoint pushed_at = w.driver->sim_time();
  w.driver->PushForTesting(Eigen::Vector3d(0, 8 / 0.1, 0), FromSeconds(0.1));  // 8 N s toward the left
  double held_offset = 0;  // the largest CoM offset while the stop holds, 1.5 s after the push on
  w.Run(60.0, [&] {
    const walking::WalkStatus h = *w.driver->walk_status();
    if (h.push_holding && w.driver->sim_time() - pushed_at > FromSeconds(1.5))
      held_offset = std::max(held_offset, h.com_offset.norm());
    return !w.done.empty() || h.fallen;
  });
  const walking::WalkStatus s = *w.driver->walk_status();
  ASSERT_FALSE(s.fallen) << "tilt " << w.max_tilt;
  EXPECT_EQ(s.push_stops, 1) << "the push stopped the walk";
  EXPECT_LT(held_offset, 0.01) << "the stabilizer stands down while the stop holds";
  ASSERT_EQ(w.done.size(), 1u);
  EXPECT_EQ(w.done[0].signal, Signal::kSuccess) << w.done[0].message;
  EXPECT_GT(w.driver->sim_time() - pushed_at, FromSeconds(3.0)) << "no answer before the 3 s hold was over";
  const walking::Pose2 p = w.Pelvis();
  EXPECT_LT(std::hypot(p.x - 1.5, p.y), 0.05);
  EXPECT_LT(std::abs(walking::Wrap(p.theta)), 0.05);
}

TEST(OdeWalk, APushedGotoStopsStandsThenReplansAndStillArrives) {
  PushAGotoAndExpectItStopsOnceStandsAndArrives({{"stabilizer", "false"}});  // the open loop (named)
}

// The same with the DCM stabilizer (stabilizer=true, the default), which stands down while
// the stop holds (its offset back on the plan): before, its offset swung
// between its bounds through the stop, the detector read that as a second
// push and the walker fell (tilt 0.61 rad; docs/ode_sim.md, "Why a pushed
// GOTO fell with the stabilizer").
TEST(OdeWalk, APushedGotoStopsStandsThenReplansAndStillArrivesWithTheStabilizer) {
  PushAGotoAndExpectItStopsOnceStandsAndArrives({{"stabilizer", "true"}});
}

// The event-driven stop's options (push_stop_wait, push_stop_land) are
// checked as the other push options: a negative wait, either without
// push_recovery, the landing's wait without a wait are refused, naming the key.
TEST(OdeWalk, PushStopWaitAndPushStopLandAreCheckedAsThePushOptionsAre) {
  // Refused, the refusal naming `key`.
  const auto refused_naming = [](const std::map<std::string, std::string>& options, const std::string& key) {
    const std::optional<std::string> why = RefusalOfWalker(options);
    ASSERT_TRUE(why) << "accepted; expected a refusal naming " << key;
    EXPECT_NE(why->find(key), std::string::npos) << *why;
  };
  refused_naming({{"push_stop_wait", "-0.1"}}, "push_stop_wait");
  refused_naming({{"push_stop_land", "true"}, {"push_stop_wait", "0"}}, "push_stop_wait");
  refused_naming({{"push_stop_land", "true"}, {"push_recovery", "false"}}, "push_recovery");
  refused_naming({{"push_stop_wait", "0.5"}, {"push_recovery", "false"}}, "push_recovery");
  EXPECT_FALSE(RefusalOfWalker({{"push_stop_land", "true"}, {"push_stop_wait", "0.3"}}));
  EXPECT_FALSE(RefusalOfWalker({{"push_stop_wait", "0.3"}}));
  EXPECT_FALSE(RefusalOfWalker({{"push_stop_wait", "0"}}));
  EXPECT_FALSE(RefusalOfWalker({{"push_recovery", "false"}})) << "the default wait needs no push_recovery";
}

// Foot damping (option foot_damping, walking/foot_damping.h): walking at
// full speed, each loaded sole's centre of pressure stays nearer the share
// of the ZMP it was given than with stiff ankles, and the soles roll less
// onto their edges; a bad value is refused naming the key. On the open
// loop (named): with the stabilizer, measured, 5.33 against 5.67 cm (the
// stabilizer alone already nearer than the open loop's 11.99).
TEST(OdeWalk, FootDampingKeepsEachSolesCopNearItsShareOfTheZmp) {
  std::map<std::string, double> cop95, roll95;
  for (const char* on : {"false", "true"}) {
    Walker w(ProjectModel("simple_humanoid.urdf"), {{"foot_damping", on}, {"stabilizer", "false"}});
    w.Run(1.0);
    ASSERT_NE(w.Exec(CommandType::kSetSpeed, {1.0, 0.0}).signal, Signal::kError);
    w.Run(10.0, [&] { return w.driver->walk_status()->steps_taken >= 2; });
    std::vector<double> cop, roll;
    for (int i = 0; i < 400 && !w.driver->walk_status()->fallen; ++i) {
      w.Run(0.01);
      const walking::WalkStatus s = *w.driver->walk_status();
      for (int f = 0; f < 2; ++f) {
        if (s.foot_force[f] < 50) continue;
        cop.push_back((s.foot_cop[f] - s.foot_cop_ref[f]).norm());
        roll.push_back(std::abs(s.foot_roll[f]));
      }
    }
    ASSERT_FALSE(w.driver->walk_status()->fallen) << on;
    ASSERT_GT(cop.size(), 300u);
    const auto p95 = [](std::vector<double> v) {
      std::sort(v.begin(), v.end());
      return v[v.size() * 95 / 100];
    };
    cop95[on] = p95(cop);
    roll95[on] = p95(roll);
    std::printf(
        "foot_damping=%s: loaded soles' CoP from their share, 95th pct %.2f cm; |roll| 95th %.4f rad\n", on,
        100 * cop95[on], roll95[on]);
  }
  EXPECT_LT(cop95["true"], 0.85 * cop95["false"]);  // measured 8.78 against 11.99 cm
  EXPECT_LT(roll95["true"], roll95["false"]);
  const std::optional<std::string> maybe = RefusalOfWalker({{"foot_damping", "maybe"}});
  ASSERT_TRUE(maybe) << "foot_damping=maybe accepted";
  EXPECT_NE(maybe->find("foot_damping"), std::string::npos) << *maybe;
}

}  // namespace
}  // namespace robotalk
