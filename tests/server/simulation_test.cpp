#include "robotalk/simulation.h"
#include "kinematic_driver.h"
#include "ode_driver.h"
#include "robotalk/urdf_import.h"
#include "test_paths.h"

#include <gtest/gtest.h>

#include <cmath>

namespace robotalk {
namespace {

using std::chrono::milliseconds;
using std::chrono::seconds;

// A SETSPEED arc, a head set-point, then a stop.
std::vector<SimulatedCommand> Arc() {
  return {{milliseconds(0), {0, CommandType::kSetSpeed, {}, "", {0.3, 0.5}}},
          {milliseconds(500), {0, CommandType::kJointSetPoint, {}, "pan", {0.4}}},
          {seconds(3), {0, CommandType::kStop, {}, "", {}}}};
}

std::unique_ptr<Driver> Ode(const std::string& seed) {
  DriverRegistry registry;
  RegisterOdeDriver(registry);
  return registry.Create("ode",
                         {"pioneer", testing::ProjectModel("pioneer2dx_pantilt.urdf"), {{"seed", seed}}});
}

TEST(Simulation, RunsTheServerCoreOnSimulatedTimeWithTheKinematicDriver) {
  auto driver =
      std::make_unique<KinematicDriver>(LoadUrdfFile(testing::ProjectModel("pioneer2dx_pantilt.urdf")).model);
  const SimulationResult r =
      RunSimulation("pioneer", "kinematic", std::move(driver), Arc(), {.duration = seconds(4)});
  ASSERT_EQ(r.replies.size(), 3u);
  for (const Reply& reply : r.replies) EXPECT_EQ(reply.signal, Signal::kSuccess) << reply.message;
  // Samples every 10 ms of simulated time, exactly on their grid.
  ASSERT_GE(r.states.size(), 400u);
  for (size_t k = 1; k < r.states.size(); ++k) {
    ASSERT_EQ(r.states[k].server_time - r.states[k - 1].server_time, milliseconds(10)) << "sample " << k;
  }
  // An arc of radius v/omega = 0.6 m for 3 s: the robot ends on that circle.
  const auto& last = r.states.back();
  EXPECT_NEAR(std::hypot(last.base.x, last.base.y - 0.6), 0.6, 1e-3);
  EXPECT_EQ(last.base.v, 0.0) << "stopped";
  EXPECT_LT(r.wall_time, seconds(2)) << "4 s of robot time, much faster than real time";
}

TEST(Simulation, GivesTheSameTrajectoryForTheSameSeedAndCommandsOnPhysics) {
  const SimulationResult a = RunSimulation("pioneer", "ode", Ode("3"), Arc(), {.duration = seconds(4)});
  const SimulationResult b = RunSimulation("pioneer", "ode", Ode("3"), Arc(), {.duration = seconds(4)});
  ASSERT_EQ(a.states.size(), b.states.size());
  for (size_t k = 0; k < a.states.size(); ++k) {
    ASSERT_EQ(a.states[k].server_time - a.states[0].server_time,
              b.states[k].server_time - b.states[0].server_time);
    ASSERT_EQ(a.states[k].base, b.states[k].base) << "sample " << k;
    ASSERT_EQ(a.states[k].positions, b.states[k].positions) << "sample " << k;
  }
  EXPECT_GT(std::hypot(a.states.back().base.x, a.states.back().base.y), 0.3) << "it drove";
}

}  // namespace
}  // namespace robotalk
