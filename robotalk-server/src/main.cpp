// robotalk-server: serves robots over LCM with the shipped drivers.
//   robotalk-server --robot pioneer=kinematic:models/pioneer2dx_pantilt.urdf [--url URL] ...
#include "kinematic_driver.h"
#include "ode_driver.h"
#include "robotalk/error.h"
#include "robotalk/sequence_file.h"
#include "robotalk/server_main.h"
#include "robotalk/simulation.h"

#include <fstream>
#include <iostream>
#include <sstream>
#include <string>

namespace {

// --simulate: the server core on a simulated clock, as fast as possible.
int Simulate(const robotalk::DriverRegistry& registry, const std::vector<robotalk::RobotSpec>& robots,
             const std::string& path, double duration_s, double sample_period_s) {
  try {
    if (robots.size() != 1) throw robotalk::Error("--simulate runs exactly one --robot");
    std::ifstream file(path);
    if (!file) throw robotalk::Error("cannot read sequence file '" + path + "'");
    std::stringstream text;
    text << file.rdbuf();
    std::vector<robotalk::SimulatedCommand> commands;
    for (const auto& e : robotalk::cli::ParseSequence(text.str(), path)) {
      commands.push_back({robotalk::FromSeconds(e.offset_s), e.command});
    }
    const robotalk::RobotSpec& spec = robots.front();
    auto driver =
        registry.Create(spec.driver, robotalk::DriverConfig{spec.name, spec.urdf_path, spec.options});
    const robotalk::SimulationResult r =
        robotalk::RunSimulation(spec.name, spec.driver, std::move(driver), commands,
                                {.duration = robotalk::FromSeconds(duration_s),
                                 .sample_period = robotalk::FromSeconds(sample_period_s)});
    for (const robotalk::Reply& reply : r.replies) {
      std::cerr << reply.id - 1 << " " << robotalk::ToString(reply.signal) << " \"" << reply.message
                << "\"\n";
    }
    std::cout << "t,x,y,theta,v,omega";
    if (!r.states.empty()) {
      for (std::size_t i = 0; i < r.states.front().positions.size(); ++i) std::cout << ",q" << i;
    }
    std::cout << "\n";
    const robotalk::TimePoint t0 = r.states.empty() ? robotalk::TimePoint{} : r.states.front().server_time;
    for (const auto& s : r.states) {
      std::cout << robotalk::ToSeconds(s.server_time - t0);
      for (double b : {s.base.x, s.base.y, s.base.theta, s.base.v, s.base.omega}) std::cout << ',' << b;
      for (double q : s.positions) std::cout << ',' << q;
      std::cout << '\n';
    }
    std::cerr << "robotalk-server: simulated " << duration_s << " s in " << robotalk::ToSeconds(r.wall_time)
              << " s of wall time\n";
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "robotalk-server: error: " << e.what() << "\n";
    return 1;
  }
}

}  // namespace

int main(int argc, char** argv) {
  robotalk::DriverRegistry registry;
  robotalk::RegisterKinematicDriver(registry);
  robotalk::RegisterOdeDriver(registry);
  return robotalk::ServerMain(argc, argv, registry, Simulate);
}
