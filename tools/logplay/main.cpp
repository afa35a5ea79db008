// robotalk-logplay: reads LCM logs of RoboTalk sessions (docs/logplay.md).
#include "export.h"
#include "interrupt.h"
#include "logplay.h"
#include "mcap_export.h"
#include "receipt_order.h"
#include "robotalk/log_writer.h"  // OpenStandardDescriptors
#include "robotalk/sequence_file.h"
#include "sequence_runner.h"

#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>

#ifndef ROBOTALK_VERSION
#define ROBOTALK_VERSION "unknown"
#endif

namespace {

using robotalk::cli::UsageError;
namespace lp = robotalk::logplay;

constexpr const char* kUsage = R"(usage: robotalk-logplay COMMAND LOG [options]

Records and reads LCM logs of RoboTalk sessions. See docs/logplay.md.

  record -o LOG [--lcm-url URL] [-c REGEX] [--duration S]
                                 every channel of every lane of URL (the split
                                 traffic layout's 66 ports) into one LCM log, until
                                 S seconds have passed or Ctrl-C

  info LOG                       channels, time span, servers, robots, clients and
                                 each client's command stream; final state per robot
  extract LOG (--client ID | --robot NAME) -o SEQ.txt [--map old=new]... [--window A:B] [--speed F]
                                 a sequence file `robotalk send --file` plays
  replay LOG --robot NAME [--from ROBOT | --client ID] [--map old=new]...
         [--mode delay|playback] [--delay S] [--speed F] [--window A:B]
         [--url URL] [--timeout S] [--no-progress]
                                 sends the recorded motion again, through the client
                                 library, to a live robot (the same or another);
                                 --from defaults to --robot; delay mode starts
                                 --delay S (default 0.5) ahead on the server clock
  export LOG [-o DIR] [--no-plot]
                                 DIR/commands.csv, DIR/state.csv (a column per joint,
                                 named from the logged configuration), DIR/joints.csv
                                 and DIR/session.png (base path; each joint's trace on
                                 its own axis, python3-matplotlib)
  export LOG --mcap OUT.mcap [--urdf ROBOT=PATH]... [--package-path DIRS]
                                 the session as an MCAP file for Foxglove: the channels
                                 robotalk-web's Foxglove endpoint publishes live, and
                                 every request and reply as JSON (docs/interop.md);
                                 a robot given its URDF is drawn from it (meshes
                                 embedded), the others as equivalent inertia boxes

  --map old=new   rename a joint or control frame (repeatable)
  --window A:B    only the commands between A and B seconds into the recording
  --speed F       play F times faster (0.5: half speed)
  --version, --help

Exit status: 0 success, 1 a failed command or a bad log, 2 usage error,
128+N interrupted by signal N (after sending STOP).
)";

class Args {
 public:
  explicit Args(std::vector<std::string> a) : args_(std::move(a)) {}
  bool Flag(const std::string& name) {
    for (auto it = args_.begin(); it != args_.end(); ++it) {
      if (*it == name) {
        args_.erase(it);
        return true;
      }
    }
    return false;
  }
  std::vector<std::string> All(const std::string& name) {
    std::vector<std::string> values;
    for (std::size_t i = 0; i < args_.size();) {
      if (args_[i] != name) {
        ++i;
        continue;
      }
      if (i + 1 == args_.size()) throw UsageError(name + " needs a value");
      values.push_back(args_[i + 1]);
      args_.erase(args_.begin() + static_cast<long>(i), args_.begin() + static_cast<long>(i) + 2);
    }
    return values;
  }
  std::optional<std::string> One(const std::string& name) {
    auto v = All(name);
    if (v.size() > 1) throw UsageError(name + " given twice");
    return v.empty() ? std::nullopt : std::optional<std::string>(v[0]);
  }
  // Nothing may remain (commands without a LOG argument).
  void None() {
    if (!args_.empty()) throw UsageError("unexpected '" + args_[0] + "'");
  }
  // The log path: the one remaining word; anything starting with '-' is unknown.
  std::string Log() {
    for (const auto& a : args_) {
      if (a.size() > 1 && a[0] == '-') throw UsageError("unknown option '" + a + "'");
    }
    if (args_.size() != 1) throw UsageError(args_.empty() ? "missing LOG" : "one LOG file, please");
    return args_[0];
  }

 private:
  std::vector<std::string> args_;
};

lp::FrameOptions TakeFrameOptions(Args& a) {
  lp::FrameOptions f;
  for (const auto& m : a.All("--map")) f.rename.insert(lp::ParseRename(m));
  if (auto w = a.One("--window")) std::tie(f.from_s, f.to_s) = lp::ParseWindow(*w);
  if (auto s = a.One("--speed")) {
    f.speed = robotalk::cli::ParseNumber(*s, "--speed");
    if (f.speed <= 0) throw UsageError("--speed must be positive");
  }
  return f;
}

lp::Selection TakeSelection(Args& a, const char* robot_flag) {
  lp::Selection s;
  if (auto c = a.One("--client")) s.client_id = lp::ParseClientId(*c);
  if (auto r = a.One(robot_flag)) s.robot = *r;
  return s;
}

std::string PlotScript() {
  std::error_code ec;
  const auto exe = std::filesystem::read_symlink("/proc/self/exe", ec);
  if (!ec) {
    const auto installed = exe.parent_path().parent_path() / "share/robotalk/plot_log.py";
    if (std::filesystem::exists(installed)) return installed;
  }
#ifdef ROBOTALK_LOGPLAY_PLOT_SCRIPT
  return ROBOTALK_LOGPLAY_PLOT_SCRIPT;
#else
  return "plot_log.py";
#endif
}

int RunExtract(Args& a) {
  const lp::Selection sel = TakeSelection(a, "--robot");
  const auto out = a.One("-o");
  const lp::FrameOptions frames = TakeFrameOptions(a);
  const std::string path = a.Log();
  if (!sel.client_id && sel.robot.empty()) throw UsageError("extract needs --client ID or --robot NAME");
  if (!out) throw UsageError("extract needs -o SEQ.txt");
  const lp::SessionLog log = lp::ReadLog(path);
  lp::PrintRejected(log, "robotalk-logplay: ", std::cerr);
  const lp::Timeline t = log.MakeTimeline(sel);
  for (const auto& s : t.skipped) std::cerr << "robotalk-logplay: not extracted: " << s << "\n";
  const auto f = lp::ToFrames(t, frames);
  std::ofstream file(*out);
  const std::string text = lp::FormatSequence(
      f, "extracted by robotalk-logplay from " + path + "\n" + std::to_string(f.size()) +
             " commands; timing from the " + t.clock + " clock\nplay: robotalk send ROBOT --file " + *out);
  robotalk::cli::ParseSequence(text, *out);  // what we write, `robotalk send --file` reads
  if (!(file << text)) throw lp::LogError("cannot write '" + *out + "'");
  std::cerr << "robotalk-logplay: wrote " << f.size() << " commands over "
            << robotalk::cli::FormatDuration(f.back().offset) << " to " << *out << "\n";
  return 0;
}

int RunReplay(Args& a) {
  lp::ReplayOptions o;
  o.robot = a.One("--robot").value_or("");
  o.selection = TakeSelection(a, "--from");
  o.frames = TakeFrameOptions(a);
  o.sequence.mode = robotalk::CommandMode::kDelay;
  o.sequence.paced = false;
  o.sequence.delay = std::chrono::milliseconds(500);
  if (auto m = a.One("--mode")) {
    auto mode = robotalk::ParseCommandMode(*m);
    if (!mode || *mode == robotalk::CommandMode::kDirect)
      throw UsageError("--mode " + *m + ": delay or playback");
    o.sequence.mode = *mode;
  }
  if (auto d = a.One("--delay")) {
    const double s = robotalk::cli::ParseSeconds(*d, "--delay");
    o.sequence.delay = robotalk::FromSeconds(s);
  }
  if (const char* env = std::getenv("LCM_DEFAULT_URL")) o.url = env;
  if (auto u = a.One("--url")) o.url = *u;
  if (auto t = a.One("--timeout")) {
    o.timeout_s = robotalk::cli::ParseSeconds(*t, "--timeout");
    if (o.timeout_s <= 0) throw UsageError("--timeout must be positive");
  }
  o.progress = !a.Flag("--no-progress") && isatty(STDERR_FILENO);
  const std::string path = a.Log();
  if (o.robot.empty()) throw UsageError("replay needs --robot NAME (the live robot to drive)");
  return lp::Replay(lp::ReadLog(path), o, std::cout);
}

int RunRecord(Args& a) {
  lp::RecordOptions o;
  o.output = a.One("-o").value_or("");
  if (o.output.empty()) throw UsageError("record needs -o LOG");
  if (auto u = a.One("--lcm-url")) o.url = *u;
  if (auto u = a.One("--url")) o.url = *u;
  if (auto c = a.One("-c")) o.channels = *c;
  if (auto d = a.One("--duration")) {
    const double s = robotalk::cli::ParseSeconds(*d, "--duration");
    if (s <= 0) throw UsageError("--duration must be positive");
    o.duration = robotalk::FromSeconds(s);
  }
  a.None();
  robotalk::cli::Interrupter::Defer(true);  // Ctrl-C ends the recording, the log is flushed
  const lp::RecordResult r = lp::Record(o, std::cerr);
  std::cerr << "robotalk-logplay: wrote " << r.events << " events (" << r.bytes << " bytes) to " << o.output
            << (r.signal ? std::string(" (stopped by ") + robotalk::cli::Interrupter::Name(r.signal) + ")"
                         : "")
            << "\n";
  if (r.late > 0) {
    std::cerr
        << "robotalk-logplay: warning: " << r.late
        << " events were dispatched more than 0.25 s after their receipt and are written after later ones\n";
  }
  if (r.early > 0) {
    std::cerr << "robotalk-logplay: warning: " << r.early << " events (" << r.early_bytes
              << " bytes) were written before their 0.25 s sort was over: more than "
              << (lp::ReceiptOrder::kMaxHeldBytes >> 20) << " MiB (or " << lp::ReceiptOrder::kMaxHeld
              << " events) arrived within it; none was dropped, but they may precede "
                 "events received before them\n";
  }
  return 0;
}

int RunExportMcap(Args& a, const std::string& out) {
  const std::vector<std::string> urdf = a.All("--urdf"), package_paths = a.All("--package-path");
  const std::string path = a.Log();
  const auto start = std::chrono::steady_clock::now();
  lp::McapGeometry geometry;
  try {
    const char* ros = std::getenv("ROS_PACKAGE_PATH");
    geometry = lp::ParseGeometryOptions(urdf, package_paths, ros ? ros : "");
  } catch (const robotalk::Error& e) {
    throw UsageError(e.what());
  }
  const lp::McapExportResult r = lp::ExportMcap(path, out, std::cerr, geometry);
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::cerr << "robotalk-logplay: wrote " << r.messages << " messages (" << r.bytes << " bytes) from "
            << r.events << " events (" << r.log_bytes << " bytes) in " << s << " s to " << out << "\n";
  if (r.messages == 0)
    std::cerr << "robotalk-logplay: warning: " << path << " holds no RoboTalk messages (" << r.events
              << " LCM events): " << out << " has none\n";
  std::cout << out << "\n";
  return 0;
}

// Runs argv[0] (found in PATH) with `argv` and waits for it; true when it
// exits 0. Its arguments are words, never a shell's (a directory named with
// a quote stays one argument), and it starts with no signal blocked and
// SIGINT/SIGTERM at their defaults: this tool blocks them for its
// Interrupter, which std::system's child inherited (a Ctrl-C ended the tool,
// the plot ran on).
bool RunToEnd(const std::vector<std::string>& argv) {
  std::vector<char*> args;
  for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  posix_spawnattr_t attr;
  posix_spawnattr_init(&attr);
  sigset_t none, defaults;
  sigemptyset(&none);
  sigemptyset(&defaults);
  sigaddset(&defaults, SIGINT);
  sigaddset(&defaults, SIGTERM);
  posix_spawnattr_setsigmask(&attr, &none);
  posix_spawnattr_setsigdefault(&attr, &defaults);
  posix_spawnattr_setflags(&attr, POSIX_SPAWN_SETSIGMASK | POSIX_SPAWN_SETSIGDEF);
  pid_t pid = 0;
  const int spawned = posix_spawnp(&pid, args[0], nullptr, &attr, args.data(), environ);
  posix_spawnattr_destroy(&attr);
  if (spawned != 0) return false;
  int status = 0;
  for (;;) {
    if (waitpid(pid, &status, 0) == pid) break;
    if (errno != EINTR) return false;  // its status unknown (ECHILD: SIGCHLD ignored): no success
  }
  return WIFEXITED(status) && WEXITSTATUS(status) == 0;
}

int RunExport(Args& a) {
  if (auto mcap = a.One("--mcap")) return RunExportMcap(a, *mcap);
  const std::string dir = a.One("-o").value_or("logplay_export");
  const bool plot = !a.Flag("--no-plot");
  const std::string path = a.Log();
  const lp::SessionLog log = lp::ReadLog(path);
  lp::PrintRejected(log, "robotalk-logplay: ", std::cerr);
  for (const auto& f : lp::ExportCsv(log, lp::ReadConfigs(path), dir, std::cerr)) std::cout << f << "\n";
  if (!plot) return 0;
  const std::string png = dir + "/session.png";
  // Debian's python3 (with python3-matplotlib), even when another python3 comes first in PATH.
  const std::string python = std::filesystem::exists("/usr/bin/python3") ? "/usr/bin/python3" : "python3";
  const std::vector<std::string> argv{python, PlotScript(),       dir + "/commands.csv", dir + "/state.csv",
                                      png,    dir + "/joints.csv"};
  if (!RunToEnd(argv)) {
    std::string command;
    for (const std::string& a : argv) command += (command.empty() ? "" : " ") + a;
    std::cerr << "robotalk-logplay: the plot failed (needs python3-matplotlib): " << command << "\n";
    return 1;
  }
  std::cout << png << "\n";
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  robotalk::OpenStandardDescriptors();  // first: a recording never takes descriptor 1 or 2
  robotalk::cli::Interrupter::Install();
  std::vector<std::string> args(argv + 1, argv + argc);
  if (args.empty()) {
    std::cerr << kUsage;
    return 2;
  }
  for (const auto& a : args) {
    if (a == "--help" || a == "-h") {
      std::cout << kUsage;
      return 0;
    }
    if (a == "--version") {
      std::cout << "robotalk-logplay " << ROBOTALK_VERSION << "\n";
      return 0;
    }
  }
  const std::string command = args.front();
  Args rest({args.begin() + 1, args.end()});
  try {
    if (command == "info") {
      lp::PrintInfo(lp::ReadLog(rest.Log()), args.size() > 1 ? args[1] : "", std::cout);
      return 0;
    }
    if (command == "extract") return RunExtract(rest);
    if (command == "replay") return RunReplay(rest);
    if (command == "export") return RunExport(rest);
    if (command == "record") return RunRecord(rest);
    if (command.size() > 1 && command[0] == '-') throw UsageError("unknown option '" + command + "'");
    throw UsageError("unknown command '" + command + "' (info, extract, replay, export, record)");
  } catch (const UsageError& e) {
    std::cerr << "robotalk-logplay: " << robotalk::cli::ErrorText(e.what())
              << "\n(robotalk-logplay --help for usage)\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "robotalk-logplay: " << robotalk::cli::ErrorText(e.what()) << "\n";
    return 1;
  }
}
