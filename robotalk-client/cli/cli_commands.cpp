#include "cli_commands.h"

#include "describe_format.h"
#include "sequence_file.h"

#include <algorithm>
#include <cinttypes>
#include <condition_variable>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <mutex>
#include <sstream>

namespace robotalk::cli {
namespace {

ClientOptions MakeOptions(const GlobalOptions& g) {
  ClientOptions o;
  o.lcm_url = g.url;
  o.timeout = FromSeconds(g.timeout_s);
  o.connect_timeout = FromSeconds(g.timeout_s);
  return o;
}

// Pulls `--name VALUE` out of args; returns whether it was there.
bool TakeOption(std::vector<std::string>& args, const std::string& name, std::string* value) {
  auto it = std::find(args.begin(), args.end(), name);
  if (it == args.end()) return false;
  if (value) {
    if (it + 1 == args.end()) throw UsageError(name + " needs a value");
    *value = *(it + 1);
    args.erase(it, it + 2);
  } else {
    args.erase(it);
  }
  return true;
}

void RejectOptions(const std::vector<std::string>& args) {
  for (const auto& a : args) {
    if (a.size() > 1 && a[0] == '-' && a[1] == '-') throw UsageError("unknown option " + a);
  }
}

int ExitStatus(const Reply& r) { return Succeeded(r.signal) ? 0 : 1; }

}  // namespace

void PrintReply(const Reply& r, std::ostream& out) {
  std::string quoted = "\"";
  for (char c : r.message) {
    if (c == '"' || c == '\\') quoted += '\\';
    quoted += c;
  }
  quoted += '"';
  out << r.id << ' ' << ToString(r.signal) << ' ' << quoted;
  for (double v : r.values) {
    char buf[32];
    std::snprintf(buf, sizeof buf, " %.6g", v);
    out << buf;
  }
  out << '\n';
}

int RunRobots(const GlobalOptions& g, const std::vector<std::string>& in) {
  std::vector<std::string> args = in;
  std::string listen = "1.5";
  TakeOption(args, "--listen", &listen);
  RejectOptions(args);
  if (!args.empty()) throw UsageError("robots takes no arguments");
  const double seconds = ParseNumber(listen, "--listen");
  const auto robots = ListRobots(MakeOptions(g), FromSeconds(seconds));
  if (robots.empty()) {
    std::cerr << "robotalk: no robot announced itself within " << seconds << " s\n";
    return 0;
  }
  std::printf("%-20s %-10s %5s %-16s %-5s %7s %s\n", "ROBOT", "DRIVER", "DOFS", "CONFIG_HASH", "PANIC",
              "CLIENTS", "SERVER");
  for (const auto& r : robots) {
    std::printf("%-20s %-10s %5d %016llx %-5s %7d %016llx\n", r.name.c_str(), r.driver.c_str(), r.total_dofs,
                static_cast<unsigned long long>(r.config_hash), r.panic ? "yes" : "no", r.num_clients,
                static_cast<unsigned long long>(r.server_id));
  }
  return 0;
}

int RunDescribe(const GlobalOptions& g, const std::vector<std::string>& in) {
  std::vector<std::string> args = in;
  const bool json = TakeOption(args, "--json", nullptr);
  RejectOptions(args);
  if (args.size() != 1) throw UsageError("usage: robotalk describe ROBOT [--json]");
  RobotClient client(MakeOptions(g));
  client.Connect(args[0]);
  if (json) {
    PrintModelJson(client.model(), {}, std::cout);
  } else {
    PrintModelTable(client.model(), std::cout);
  }
  return 0;
}

int RunQuery(const GlobalOptions& g, const std::vector<std::string>& args) {
  RejectOptions(args);
  if (args.size() < 2 || args.size() > 3) {
    throw UsageError("usage: robotalk query ROBOT joint_state|link_poses|frame_poses|base_pose [TARGET]");
  }
  const auto type = ParseQueryType(args[1]);
  if (!type)
    throw UsageError("unknown query '" + args[1] + "' (joint_state, link_poses, frame_poses, base_pose)");
  RobotClient client(MakeOptions(g));
  client.Connect(args[0]);
  const Reply r = client.Query(*type, args.size() == 3 ? args[2] : "");
  PrintReply(r, std::cout);
  return ExitStatus(r);
}

namespace {

struct SequenceFlags {
  SequenceOptions options;
  bool any = false;  // a mode flag was given (only valid with --file)
};

// --mode direct|delay|playback, --delay S, --paced.
SequenceFlags TakeSequenceFlags(std::vector<std::string>& args) {
  SequenceFlags f;
  f.options.mode = CommandMode::kDelay;
  f.options.delay = Duration(0);
  f.options.paced = false;
  std::string mode, delay;
  if (TakeOption(args, "--mode", &mode)) {
    auto m = ParseCommandMode(mode);
    if (!m) throw UsageError("--mode " + mode + ": expected direct, delay or playback");
    f.options.mode = *m;
    f.any = true;
  }
  if (TakeOption(args, "--delay", &delay)) {
    const double d = ParseNumber(delay, "--delay");
    if (d < 0) throw UsageError("--delay " + delay + " is negative");
    if (f.options.mode != CommandMode::kDelay) throw UsageError("--delay goes with --mode delay");
    f.options.delay = FromSeconds(d);
    f.any = true;
  }
  if (TakeOption(args, "--paced", nullptr)) {
    f.options.paced = true;
    f.any = true;
  }
  if (f.options.mode == CommandMode::kDirect) f.options.paced = true;  // a handshake per frame, at its time
  return f;
}

int SendFile(const GlobalOptions& g, const std::string& robot, const std::string& path,
             const SequenceOptions& options) {
  std::ifstream file(path);
  if (!file) throw UsageError("cannot read sequence file '" + path + "'");
  std::stringstream text;
  text << file.rdbuf();
  const auto entries = ParseSequence(text.str(), path);  // all lines checked before connecting
  std::vector<TimedCommand> frames;
  for (const auto& e : entries) frames.push_back({FromSeconds(e.offset_s), e.command});

  RobotClient client(MakeOptions(g));
  client.Connect(robot);
  const SequenceResult result = client.RunSequence(std::move(frames), options);
  if (result.playback_delay) {
    std::cerr << "robotalk: playback: the server starts the sequence " << ToSeconds(*result.playback_delay)
              << " s after its first frame arrived\n";
  }
  int status = 0;
  for (const Reply& r : result.replies) {
    PrintReply(r, std::cout);
    status = std::max(status, ExitStatus(r));
  }
  return status;
}

}  // namespace

int RunSend(const GlobalOptions& g, const std::vector<std::string>& in) {
  std::vector<std::string> args = in;
  std::string file, at;
  const bool has_file = TakeOption(args, "--file", &file);
  const bool has_at = TakeOption(args, "--at", &at);
  const SequenceFlags sequence = TakeSequenceFlags(args);
  RejectOptions(args);
  if (args.empty()) {
    throw UsageError(
        "usage: robotalk send ROBOT COMMAND ARGS... [--at S] | send ROBOT --file SEQ.txt [--mode M] [--delay "
        "S] [--paced]");
  }
  if (has_file) {
    if (args.size() != 1 || has_at) throw UsageError("send ROBOT --file SEQ.txt takes nothing else");
    return SendFile(g, args[0], file, sequence.options);
  }
  if (sequence.any) throw UsageError("--mode, --delay and --paced go with --file");
  Command c = ParseCommandWords({args.begin() + 1, args.end()});
  std::optional<double> delay;
  if (has_at) {
    delay = ParseNumber(at, "--at");
    if (*delay < 0) throw UsageError("--at " + at + " is negative");
  }
  RobotClient client(MakeOptions(g));
  client.Connect(args[0]);
  if (delay) c.start_time = client.ServerNow() + FromSeconds(*delay);
  const Reply r = client.Execute(std::move(c));
  PrintReply(r, std::cout);
  return ExitStatus(r);
}

int RunPanic(const GlobalOptions& g, const std::vector<std::string>& args) {
  RejectOptions(args);
  if (args.size() != 1) throw UsageError("usage: robotalk panic ROBOT");
  RobotClient client(MakeOptions(g));
  client.Connect(args[0]);
  client.Panic();
  std::cout << "panic acknowledged by " << args[0] << "\n";
  return 0;
}

int RunReset(const GlobalOptions& g, const std::vector<std::string>& args) {
  RejectOptions(args);
  if (args.size() != 1) throw UsageError("usage: robotalk reset ROBOT");
  RobotClient client(MakeOptions(g));
  client.Connect(args[0]);
  const Reply r = client.ResetPanic();
  PrintReply(r, std::cout);
  return ExitStatus(r);
}

}  // namespace robotalk::cli

namespace robotalk::cli {

int RunWatch(const GlobalOptions& g, const std::vector<std::string>& in) {
  std::vector<std::string> args = in;
  std::string period = "0.1", duration, count;
  TakeOption(args, "--period", &period);
  const bool has_duration = TakeOption(args, "--duration", &duration);
  const bool has_count = TakeOption(args, "--count", &count);
  RejectOptions(args);
  if (args.size() != 1)
    throw UsageError("usage: robotalk watch ROBOT [--period S] [--duration S] [--count N]");
  const double period_s = ParseNumber(period, "--period");
  const double duration_s = has_duration ? ParseNumber(duration, "--duration") : 1e9;
  const double max_samples = has_count ? ParseNumber(count, "--count") : 1e18;
  if (period_s < 0.001 || duration_s <= 0 || max_samples < 1) {
    throw UsageError("watch: --period must be >= 0.001 s, --duration and --count positive");
  }
  RobotClient client(MakeOptions(g));
  client.Connect(args[0]);
  std::cerr << "robotalk: watching ROBOTALK/" << args[0] << "/STATE (asked every " << period_s << " s)\n";
  std::mutex mu;
  std::condition_variable done_cv;
  double samples = 0;
  const Duration actual =
      client.StartStateStream(FromSeconds(period_s), [&](const robotalk_msgs::robot_state_t& s) {
        std::lock_guard lock(mu);
        if (samples >= max_samples) return;
        char line[160];
        std::snprintf(line, sizeof line, "%" PRId64 " t=%.3f base %.4f %.4f %.4f v=%.3f w=%.3f%s q", s.sample,
                      static_cast<double>(s.server_time_us) * 1e-6, s.base[0], s.base[1], s.base[2],
                      s.base[3], s.base[4], s.panic ? " PANIC" : "");
        std::cout << line;
        for (double q : s.position) std::cout << ' ' << q;
        std::cout << '\n' << std::flush;
        if (++samples >= max_samples) done_cv.notify_all();
      });
  if (actual != FromSeconds(period_s)) {
    std::cerr << "robotalk: the stream runs every " << ToSeconds(actual)
              << " s (another client asked for faster)\n";
  }
  {
    std::unique_lock lock(mu);
    done_cv.wait_for(lock, FromSeconds(duration_s), [&] { return samples >= max_samples; });
  }
  client.StopStateStream();
  return 0;
}

}  // namespace robotalk::cli
