// robotalk: command-line client of a RoboTalk server (docs/client.md).
#include "cli_commands.h"
#include "interrupt.h"
#include "robotalk/log_writer.h"  // OpenStandardDescriptors
#include "robotalk/option_reader.h"
#include "robotalk/sequence_file.h"
#include "sequence_runner.h"

#include <algorithm>
#include <cstdlib>
#include <iostream>
#include <map>

#ifndef ROBOTALK_VERSION
#define ROBOTALK_VERSION "unknown"
#endif

namespace {

constexpr const char* kUsage = R"(usage: robotalk [--url URL] [--timeout S] [--key FILE] COMMAND ...

  robots [--listen S] [--json]        robots announced on ROBOTALK/ANNOUNCE (default 1.5 s)
  describe ROBOT [--json]             the robot's description (links, joints, frames)
  query ROBOT TYPE [TARGET] [--json]  TYPE: joint_state | link_poses | frame_poses | base_pose
  send ROBOT COMMAND ARGS... [--at S] [--hold] [--json]
                                      one command, waited for to its end, e.g.
                                        send pioneer goto 1 0 0
                                        send pioneer joint_setpoint pan 0.5
                                        send pioneer setspeed 0.2 0.1 --hold
                                        send pioneer stop --at 2
                                      --at S: start S seconds from now (server clock)
                                      --hold: keep a setspeed / joint_speed / joint_force
                                      until Ctrl-C, then STOP (without it the server's
                                      watchdog stops the robot ~2 s after robotalk exits)
  send ROBOT --file SEQ.txt [--mode M] [--delay S] [--paced] [--interpolation I] [--json]
                                      a timed sequence (format: docs/client.md); M is
                                      direct (a handshake per frame), delay (start =
                                      server clock + S, default 0, interpolated 0.5) or
                                      playback (the server picks the delay); --paced
                                      sends each frame at its time instead of all at
                                      once; I is step, linear, cubic or quintic: how the
                                      set-points join into a trajectory (overrides the
                                      file's 'interpolation' line)
  watch ROBOT [--period S] [--duration S] [--count N] [--json]
                                      broadcast mode: print the state stream (default 0.1 s);
                                      exits 1 when the server is gone (3 s without STATE
                                      or announce), 0 at the end or on Ctrl-C
  panic ROBOT                         panic: stop everything, refuse commands
  reset ROBOT                         PANIC_RESET

Global options:
  --url URL      LCM URL (default: $LCM_DEFAULT_URL or LCM's default)
  --timeout S    seconds to wait for a robot that does not answer (default 5); a
                 command that runs long (GOTO, a sequence) is waited for to its end
  --key FILE     keyed mode: this client's secret key (robotalk-keygen; default
                 $ROBOTALK_KEY); without one the client talks in open mode
  --server-key FILE.pub
                 keyed mode: trust only the server with this key
  --known-servers FILE
                 keyed mode without --server-key: where each robot's server key
                 is pinned on first use (default $ROBOTALK_KNOWN_SERVERS or
                 ~/.robotalk/known_servers); a server with another key is refused
  --max-late S|never
                 deadline of every command sent: one that would begin more than S
                 seconds after its start time is not executed (INTERRUPTED
                 "expired ..."); default: the robot's --max-late for set-points,
                 speeds and forces, none for a GOTO
  --version      the version
  --help         this text (also after a command)

Ctrl-C or SIGTERM during send stops what it started (STOP) and says so.
Each reply prints as: <id> <SIGNAL> "<message>" [values]  (--json: one JSON object per reply)
Exit status: 0 SUCCESS/MODIFIED, 1 any other signal or a timeout, 2 usage error,
128+N after signal N.
)";

}  // namespace

int main(int argc, char** argv) {
  using namespace robotalk::cli;
  robotalk::OpenStandardDescriptors();  // nothing of ours on descriptors 0-2
  Interrupter::Install();               // before any thread: every later one inherits the blocked signals
  std::vector<std::string> args(argv + 1, argv + argc);
  if (std::find(args.begin(), args.end(), "--version") != args.end()) {
    std::cout << "robotalk " << ROBOTALK_VERSION << "\n";
    return 0;
  }
  if (args.empty() || std::find_if(args.begin(), args.end(), [](const std::string& a) {
                        return a == "--help" || a == "-h";
                      }) != args.end()) {
    std::cout << kUsage;
    return args.empty() ? 2 : 0;
  }
  try {
    GlobalOptions g;
    if (const char* env = std::getenv("LCM_DEFAULT_URL")) g.url = env;
    std::vector<std::string> rest;
    robotalk::OptionReader r(args);
    while (r.Next()) {
      if (r.Is("--url")) {
        g.url = r.Value();
      } else if (r.Is("--key")) {
        g.key_file = r.Value();
      } else if (r.Is("--server-key")) {
        g.server_key = r.Value();
      } else if (r.Is("--known-servers")) {
        g.known_servers = r.Value();
      } else if (r.Is("--max-late")) {
        const std::string& v = r.Value();
        const double s = v == "never" ? 0 : ParseSeconds(v, "--max-late");
        if (v != "never" && !(s > 0)) throw UsageError("--max-late " + v + ": expected seconds > 0 or never");
        g.max_late = v == "never" ? robotalk::kMaxLateNever : robotalk::FromSeconds(s);
      } else if (r.Is("--timeout")) {
        g.timeout_s = ParseSeconds(r.Value(), "--timeout");
        if (g.timeout_s <= 0) throw UsageError("--timeout must be positive");
      } else if (rest.empty() && r.word().size() > 1 && r.word()[0] == '-') {
        // Not r.Unknown(): every usage error of the CLI ends "(robotalk --help for usage)".
        throw UsageError("unknown option '" + r.word() + "'");
      } else {
        rest.push_back(r.word());
      }
    }
    if (rest.empty()) throw UsageError("missing command");
    const std::string command = rest.front();
    rest.erase(rest.begin());
    const std::map<std::string, int (*)(const GlobalOptions&, const std::vector<std::string>&)> commands = {
        {"robots", &RunRobots}, {"describe", &RunDescribe}, {"query", &RunQuery}, {"send", &RunSend},
        {"panic", &RunPanic},   {"reset", &RunReset},       {"watch", &RunWatch}};
    auto it = commands.find(command);
    if (it == commands.end()) throw UsageError("unknown command '" + command + "'");
    return it->second(g, rest);
  } catch (const UsageError& e) {
    std::cerr << "robotalk: " << ErrorText(e.what()) << "\n(robotalk --help for usage)\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "robotalk: " << ErrorText(e.what()) << "\n";
    return 1;
  }
}
