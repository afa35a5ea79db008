#include "cli_commands.h"

#include "describe_format.h"
#include "sequence_file.h"

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <iostream>
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
  std::printf("%-20s %-10s %5s %-16s %-5s %7s %s\n", "ROBOT", "DRIVER", "DOFS", "CONFIG_HASH", "PANIC", "CLIENTS",
              "SERVER");
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
  if (!type) throw UsageError("unknown query '" + args[1] + "' (joint_state, link_poses, frame_poses, base_pose)");
  RobotClient client(MakeOptions(g));
  client.Connect(args[0]);
  const Reply r = client.Query(*type, args.size() == 3 ? args[2] : "");
  PrintReply(r, std::cout);
  return ExitStatus(r);
}

namespace {

int SendFile(const GlobalOptions& g, const std::string& robot, const std::string& path) {
  std::ifstream file(path);
  if (!file) throw UsageError("cannot read sequence file '" + path + "'");
  std::stringstream text;
  text << file.rdbuf();
  const auto entries = ParseSequence(text.str(), path);  // all lines checked before connecting

  RobotClient client(MakeOptions(g));
  client.Connect(robot);
  const TimePoint base = client.ServerNow();
  // Several packages when the sequence is long (each must stay under ~60 KB).
  constexpr std::size_t kPerPackage = 200;
  std::vector<PendingReply> pending;
  for (std::size_t first = 0; first < entries.size(); first += kPerPackage) {
    std::vector<Command> batch;
    for (std::size_t i = first; i < std::min(entries.size(), first + kPerPackage); ++i) {
      Command c = entries[i].command;
      c.start_time = base + FromSeconds(entries[i].offset_s);
      batch.push_back(std::move(c));
    }
    for (auto& p : client.SendBatch(std::move(batch))) pending.push_back(std::move(p));
  }
  int status = 0;
  for (std::size_t i = 0; i < pending.size(); ++i) {
    const Duration until_start = std::max(Duration::zero(), base + FromSeconds(entries[i].offset_s) - client.ServerNow());
    try {
      const Reply r = pending[i].Wait(until_start + client.options().timeout);
      PrintReply(r, std::cout);
      std::cout.flush();
      status = std::max(status, ExitStatus(r));
    } catch (const TimeoutError& e) {
      std::cerr << "robotalk: " << path << ":" << entries[i].line << ": " << e.what() << "\n";
      status = 1;
    }
  }
  return status;
}

}  // namespace

int RunSend(const GlobalOptions& g, const std::vector<std::string>& in) {
  std::vector<std::string> args = in;
  std::string file, at;
  const bool has_file = TakeOption(args, "--file", &file);
  const bool has_at = TakeOption(args, "--at", &at);
  RejectOptions(args);
  if (args.empty()) throw UsageError("usage: robotalk send ROBOT COMMAND ARGS... [--at S] | send ROBOT --file SEQ.txt");
  if (has_file) {
    if (args.size() != 1 || has_at) throw UsageError("send ROBOT --file SEQ.txt takes nothing else");
    return SendFile(g, args[0], file);
  }
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
