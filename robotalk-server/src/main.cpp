// robotalk-server: serves robots over LCM.
//   robotalk-server --robot pioneer=kinematic:models/pioneer2dx_pantilt.urdf [--url URL] ...
#include "kinematic_driver.h"
#include "ode_driver.h"
#include "robotalk/error.h"
#include "robotalk/server.h"
#include "robotalk/simulation.h"
#include "sequence_file.h"

#include <csignal>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>

namespace {

constexpr const char* kUsage =
    R"(usage: robotalk-server --robot NAME=DRIVER:URDF[,key=value...] [--robot ...] [options]
Serves one or more robots over LCM (see docs/protocol.md).
  --robot NAME=DRIVER:URDF[,k=v]  a robot: its name, driver (e.g. kinematic) and URDF file,
                                  then driver options (see docs/drivers.md)
  --url URL                       LCM URL (default: LCM's default or $LCM_DEFAULT_URL)
  --session-timeout S             expire a silent client after S seconds (default 2)
  --max-queue N                   most queued commands per client (default 10000)
  --max-future S                  refuse start times more than S seconds ahead (default 3600)
  --duration S                    exit after S seconds (default: run until SIGINT/SIGTERM)
  --congestion-max-pause S        the paper's congestion injector: pause a random time in
                                  [0, S] s in the ServerDaemon after each received package
  --playback-min-frames N         frames playback mode waits for before estimating (default 5;
                                  also at least 10% of the declared sequence)
  --inject-reply-drop P           test only: drop each reply package with probability P
  --inject-reply-dup P            test only: send each reply package twice with probability P
  --seed N                        seed of the fault injection (default 1)
  --log-executions                print one line per executed command (diagnostics)
  --simulate SEQ.txt              instead of serving: run the sequence file (docs/client.md
                                  format) on the one --robot as fast as possible on a
                                  simulated clock for --duration S (default 10) and print
                                  its state every --sample-period S (default 0.01) as CSV:
                                  t,x,y,theta,v,omega,q0,q1,...; replies go to stderr
  --list-drivers                  print the known drivers and exit
On SIGINT or SIGTERM every robot is stopped before the server exits.
)";

double ParseNumber(const std::string& flag, const char* text, double min, double max) {
  char* end = nullptr;
  const double v = std::strtod(text, &end);
  if (end == text || *end != '\0' || !(v >= min && v <= max)) {
    throw robotalk::Error(flag + ": '" + text + "' is not a number in [" + std::to_string(min) + ", " +
                          std::to_string(max) + "]");
  }
  return v;
}

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
      for (int i = 0; i < r.states.front().num_dofs; ++i) std::cout << ",q" << i;
    }
    std::cout << "\n";
    const std::int64_t t0 = r.states.empty() ? 0 : r.states.front().server_time_us;
    for (const auto& s : r.states) {
      std::cout << (s.server_time_us - t0) * 1e-6;
      for (double b : s.base) std::cout << ',' << b;
      for (double q : s.position) std::cout << ',' << q;
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
  robotalk::ServerOptions options;
  std::vector<robotalk::RobotSpec> robots;
  double duration = -1;
  std::string simulate;
  double sample_period = 0.01;
  try {
    for (int i = 1; i < argc; ++i) {
      const std::string arg = argv[i];
      auto value = [&]() -> const char* {
        if (i + 1 >= argc) throw robotalk::Error(arg + " needs a value");
        return argv[++i];
      };
      if (arg == "-h" || arg == "--help") {
        std::cout << kUsage;
        return 0;
      } else if (arg == "--list-drivers") {
        for (const std::string& name : registry.names()) std::cout << name << "\n";
        return 0;
      } else if (arg == "--simulate") {
        simulate = value();
      } else if (arg == "--sample-period") {
        sample_period = ParseNumber(arg, value(), 0.001, 3600);
      } else if (arg == "--log-executions") {
        options.log_executions = true;
      } else if (arg == "--robot") {
        robots.push_back(robotalk::RobotSpec::Parse(value()));
      } else if (arg == "--url") {
        options.lcm_url = value();
      } else if (arg == "--session-timeout") {
        options.session_timeout = robotalk::FromSeconds(ParseNumber(arg, value(), 0.05, 3600));
      } else if (arg == "--max-queue") {
        options.max_queue = static_cast<size_t>(ParseNumber(arg, value(), 1, 1e7));
      } else if (arg == "--max-future") {
        options.max_future = robotalk::FromSeconds(ParseNumber(arg, value(), 0, 86400 * 7));
      } else if (arg == "--congestion-max-pause") {
        options.congestion_max_pause = robotalk::FromSeconds(ParseNumber(arg, value(), 0, 10));
      } else if (arg == "--playback-min-frames") {
        options.playback_min_frames = static_cast<size_t>(ParseNumber(arg, value(), 2, 1e6));
      } else if (arg == "--duration") {
        duration = ParseNumber(arg, value(), 0, 1e9);
      } else if (arg == "--inject-reply-drop") {
        options.reply_drop_probability = ParseNumber(arg, value(), 0, 1);
      } else if (arg == "--inject-reply-dup") {
        options.reply_duplicate_probability = ParseNumber(arg, value(), 0, 1);
      } else if (arg == "--seed") {
        options.fault_seed = static_cast<std::uint64_t>(ParseNumber(arg, value(), 0, 1e18));
      } else {
        std::cerr << "robotalk-server: unknown argument '" << arg << "'\n" << kUsage;
        return 2;
      }
    }
    if (robots.empty()) {
      std::cerr << "robotalk-server: no --robot given\n" << kUsage;
      return 2;
    }
  } catch (const std::exception& e) {
    std::cerr << "robotalk-server: " << e.what() << "\n";
    return 2;
  }

  if (!simulate.empty())
    return Simulate(registry, robots, simulate, duration < 0 ? 10.0 : duration, sample_period);

  // Signals are taken synchronously by this thread; the daemons never see them.
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGINT);
  sigaddset(&signals, SIGTERM);
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);

  try {
    robotalk::SteadyClock clock;
    robotalk::Server server(options, robots, registry, clock);
    server.Start();
    int received = 0;
    if (duration >= 0) {
      const timespec timeout{static_cast<time_t>(duration),
                             static_cast<long>((duration - static_cast<time_t>(duration)) * 1e9)};
      received = sigtimedwait(&signals, nullptr, &timeout);
    } else {
      sigwait(&signals, &received);
    }
    if (received > 0) std::cerr << "robotalk-server: " << strsignal(received) << ", stopping every robot\n";
    server.Stop();
  } catch (const std::exception& e) {
    std::cerr << "robotalk-server: error: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
