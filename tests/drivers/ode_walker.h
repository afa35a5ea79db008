// The walking simple humanoid on ODE as the walking tests drive it: a Walker
// (an OdeDriver with walk=true, stepped in simulated time, its worst tilt
// tracked) and the error a walker with bad options gives. Shared by
// ode_walk_test.cpp and ode_walk_balance_test.cpp.
#pragma once

#include "ode_driver.h"
#include "robotalk/error.h"
#include "test_paths.h"

#include <algorithm>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace robotalk::testing {

struct Walker {
  explicit Walker(const std::string& urdf = ProjectModel("simple_humanoid.urdf"),
                  const std::map<std::string, std::string>& more = {}) {
    DriverRegistry registry;
    RegisterOdeDriver(registry);
    std::map<std::string, std::string> options = {{"walk", "true"}, {"seed", "7"}};
    options.insert(more.begin(), more.end());
    std::unique_ptr<Driver> d =
        registry.Create("ode", DriverConfig{.robot_name = "", .urdf_path = urdf, .options = options});
    driver.reset(static_cast<OdeDriver*>(d.release()));
    driver->Step(1, done);
  }
  // Runs until `until` says stop or `seconds` pass; tracks the worst tilt.
  void Run(
      double seconds, const std::function<bool()>& until = [] { return false; }) {
    for (int i = 0; i < static_cast<int>(seconds * 100) && !until(); ++i) {
      driver->Step(10, done);
      max_tilt = std::max(max_tilt, driver->walk_status()->tilt);
    }
  }
  DriverResult Exec(CommandType type, std::vector<double> values, int target = -1) {
    DriverCommand c;
    c.id = ++next_id;
    c.type = type;
    c.target = target;
    c.num_values = static_cast<int>(values.size());
    for (size_t i = 0; i < values.size(); ++i) c.values[i] = values[i];
    return driver->Execute(c, driver->sim_time(), done);
  }
  void Stop() { driver->Stop(driver->sim_time(), done); }
  walking::Pose2 Pelvis() const { return driver->walk_status()->pelvis; }
  std::unique_ptr<OdeDriver> driver;
  std::vector<Completion> done;
  CommandId next_id = 0;
  double max_tilt = 0;
};

// The error creating a walking simple humanoid with these extra options
// gives; nullopt when it is accepted.
inline std::optional<std::string> RefusalOfWalker(const std::map<std::string, std::string>& more) {
  DriverRegistry registry;
  RegisterOdeDriver(registry);
  std::map<std::string, std::string> options = {{"walk", "true"}};
  options.insert(more.begin(), more.end());
  try {
    registry.Create(
        "ode", DriverConfig{
                   .robot_name = "", .urdf_path = ProjectModel("simple_humanoid.urdf"), .options = options});
  } catch (const Error& e) {
    return e.what();
  }
  return std::nullopt;
}

inline void Goto(Walker& w, double x, double y, double th) { w.Exec(CommandType::kGoto, {x, y, th}); }

}  // namespace robotalk::testing
