// Published and point-footed humanoids walk with the walking controller
// (issue 26, item 5): a foot's sole is found from its contact points
// (drivers/ode_sim/collision_shapes.h, FindSole) and stood on as a box. A
// synthetic point-footed simple humanoid stands and walks a GOTO (runs
// everywhere); atlas.urdf (Drake's atlas_minimal_contact, 175 kg, eight
// contact points a foot) stands and walks a 0.3 m GOTO without falling (with
// the sole spring scaled by mass per contact alone it falls in its fourth
// step: the test guards SoleSpringFor) and
// is refused on quickstep (skipped where ../shared/robots is absent).
// Simulated time only (Step), deterministic with the seed.
#include "ode_driver.h"
#include "point_footed_humanoid.h"
#include "robotalk/error.h"
#include "test_paths.h"

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <memory>
#include <string>

namespace robotalk {
namespace {

std::unique_ptr<OdeDriver> MakeDriver(const std::string& urdf, std::map<std::string, std::string> options) {
  DriverRegistry registry;
  RegisterOdeDriver(registry);
  options.emplace("walk", "true");
  options.emplace("seed", "7");
  std::unique_ptr<Driver> d =
      registry.Create("ode", DriverConfig{.robot_name = "", .urdf_path = urdf, .options = options});
  return std::unique_ptr<OdeDriver>(static_cast<OdeDriver*>(d.release()));
}

// Steps `seconds` of simulated time (or until `done` holds an answer) and
// returns the largest torso tilt seen.
double Run(OdeDriver& d, double seconds, std::vector<Completion>& done, bool until_done = false) {
  double tilt = 0;
  for (int i = 0; i < static_cast<int>(seconds * 100) && !(until_done && !done.empty()); ++i) {
    d.Step(10, done);
    tilt = std::max(tilt, d.walk_status()->tilt);
  }
  return tilt;
}

DriverResult Goto(OdeDriver& d, double x, double y, double theta, std::vector<Completion>& done) {
  DriverCommand c;
  c.id = 1;
  c.type = CommandType::kGoto;
  c.num_values = 3;
  c.values[0] = x;
  c.values[1] = y;
  c.values[2] = theta;
  return d.Execute(c, d.sim_time(), done);
}

// Stands on both soles flat (a contact at each corner of the derived box),
// the weight carried by the soles; then a GOTO walks there, SUCCESS.
void StandsAndWalks(OdeDriver& d, double x, double y, double theta, double walk_seconds) {
  std::vector<Completion> done;
  ASSERT_TRUE(d.walk_status().has_value()) << "walk=true is granted";
  EXPECT_LT(Run(d, 1.5, done), 0.02) << "stands upright";
  const walking::WalkStatus s = *d.walk_status();
  EXPECT_FALSE(s.fallen);
  EXPECT_EQ(s.foot_contacts[0], 4) << "the sole lies flat: its derived box's four corners";
  EXPECT_EQ(s.foot_contacts[1], 4);
  const double weight = d.model().total_mass() * 9.81;
  EXPECT_NEAR(s.foot_force[0] + s.foot_force[1], weight, 0.03 * weight) << "the soles carry the weight";
  const DriverResult r = Goto(d, x, y, theta, done);
  ASSERT_TRUE(r.in_progress) << r.message;
  const double tilt = Run(d, walk_seconds, done, true);
  ASSERT_EQ(done.size(), 1u) << "the GOTO completes";
  EXPECT_EQ(done[0].signal, Signal::kSuccess) << done[0].message;
  EXPECT_FALSE(d.walk_status()->fallen);
  EXPECT_LT(tilt, 0.1);
  const walking::Pose2 p = d.walk_status()->pelvis;
  EXPECT_LT(std::hypot(p.x - x, p.y - y), 0.05);
  EXPECT_LT(std::abs(walking::Wrap(p.theta - theta)), 0.05);
  EXPECT_GE(d.walk_status()->steps_taken, 2);
}

TEST(OdeSoles, APointFootedHumanoidStandsOnItsDerivedSolesAndWalks) {
  const testing::TempUrdf urdf("point_footed", testing::PointFootedHumanoid(testing::SixPointSoles()));
  const std::unique_ptr<OdeDriver> d = MakeDriver(urdf.path, {});
  StandsAndWalks(*d, 0.15, 0.05, 0.2, 30);
}

TEST(OdeAtlas, StandsOnItsContactPointsAndWalksAShortGoto) {
  ROBOTALK_REQUIRE_SHARED_ROBOTS();
  const std::unique_ptr<OdeDriver> d = MakeDriver(testing::SharedRobot("atlas.urdf"), {{"base", "floating"}});
  StandsAndWalks(*d, 0.3, 0, 0, 30);
}

TEST(OdeAtlas, QuickstepIsRefusedWithTheMeasuredReason) {
  ROBOTALK_REQUIRE_SHARED_ROBOTS();
  try {
    MakeDriver(testing::SharedRobot("atlas.urdf"), {{"base", "floating"}, {"solver", "quickstep"}});
    ADD_FAILURE() << "atlas with walk=true and solver=quickstep was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("walk=true needs solver=step"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("atlas sags and falls standing"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace robotalk
