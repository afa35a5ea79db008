// The simple humanoid walking on ODE dynamics (drivers/ode_sim/walking_humanoid.*):
// it stands on its contacts, GOTO walks there and answers SUCCESS within
// 5 cm / 0.05 rad, BUSY meanwhile, STOP mid-walk ends in double support
// within two steps, SETSPEED walks at the clamped rate, and it never falls.
// Simulated time only (Step), deterministic with the seed.
//
// The soles are spring-dampers on the ground (docs/ode_sim.md, "Walking"):
// the tests check that they carry the robot's weight on four contacts each.
#include "ode_driver.h"
#include "ode_walker.h"
#include "point_footed_humanoid.h"
#include "robotalk/error.h"
#include "robotalk/urdf_import.h"
#include "test_paths.h"

#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <optional>
#include <sstream>

namespace robotalk {
namespace {

using testing::Goto;
using testing::ProjectModel;
using testing::RefusalOfWalker;
using testing::Walker;

TEST(OdeWalk, TheHumanoidStandsOnItsContactsWithBentKnees) {
  Walker w;
  ASSERT_TRUE(w.driver->walk_status().has_value());
  w.Run(3.0);
  EXPECT_FALSE(w.driver->walk_status()->fallen);
  EXPECT_LT(w.max_tilt, 0.05);
  const walking::Pose2 p = w.Pelvis();
  EXPECT_LT(std::hypot(p.x, p.y), 0.02) << "standing still, not drifting";
  EXPECT_LT(std::abs(p.theta), 0.01);
  const walking::WalkStatus s = *w.driver->walk_status();
  EXPECT_EQ(s.foot_contacts[0], 4) << "the sole lies flat: a contact at each corner";
  EXPECT_EQ(s.foot_contacts[1], 4);
  const double mass = w.driver->model().total_mass();
  EXPECT_NEAR(s.foot_force[0] + s.foot_force[1], mass * 9.81, 0.02 * mass * 9.81)
      << "the soles carry the weight";
  EXPECT_NEAR(s.foot_force[0], s.foot_force[1], 0.1 * mass * 9.81) << "on both feet";
  EXPECT_LT((s.zmp - s.zmp_ref).norm(), 0.01)
      << "the centre of pressure is where the plan puts it: " << s.zmp.transpose() << " vs "
      << s.zmp_ref.transpose();
  for (int i = 0; i < 2; ++i) {
    EXPECT_LT(std::hypot(s.foot_measured[i].x - s.foot[i].x, s.foot_measured[i].y - s.foot[i].y), 0.002)
        << "the feet stand where the plan has them";
    EXPECT_LT(s.foot_tilt[i], 0.005);
  }
  const RobotModel& m = w.driver->model();
  const int knee = m.JointIndex("left_knee");
  EXPECT_EQ(w.Exec(CommandType::kJointSetPoint, {0.3}, knee).signal, Signal::kBusy)
      << "the legs belong to the walk";
  EXPECT_EQ(w.Exec(CommandType::kJointSetPoint, {0.4}, m.JointIndex("pan")).signal, Signal::kSuccess);
}

TEST(OdeWalk, GotoWalksThereAndAnswersSuccessWithoutFalling) {
  Walker w;
  w.Run(1.5);
  const DriverResult r = w.Exec(CommandType::kGoto, {0.4, 0.15, 0.4});
  ASSERT_TRUE(r.in_progress) << r.message;
  w.Run(2.0);
  EXPECT_EQ(w.Exec(CommandType::kGoto, {0, 0, 0}).signal, Signal::kBusy);
  EXPECT_EQ(w.Exec(CommandType::kSetSpeed, {0.1, 0}).signal, Signal::kBusy);
  w.Run(60.0, [&] { return !w.done.empty(); });
  ASSERT_EQ(w.done.size(), 1u);
  EXPECT_EQ(w.done[0].signal, Signal::kSuccess) << w.done[0].message;
  const walking::Pose2 p = w.Pelvis();
  EXPECT_LT(std::hypot(p.x - 0.4, p.y - 0.15), 0.05);
  EXPECT_LT(std::abs(walking::Wrap(p.theta - 0.4)), 0.05);
  EXPECT_FALSE(w.driver->walk_status()->fallen);
  EXPECT_LT(w.max_tilt, 0.2);
  EXPECT_GE(w.driver->walk_status()->steps_taken, 3)
      << "it stepped there (0.5 m and a turn: 3 steps or more)";
}

TEST(OdeWalk, StopMidWalkEndsInDoubleSupportWithinTwoSteps) {
  Walker w;
  w.Run(1.0);
  ASSERT_TRUE(w.Exec(CommandType::kGoto, {1.5, 0, 0}).in_progress);
  w.Run(3.5);  // the second step of the walk
  ASSERT_TRUE(w.driver->walk_status()->stepping);
  const int steps = w.driver->walk_status()->steps_taken;
  const double x = w.Pelvis().x;
  EXPECT_GT(x, 0.05) << "it walked forward";
  w.Stop();
  ASSERT_EQ(w.done.size(), 1u);
  EXPECT_EQ(w.done[0].signal, Signal::kInterrupted);
  w.Run(5.0, [&] { return !w.driver->walk_status()->stepping; });
  const walking::WalkStatus s = *w.driver->walk_status();
  EXPECT_FALSE(s.stepping);
  EXPECT_LE(s.steps_taken - steps, 2);
  EXPECT_NEAR(std::hypot(s.foot[0].x - s.foot[1].x, s.foot[0].y - s.foot[1].y), 0.18, 0.01)
      << "feet side by side";
  w.Run(1.0);
  EXPECT_FALSE(w.driver->walk_status()->fallen);
  EXPECT_LT(w.max_tilt, 0.2);
  EXPECT_LT(w.Pelvis().x, 1.0);
}

TEST(OdeWalk, SetSpeedWalksAtTheClampedRateAndPanicStopsStepping) {
  Walker w;
  w.Run(1.0);
  const DriverResult r = w.Exec(CommandType::kSetSpeed, {1.0, 0.0});
  EXPECT_EQ(r.signal, Signal::kModified) << r.message;
  EXPECT_NE(r.message.find("clamped"), std::string::npos) << r.message;
  w.Run(8.0);
  const double x = w.Pelvis().x;
  EXPECT_GT(x, 1.0) << "8 s at the gait's limit (0.29 m/s), the first 1.8 s standing and shifting weight";
  EXPECT_LT(x, 8 * 0.3) << "no faster than the clamp";
  const int steps = w.driver->walk_status()->steps_taken;
  std::vector<Completion> interrupted;
  w.driver->Halt(interrupted);  // panic (the server sends nothing more until Resume())
  EXPECT_TRUE(interrupted.empty()) << "SETSPEED had completed; nothing was running";
  w.Run(5.0, [&] { return !w.driver->walk_status()->stepping; });
  EXPECT_FALSE(w.driver->walk_status()->stepping);
  EXPECT_LE(w.driver->walk_status()->steps_taken - steps, 2) << "the step in the air and one more";
  const walking::WalkStatus s = *w.driver->walk_status();
  EXPECT_NEAR(std::hypot(s.foot[0].x - s.foot[1].x, s.foot[0].y - s.foot[1].y), 0.18, 0.01)
      << "feet side by side";
  w.Run(1.0);
  EXPECT_FALSE(w.driver->walk_status()->fallen);
  EXPECT_LT(w.max_tilt, 0.2);
}

// The derived gait (walking/gait_limits.h) walks at the 0.25 m/s:
// SETSPEED 1 m/s is clamped to the gait's limit, and over four steady steps
// (after the start's weight shift and two steps) the pelvis covers >= 0.25
// m/s without falling or tilting.
TEST(OdeWalk, TheDerivedGaitWalksAQuarterMetrePerSecond) {
  Walker w;
  w.Run(1.0);
  const DriverResult r = w.Exec(CommandType::kSetSpeed, {1.0, 0.0});
  EXPECT_EQ(r.signal, Signal::kModified) << r.message;
  w.Run(10.0, [&] { return w.driver->walk_status()->steps_taken >= 3; });
  const double x0 = w.Pelvis().x;
  const TimePoint t0 = w.driver->sim_time();
  w.Run(10.0, [&] { return w.driver->walk_status()->steps_taken >= 7; });
  const double v = (w.Pelvis().x - x0) / ToSeconds(w.driver->sim_time() - t0);
  std::printf("SETSPEED 1 (%s): %.3f m/s over 4 steps, max tilt %.3f rad\n", r.message.c_str(), v,
              w.max_tilt);
  EXPECT_GE(v, 0.25);
  EXPECT_FALSE(w.driver->walk_status()->fallen);
  EXPECT_LT(w.max_tilt, 0.2);
}

// gait=slow restores the old gait, a per-value option overrides the derived
// one (the SETSPEED clamp says which), and a bad gait option is refused naming it.
TEST(OdeWalk, TheGaitOptionsChooseTheGaitAndBadOnesAreRefused) {
  const auto limit = [](const std::map<std::string, std::string>& options) {
    Walker w(ProjectModel("simple_humanoid.urdf"), options);
    return w.Exec(CommandType::kSetSpeed, {9.0, 0.0}).message;
  };
  EXPECT_NE(limit({}).find("limit 0.289474 m/s"), std::string::npos) << limit({});
  EXPECT_NE(limit({{"gait", "slow"}}).find("limit 0.0909091 m/s"), std::string::npos);
  EXPECT_NE(limit({{"step_length", "0.15"}}).find("limit 0.197368 m/s"), std::string::npos)
      << "0.15 m every 0.76 s";
  for (const auto& [key, value] : std::map<std::string, std::string>{
           {"gait", "fastest"}, {"step_length", "-0.1"}, {"single_support", "0"}, {"step_yaw", "x"}}) {
    try {
      OdeDriverOptions::FromMap({{key, value}});
      ADD_FAILURE() << key << "=" << value << " accepted";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(key), std::string::npos) << e.what();
    }
  }
}

// RobotState::moving tells a walk from standing: the server sends its STOP
// on giving a robot up only when it moves. Moving means a walk in progress or
// a joint servo with a live target (a set-point not reached yet), not the
// contact bounce of a joint held at its stop: the arms' elbows rest on their
// stops and twitch there (issue 26: a standing walker read moving in 57 of
// 500 samples), every sample of a standing walker says still.
TEST(OdeWalk, AStandingWalkerIsNotMovingAndAWalkingOneIs) {
  Walker w;
  RobotState state;
  // Samples every 10 ms for `seconds`: how many found the robot moving, of how many.
  const auto moving_samples = [&](double seconds) {
    int moving = 0, samples = 0;
    w.Run(seconds, [&] {
      w.driver->ReadState(state);
      moving += state.moving ? 1 : 0;
      return ++samples > seconds * 100;
    });
    return std::pair{moving, samples};
  };
  w.Run(2.0);
  const auto [standing, of_standing] = moving_samples(2.0);
  EXPECT_EQ(standing, 0) << "standing on both soles: moving in " << standing << " of " << of_standing;
  // An arm's set-point is a live target until reached.
  const int pan = w.driver->model().JointIndex("pan");
  ASSERT_EQ(w.Exec(CommandType::kJointSetPoint, {0.5}, pan).signal, Signal::kSuccess);
  w.driver->Step(1, w.done);
  w.driver->ReadState(state);
  EXPECT_TRUE(state.moving) << "a joint on its way to a set-point";
  w.Run(1.5);
  const auto [arrived, of_arrived] = moving_samples(0.5);
  EXPECT_EQ(arrived, 0) << "the set-point reached: moving in " << arrived << " of " << of_arrived;
  ASSERT_EQ(w.Exec(CommandType::kSetSpeed, {0.05, 0.0}).signal, Signal::kSuccess);
  w.Run(1.0);
  const auto [walking, of_walking] = moving_samples(2.0);
  EXPECT_EQ(walking, of_walking) << "walking";
  w.Stop();
  w.Run(5.0, [&] { return !w.driver->walk_status()->stepping; });
  w.Run(1.0);
  const auto [stopped, of_stopped] = moving_samples(1.0);
  EXPECT_EQ(stopped, 0) << "standing again after the STOP: moving in " << stopped << " of " << of_stopped;
  EXPECT_FALSE(w.driver->walk_status()->fallen);
}

// The reproducers (issue 26, item 2): a command at the instant that
// made the walk fall or rock: restarting after STOP, SETSPEED 0 or panic,
// and a STOP in the first shift of weight. Times from the first command.
struct Timed {
  double at;  // s after the first command
  std::function<void(Walker&)> act;
};
// Runs the script, then `after` s more; the robot never falls nor tilts
// much, and ends standing on both soles (neither unloaded).
void ExpectNoFallNorRocking(const std::vector<Timed>& script, double after, const std::string& what) {
  Walker w;
  w.Run(1.0);
  const TimePoint t0 = w.driver->sim_time();
  for (const Timed& a : script) {
    w.Run(a.at - ToSeconds(w.driver->sim_time() - t0));
    a.act(w);
  }
  const auto fallen = [&] { return w.driver->walk_status()->fallen; };
  w.Run(after, fallen);
  w.Run(20.0, [&] { return fallen() || !w.driver->walk_status()->stepping; });
  w.Run(1.0, fallen);
  const walking::WalkStatus s = *w.driver->walk_status();
  EXPECT_FALSE(s.fallen) << what;
  EXPECT_LT(w.max_tilt, 0.1) << what;
  EXPECT_FALSE(s.stepping) << what;
  const double weight = w.driver->model().total_mass() * 9.81;
  for (int i = 0; i < 2; ++i)
    EXPECT_GT(s.foot_force[i], 0.25 * weight) << what << ": foot " << i << " unloaded";
  EXPECT_LT(std::max(s.foot_tilt[0], s.foot_tilt[1]), 0.01) << what;
}

TEST(OdeWalkRestart, StopThenGotoAPointOneSecondLater) {
  ExpectNoFallNorRocking({{0.0, [](Walker& w) { Goto(w, 1.0, 0, 0); }},
                          {1.3, [](Walker& w) { w.Stop(); }},
                          {1.4, [](Walker& w) { Goto(w, 1.0, 0, 0); }},
                          {4.0, [](Walker& w) { w.Stop(); }}},
                         2.0, "stop 1.3 s, goto 1.4 s");
}

TEST(OdeWalkRestart, StopThenGotoOneSecondLater) {
  ExpectNoFallNorRocking({{0.0, [](Walker& w) { Goto(w, 1.0, 0, 0); }},
                          {2.3, [](Walker& w) { w.Stop(); }},
                          {3.5, [](Walker& w) { Goto(w, 1.0, 0, 0); }},
                          {6.0, [](Walker& w) { w.Stop(); }}},
                         2.0, "stop 2.3 s, goto 3.5 s");
}

TEST(OdeWalkRestart, SetSpeedZeroAndBack) {
  ExpectNoFallNorRocking({{0.0,
                           [](Walker& w) {
                             w.Exec(CommandType::kSetSpeed, {0.09, 0});
                           }},
                          {1.5,
                           [](Walker& w) {
                             w.Exec(CommandType::kSetSpeed, {0, 0});
                           }},
                          {2.5,
                           [](Walker& w) {
                             w.Exec(CommandType::kSetSpeed, {0.09, 0});
                           }},
                          {5.0,
                           [](Walker& w) {
                             w.Exec(CommandType::kSetSpeed, {0, 0});
                           }}},
                         1.0, "setspeed 0.09, 0 at 1.5 s, 0.09 at 2.5 s");
}

// A reduced phase sweep at the derived gait (the full one: robotalk-walk-sweep):
// STOP then GOTO 0.1 s later in the first step's single support, in the
// double support after it and in the second step's single support (the
// other foot): no fall, no rocking.
TEST(OdeWalkRestart, StopThenGotoAtThreePhasesOfTheFastGait) {
  for (const double t : {2.05, 2.45, 2.85}) {
    ExpectNoFallNorRocking({{0.0, [](Walker& w) { Goto(w, 1.0, 0, 0); }},
                            {t, [](Walker& w) { w.Stop(); }},
                            {t + 0.1, [](Walker& w) { Goto(w, 1.0, 0, 0); }},
                            {t + 1.6, [](Walker& w) { w.Stop(); }}},
                           1.0, "stop at " + std::to_string(t) + " s, goto 0.1 s later");
  }
}

TEST(OdeWalkRestart, PanicResetGoto) {
  ExpectNoFallNorRocking({{0.0, [](Walker& w) { Goto(w, 1.0, 0, 0); }},
                          {1.4,
                           [](Walker& w) {
                             w.driver->Halt(w.done);
                             w.driver->Resume();
                           }},
                          {1.5, [](Walker& w) { Goto(w, 1.0, 0, 0); }},
                          {4.0, [](Walker& w) { w.Stop(); }}},
                         2.0, "panic at 1.4 s, reset, goto");
}

TEST(OdeWalkRestart, StopInTheFirstShiftOfWeight) {
  for (double at : {1.2, 1.6}) {
    ExpectNoFallNorRocking({{0.0, [](Walker& w) { Goto(w, 1.0, 0, 0); }}, {at, [](Walker& w) { w.Stop(); }}},
                           0.5, "stop at " + std::to_string(at) + " s");
  }
}

// The simple humanoid on soles 3 cm wide (a copy of the model in a temporary
// file): it stands, but the first step tips it over the stance sole's edge.
TEST(OdeWalk, ARobotThatFallsHaltsAndAnswersTheGotoInterrupted) {
  std::ifstream in(ProjectModel("simple_humanoid.urdf"));
  std::stringstream text;
  text << in.rdbuf();
  std::string urdf = text.str();
  const std::string sole = "box size=\"0.24 0.12 0.05\"";
  int replaced = 0;
  for (size_t at = urdf.find(sole); at != std::string::npos; at = urdf.find(sole, at)) {
    urdf.replace(at, sole.size(), "box size=\"0.24 0.03 0.05\"");
    ++replaced;
  }
  ASSERT_EQ(replaced, 4) << "visual and collision of both feet";
  const std::filesystem::path path = std::filesystem::temp_directory_path() /
                                     ("robotalk_narrow_feet_" + std::to_string(::getpid()) + ".urdf");
  std::ofstream(path) << urdf;
  Walker w(path.string());
  std::filesystem::remove(path);
  w.Run(1.0);
  ASSERT_FALSE(w.driver->walk_status()->fallen) << "it stands";
  EXPECT_EQ(w.driver->Fault(), "");
  ASSERT_TRUE(w.Exec(CommandType::kGoto, {1.0, 0, 0}).in_progress);
  w.Run(20.0, [&] { return !w.done.empty(); });
  ASSERT_EQ(w.done.size(), 1u);
  EXPECT_EQ(w.done[0].signal, Signal::kInterrupted);
  EXPECT_NE(w.done[0].message.find("fell"), std::string::npos) << w.done[0].message;
  EXPECT_TRUE(w.driver->walk_status()->fallen);
  EXPECT_GT(w.driver->walk_status()->tilt, 0.6);
  // The server halts and holds in panic a robot whose driver reports a fault
  // (Driver::Fault): the STATE stream says panic, commands name the fall.
  EXPECT_NE(w.driver->Fault().find("the robot has fallen (torso tilt 0."), std::string::npos)
      << w.driver->Fault();
  const DriverResult again = w.Exec(CommandType::kGoto, {0, 0, 0});
  EXPECT_EQ(again.signal, Signal::kError);
  EXPECT_NE(again.message.find("fallen"), std::string::npos) << again.message;
  EXPECT_EQ(w.Exec(CommandType::kSetSpeed, {0.05, 0}).signal, Signal::kError);
}

// Issue 26, item 6: walk=true is never silently ignored. A model that cannot
// walk (a synthetic humanoid whose feet are two contact points each: no
// sole) moves its root kinematically and its answers say why, and the
// driver's log says it once; quickstep, on which the walk falls, is refused
// with the reason. (atlas.urdf, this test's model before, now walks:
// tests/drivers/ode_atlas_walk_test.cpp.)
TEST(OdeWalk, AModelThatCannotWalkSaysWhyAndQuickstepIsRefused) {
  const std::string quickstep = RefusalOfWalker({{"solver", "quickstep"}}).value_or("(accepted)");
  EXPECT_NE(quickstep.find("walk=true needs solver=step"), std::string::npos)
      << "walk=true with solver=quickstep: " << quickstep;
  DriverRegistry registry;
  RegisterOdeDriver(registry);
  const testing::TempUrdf urdf("no_soles",
                               testing::PointFootedHumanoid(testing::ContactPoint(-0.09, 0, -0.07) +
                                                            testing::ContactPoint(0.15, 0, -0.07)));
  ::testing::internal::CaptureStderr();
  std::unique_ptr<Driver> bladed = registry.Create(
      "ode", DriverConfig{.robot_name = "", .urdf_path = urdf.path, .options = {{"walk", "true"}}});
  EXPECT_FALSE(static_cast<OdeDriver*>(bladed.get())->walk_status().has_value());
  const std::string why = "walk=true ignored: foot 'left_foot''s lowest contact points (2 within 1 mm";
  auto* ode = static_cast<OdeDriver*>(bladed.get());
  std::vector<Completion> done;
  DriverCommand c;
  c.id = 1;
  c.type = CommandType::kSetSpeed;
  c.num_values = 2;
  c.values[0] = 0.1;
  const DriverResult speed = ode->Execute(c, ode->sim_time(), done);
  EXPECT_EQ(speed.signal, Signal::kModified);
  EXPECT_NE(speed.message.find(why), std::string::npos) << speed.message;
  ode->Stop(ode->sim_time(), done);
  c.id = 2;
  c.type = CommandType::kGoto;
  c.num_values = 3;
  c.values[0] = 0.05;
  ASSERT_TRUE(ode->Execute(c, ode->sim_time(), done).in_progress);
  for (int i = 0; i < 300 && done.empty(); ++i) ode->Step(10, done);
  ASSERT_EQ(done.size(), 1u);
  EXPECT_EQ(done[0].signal, Signal::kModified);
  EXPECT_NE(done[0].message.find(why), std::string::npos) << done[0].message;
  const std::string log = ::testing::internal::GetCapturedStderr();
  const size_t first = log.find(why);
  EXPECT_NE(first, std::string::npos) << log;
  EXPECT_EQ(log.find(why, first + 1), std::string::npos) << "said once:\n" << log;
}

TEST(OdeWalk, TheSameCommandsGiveTheSameWalk) {
  auto run = [] {
    Walker w;
    w.Run(0.5);
    w.Exec(CommandType::kGoto, {0.3, -0.1, -0.3});
    w.Run(4.0);
    const walking::Pose2 p = w.Pelvis();
    return std::array<double, 3>{p.x, p.y, p.theta};
  };
  EXPECT_EQ(run(), run());
}

}  // namespace
}  // namespace robotalk
