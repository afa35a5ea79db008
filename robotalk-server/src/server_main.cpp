// robotalk-server's command line (server_main.h).
#include "robotalk/server_main.h"

#include "panic_latch.h"
#include "robotalk/error.h"
#include "robotalk/log_writer.h"
#include "robotalk/option_reader.h"
#include "robotalk/sequence_file.h"  // NumberOf
#include "server_log.h"

#include <algorithm>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <iostream>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace robotalk {
namespace {

constexpr const char* kUsage =
    R"(usage: robotalk-server --robot NAME=DRIVER:URDF[,key=value...] [--robot ...] [options]
Serves one or more robots over LCM (see docs/protocol.md).
  --robot NAME=DRIVER:URDF[,k=v]  a robot: its name, driver (e.g. kinematic) and URDF file,
                                  then driver options (see docs/drivers.md)
  --url URL                       LCM URL (default: LCM's default or $LCM_DEFAULT_URL)
  --session-timeout S             expire a silent client after S seconds (default 2)
  --max-queue N                   most queued commands per client (default 10000)
  --max-queued-total N            most queued commands of all clients in the server, shared
                                  equally by its robots; half is each client's guaranteed
                                  share (default 65536)
  --max-future S                  refuse start times more than S seconds ahead, or in the past (default 3600)
  --max-late S|never|NAME=S       deadlines: a timed servo command (set-point, speed, force)
                                  whose package gives no limit is not executed (INTERRUPTED
                                  "expired ...") when it would begin more than S seconds after
                                  its start time; NAME=S for one robot (default 0.1; docs/server.md)
  --link-stop                     stop what a client session owns when its link health passes a
                                  stop threshold (loss 25 %, round trip 1 s, ...; off by default)
  --max-goto-distance M           refuse a GOTO whose target is more than M metres from the world
                                  origin (default 100)
  --duration S                    exit after S seconds (default: run until SIGINT/SIGTERM)
  --congestion-max-pause S        the paper's congestion injector: pause a random time in
                                  [0, S] s in the ServerDaemon after each received package
  --playback-min-frames N         frames playback mode waits for before estimating (default 5;
                                  also at least 10% of the declared sequence)
  --playback-estimator E          how a playback sequence's start is decided: adaptive (default:
                                  at its first frame from the client's worst recent one-way
                                  delay, then gaps stretch when a frame is slower), quick
                                  (issue 11's start, fixed timing) or paper (wait for frames)
  --playback-stretch F            adaptive: how much longer than recorded a gap between two
                                  frames may play (default 0.1: 10 %; 0: never); above 0.1 the
                                  adaptive start's gate (1.2 frame intervals) moves up by F - 0.1
  --playback-thin-stretch F       adaptive: a frame that comes after the latest time
                                  --playback-stretch allows, or on a FIFO link less than a
                                  quarter of the delay spread before it, may have its gap play
                                  up to F longer (a thin buffer, e.g. 0.25; default 0: off, as is
                                  any F at or below --playback-stretch)
  --playback-margin MS            adaptive: a frame plays no sooner than MS milliseconds after
                                  it arrived (its hand-over to the robot's thread; default 2)
  --playback-queue-start on|off   adaptive: delays spread by more than 1.2 frame intervals
                                  start from a simulated queue of the sequence's frames (on)
                                  or wait for frames (off, default: the paper's estimate)
  --playback-follow-queue on|off  adaptive: delays spread by more than 1.2 frame intervals on
                                  the link (this server kept up) start at the first frame and
                                  the gaps stretch until the buffer covers the queue (default
                                  on; off: the paper's estimate there)
  --playback-burst-discount on|off
                                  adaptive: leave a connect-time package's wait behind the
                                  one sent just before it out of the delay spread (default on)
  --playback-copies-start on|off  adaptive: wait for the first frame's second copy (a client
                                  that sends each package twice) and then cover the earlier
                                  of two delays (default off: measured, not kept)
  --playback-resent-delays on|off adaptive: count a retransmitted package's delay (its resend
                                  wait included) in the client's delay history (default off)
  --playback-start-lead G         adaptive: start G gaps' stretch below the worst delay, which
                                  the first gaps' stretch then reaches (default 1; 0: the
                                  start covers it)
  --inject-reply-drop P           test only: drop each reply package with probability P
  --inject-reply-dup P            test only: send each reply package twice with probability P
  --seed N                        seed of the fault injection (default 1)
  --log-executions                print one line per executed command (diagnostics)
  --log-playback                  print one line per playback start: the delays its estimator
                                  saw and what it decided (diagnostics)
  --max-acceleration A            acceleration limit of every dof's trajectory, rad/s^2 or m/s^2
                                  (interpolated waypoints; default 20)
  --max-base-acceleration LIN[,ANG]|NAME=LIN[,ANG]
                                  a mobile base's acceleration limit, m/s^2 and rad/s^2: the SETSPEED
                                  frames of interpolated packages ramp within it; NAME= for one
                                  robot (default 3,6: a Clearpath Husky's; docs/server.md)
  --driver-call-bound S           a driver call running longer than S seconds is a driver fault:
                                  its command answers ERROR, the robot is held in panic (default 2;
                                  0 = no bound)
  --log-lines-per-second N        most log lines a second; the rest are counted (default 20)
  --state-dir DIR                 where the server keeps state across restarts (default
                                  $ROBOTALK_STATE_DIR, else /var/lib/robotalk for root, else
                                  $XDG_STATE_HOME/robotalk or ~/.local/state/robotalk)
  --panic-latch FILE              the panic latch: which robots are in panic, so a panic survives a
                                  restart (written before a panic is acknowledged; default: a file
                                  per LCM network in the state directory, panic-latch.<network>)
  --no-panic-latch                keep no panic across restarts (warns: a restarted server forgets
                                  a panic)
  --key FILE                      keyed mode: the server's secret key (robotalk-keygen); with --clients
  --clients FILE                  keyed mode: the access list of client keys and their rights per
                                  robot (docs/security.md); without both the server runs open
  --max-sessions N                most client sessions in the whole server (default 1024)
  --max-sessions-per-robot N      most clients one robot serves at once (default 256)
  --no-precise-timing             default timer slack, no final spin before deadlines, no SCHED_FIFO
                                  (saves CPU; the same as ROBOTALK_PRECISE_TIMING=0)
  --allow-duplicate-robots        serve a robot even when another server announces the same name
                                  (by default the server that started later refuses it)
  --simulate SEQ.txt              instead of serving: run the sequence file (docs/client.md
                                  format) on the one --robot as fast as possible on a
                                  simulated clock for --duration S (default 10) and print
                                  its state every --sample-period S (default 0.01) as CSV:
                                  t,x,y,theta,v,omega,q0,q1,...; replies go to stderr
  --list-drivers                  print the known drivers and exit
  --version                       print the version and exit
On SIGINT or SIGTERM every robot is stopped before the server exits.
)";

int Serve(int argc, char** argv, const DriverRegistry& registry, const SimulateCommand& simulate_command) {
  ServerOptions options;
  std::vector<RobotSpec> robots;
  double duration = -1;
  std::string simulate;
  double sample_period = 0.01;
  bool no_panic_latch = false;
  try {
    OptionReader r(argc, argv);
    while (r.Next()) {
      const std::string& arg = r.word();
      if (r.IsHelp()) {
        std::cout << kUsage;
        return 0;
      } else if (r.IsVersion()) {
        std::cout << "robotalk-server " << ROBOTALK_VERSION << "\n";
        return 0;
      } else if (arg == "--list-drivers") {
        for (const std::string& name : registry.names()) std::cout << name << "\n";
        return 0;
      } else if (arg == "--simulate") {
        simulate = r.Value();
      } else if (arg == "--sample-period") {
        sample_period = ParseNumberIn(r.Value(), arg, {0.001, 3600});
      } else if (arg == "--allow-duplicate-robots") {
        options.allow_duplicate_robots = true;
      } else if (arg == "--key") {
        options.key_file = r.Value();
      } else if (arg == "--clients") {
        options.clients_file = r.Value();
      } else if (arg == "--no-precise-timing") {
        options.precise_timing = false;
      } else if (arg == "--max-sessions") {
        options.max_sessions =
            static_cast<std::size_t>(ParseNumberIn(r.Value(), arg, {.min = 1, .max = 1e6, .whole = true}));
      } else if (arg == "--max-sessions-per-robot") {
        options.max_sessions_per_robot =
            static_cast<std::size_t>(ParseNumberIn(r.Value(), arg, {.min = 1, .max = 1e6, .whole = true}));
      } else if (arg == "--panic-latch") {
        options.panic_latch_path = r.Value();
        if (options.panic_latch_path.empty()) throw Error("--panic-latch needs a file name");
      } else if (arg == "--state-dir") {
        options.state_dir = r.Value();
        if (options.state_dir.empty()) throw Error("--state-dir needs a directory name");
      } else if (arg == "--no-panic-latch") {
        no_panic_latch = true;
      } else if (arg == "--log-lines-per-second") {
        options.log_lines_per_second =
            static_cast<int>(ParseNumberIn(r.Value(), arg, {.min = 1, .max = 1e6, .whole = true}));
      } else if (arg == "--driver-call-bound") {
        options.driver_call_bound = FromSeconds(ParseNumberIn(r.Value(), arg, {0, 3600}));
      } else if (arg == "--max-acceleration") {
        options.max_acceleration = ParseNumberIn(r.Value(), arg, {1e-3, 1e6});
      } else if (arg == "--log-executions") {
        options.log_executions = true;
      } else if (arg == "--log-playback") {
        options.log_playback = true;
      } else if (arg == "--robot") {
        robots.push_back(RobotSpec::Parse(r.Value()));
      } else if (arg == "--url") {
        options.lcm_url = r.Value();
      } else if (arg == "--session-timeout") {
        options.session_timeout = FromSeconds(ParseNumberIn(r.Value(), arg, {0.05, 3600}));
      } else if (arg == "--max-queue") {
        options.max_queue =
            static_cast<size_t>(ParseNumberIn(r.Value(), arg, {.min = 1, .max = 1e7, .whole = true}));
      } else if (arg == "--max-queued-total") {
        options.max_queued_total =
            static_cast<size_t>(ParseNumberIn(r.Value(), arg, {.min = 1, .max = 1e8, .whole = true}));
      } else if (arg == "--max-goto-distance") {
        options.max_goto_distance = ParseNumberIn(r.Value(), arg, {0, 1e7});
      } else if (arg == "--max-future") {
        options.max_future = FromSeconds(ParseNumberIn(r.Value(), arg, {0, 86400 * 7}));
      } else if (arg == "--max-late") {
        const std::string text = r.Value();
        const std::size_t eq = text.find('=');
        const std::string limit = eq == std::string::npos ? text : text.substr(eq + 1);
        const Duration d =
            limit == "never" ? Duration::max() : FromSeconds(ParseNumberIn(limit, arg, {1e-6, 86400 * 7}));
        if (eq == std::string::npos) {
          options.max_late = d;
        } else if (eq == 0) {
          throw Error("--max-late: '" + text + "' names no robot (NAME=S)");
        } else {
          options.robot_max_late[text.substr(0, eq)] = d;
        }
      } else if (arg == "--max-base-acceleration") {
        const std::string text = r.Value();
        const std::size_t eq = text.find('=');
        if (eq == 0) throw Error("--max-base-acceleration: '" + text + "' names no robot (NAME=LIN[,ANG])");
        const std::string limits = eq == std::string::npos ? text : text.substr(eq + 1);
        const std::size_t comma = limits.find(',');
        BaseAccelerationLimit limit;
        limit.linear = ParseNumberIn(limits.substr(0, comma), arg, {1e-3, 1e3});
        if (comma != std::string::npos)
          limit.angular = ParseNumberIn(limits.substr(comma + 1), arg, {1e-3, 1e3});
        if (eq == std::string::npos) {
          options.base_acceleration = limit;
        } else {
          options.robot_base_acceleration[text.substr(0, eq)] = limit;
        }
      } else if (arg == "--link-stop") {
        options.link_stop = true;
      } else if (arg == "--congestion-max-pause") {
        options.congestion_max_pause = FromSeconds(ParseNumberIn(r.Value(), arg, {0, 10}));
      } else if (arg == "--playback-min-frames") {
        options.playback_min_frames =
            static_cast<size_t>(ParseNumberIn(r.Value(), arg, {.min = 2, .max = 1e6, .whole = true}));
      } else if (arg == "--playback-estimator") {
        options.playback_estimator = r.Value();
        if (options.playback_estimator != "adaptive" && options.playback_estimator != "quick" &&
            options.playback_estimator != "paper") {
          throw Error("--playback-estimator '" + options.playback_estimator +
                      "': expected adaptive, quick or paper");
        }
      } else if (arg == "--playback-stretch") {
        options.playback_stretch = ParseNumberIn(r.Value(), arg, {0, 1});
      } else if (arg == "--playback-thin-stretch") {
        options.playback_thin_stretch = ParseNumberIn(r.Value(), arg, {0, 1});
      } else if (arg == "--playback-margin") {
        options.playback_margin = FromSeconds(ParseNumberIn(r.Value(), arg, {0, 1000}) / 1000);
      } else if (arg == "--playback-queue-start") {
        const std::string v = r.Value();
        if (v != "on" && v != "off") throw Error("--playback-queue-start '" + v + "': expected on or off");
        options.playback_queue_start = v == "on";
      } else if (arg == "--playback-follow-queue") {
        const std::string v = r.Value();
        if (v != "on" && v != "off") throw Error("--playback-follow-queue '" + v + "': expected on or off");
        options.playback_follow_queue = v == "on";
      } else if (arg == "--playback-copies-start") {
        const std::string v = r.Value();
        if (v != "on" && v != "off") throw Error("--playback-copies-start '" + v + "': expected on or off");
        options.playback_copies_start = v == "on";
      } else if (arg == "--playback-burst-discount") {
        const std::string v = r.Value();
        if (v != "on" && v != "off") throw Error("--playback-burst-discount '" + v + "': expected on or off");
        options.playback_burst_discount = v == "on";
      } else if (arg == "--playback-resent-delays") {
        const std::string v = r.Value();
        if (v != "on" && v != "off") throw Error("--playback-resent-delays '" + v + "': expected on or off");
        options.playback_resent_delays = v == "on";
      } else if (arg == "--playback-start-lead") {
        options.playback_start_lead = ParseNumberIn(r.Value(), arg, {0, 100});
      } else if (arg == "--duration") {
        duration = ParseNumberIn(r.Value(), arg, {0, 1e9});
      } else if (arg == "--inject-reply-drop") {
        options.reply_drop_probability = ParseNumberIn(r.Value(), arg, {0, 1});
      } else if (arg == "--inject-reply-dup") {
        options.reply_duplicate_probability = ParseNumberIn(r.Value(), arg, {0, 1});
      } else if (arg == "--seed") {
        // Read as a double: whole numbers are exact below 2^53 only.
        options.fault_seed = static_cast<std::uint64_t>(
            ParseNumberIn(r.Value(), arg, {.min = 0, .max = 0x1p53 - 1, .whole = true}));
      } else {
        r.Unknown();
      }
    }
    if (robots.empty()) {
      SayServer("no --robot given");
      std::vector<std::string> usage = SplitLines(kUsage);  // one Write of its lines
      LogWriter::Stderr().Write(usage);
      return 2;
    }
    if (no_panic_latch && (!options.panic_latch_path.empty() || !options.state_dir.empty())) {
      throw Error("--no-panic-latch contradicts --panic-latch / --state-dir");
    }
  } catch (const std::exception& e) {
    SayServer(e.what());
    return 2;
  }

  if (!simulate.empty()) {
    if (!simulate_command) {
      SayServer("--simulate is not available in this server");
      return 2;
    }
    return simulate_command(registry, robots, simulate, duration < 0 ? 10.0 : duration, sample_period);
  }

  if (no_panic_latch) {
    SayServer(
        "WARNING: --no-panic-latch: a panic does not survive a restart of this server (a restarted server "
        "runs the next command)");
  } else if (options.panic_latch_path.empty() && options.state_dir.empty()) {
    try {
      options.state_dir = PanicLatch::DefaultStateDir();
    } catch (const std::exception& e) {
      SayServer(std::string("error: ") + e.what());
      return 1;
    }
  }

  // Signals are taken synchronously by this thread; the daemons never see them.
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGINT);
  sigaddset(&signals, SIGTERM);
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);
  // A stderr whose reader went away (`robotalk-server ... | head`, a log
  // collector restarted) loses the log lines written to it (EPIPE), never the
  // server: SIGPIPE would end it at its next line without STOPping a robot.
  std::signal(SIGPIPE, SIG_IGN);

  try {
    // Outlives the server: a robot thread the shutdown gave up on (a driver
    // call that hangs) may still read it until the process exits.
    static const SteadyClock clock;
    Server server(options, robots, registry, clock);
    server.Start();
    // Waits for a signal or --duration, and looks every 100 ms whether the
    // server still serves a robot: one that another server already served
    // when this one started is refused, and a server with none left exits.
    int received = 0;
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(duration);
    while (received <= 0) {
      if (server.serving() == 0) {
        server.Stop();
        std::vector<std::string> lines{"error: no robot left to serve:"};
        for (const std::string& why : server.refusals()) lines.push_back("  " + why);
        ServerLog().Write(lines);
        return 1;
      }
      auto wait = std::chrono::nanoseconds(std::chrono::milliseconds(100));
      if (duration >= 0) {
        const auto left = end - std::chrono::steady_clock::now();
        if (left <= decltype(left)::zero()) break;
        wait = std::min(wait, std::chrono::duration_cast<std::chrono::nanoseconds>(left));
      }
      const timespec timeout{0, static_cast<long>(wait.count())};
      received = sigtimedwait(&signals, nullptr, &timeout);
    }
    if (received > 0) {
      // A stderr that takes nothing must not keep the robots from their STOP.
      SayServer(std::string(strsignal(received)) + ", stopping every robot");
    }
    server.Stop();
    if (!server.not_stopped().empty()) {
      std::string line = "error: not stopped (a driver call hung):";
      for (const std::string& robot : server.not_stopped()) line += " '" + robot + "'";
      SayServer(std::move(line));
      return 1;
    }
  } catch (const std::exception& e) {
    SayServer(std::string("error: ") + e.what());
    return 1;
  }
  return 0;
}

}  // namespace

int ServerMain(int argc, char** argv, const DriverRegistry& registry,
               const SimulateCommand& simulate_command) {
  OpenStandardDescriptors();  // first: nothing of ours on descriptors 0-2
  const int status = Serve(argc, argv, registry, simulate_command);
  LogWriter::Stderr().Flush();  // the count of lines lost, if any is unsaid (within kMaxWait)
  return status;
}

}  // namespace robotalk
