// Runs the server core -- command queue, start-time scheduling, the driver
// and the broadcast state stream -- on a simulated clock, as fast as
// possible, for tests and experiments: no threads, no network. The same
// driver seed and the same commands give the same trajectory.
//
// These are the server's own RobotSessions and RobotDaemon (not a copy),
// without threads or a transport, stepped from one deadline to the next:
// each driver period, each command's start time, each state sample.
#pragma once

#include "robotalk/clock.h"
#include "robotalk/command.h"
#include "robotalk/driver.h"
#include "robotalk/state_sample.h"

#include <memory>
#include <string>
#include <vector>

namespace robotalk {

/// One command of a simulated sequence, at its offset from the start.
struct SimulatedCommand {
  Duration offset{0};
  Command command;  ///< its start_time and id are ignored
};

struct SimulationOptions {
  /// Simulated time to run, from the start of the sequence.
  Duration duration = std::chrono::seconds(10);
  /// Period of the recorded state samples (the broadcast stream's).
  Duration sample_period = std::chrono::milliseconds(10);
};

struct SimulationResult {
  std::vector<StateSample> states;  ///< every sample, in time order
  std::vector<Reply> replies;       ///< one per command, in the order given
  Duration wall_time{0};            ///< how long the run took for real
};

/// Runs `commands` on `driver` for `options.duration` of simulated time.
/// Throws Error when a command is refused before it could run (its reply
/// is still returned for commands the robot answered).
SimulationResult RunSimulation(std::string robot_name, std::string driver_name,
                               std::unique_ptr<Driver> driver, const std::vector<SimulatedCommand>& commands,
                               const SimulationOptions& options);

}  // namespace robotalk
