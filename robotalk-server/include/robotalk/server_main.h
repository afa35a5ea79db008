// The whole `robotalk-server` command line as one function, so a hardware
// developer ships a server with their own driver in a few lines:
//
//   #include <robotalk/server_main.h>
//   int main(int argc, char** argv) {
//     robotalk::DriverRegistry registry;
//     registry.Register("my_arm", [](const robotalk::DriverConfig& c) { return MakeMyArm(c); });
//     return robotalk::ServerMain(argc, argv, registry);
//   }
//
// It parses every option (--help lists them), serves the --robot given with
// the drivers of `registry`, stops every robot on SIGINT/SIGTERM, and
// returns the process exit code (0 done, 1 failed to serve, 2 bad usage).
#pragma once

#include "robotalk/driver.h"
#include "robotalk/server.h"

#include <functional>
#include <string>
#include <vector>

namespace robotalk {

/// `--simulate SEQ.txt`: runs a sequence file on one robot on simulated time
/// (the shipped binary provides it; other servers may leave it empty).
using SimulateCommand =
    std::function<int(const DriverRegistry& registry, const std::vector<RobotSpec>& robots,
                      const std::string& sequence_path, double duration_s, double sample_period_s)>;

/// Runs the robotalk-server command line. Must be called from the main
/// thread before any other thread starts (it blocks SIGINT and SIGTERM).
int ServerMain(int argc, char** argv, const DriverRegistry& registry, const SimulateCommand& simulate = {});

}  // namespace robotalk
