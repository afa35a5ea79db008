// `robotalk send`: one command or a sequence file, waited for to its end,
// stopped on Ctrl-C / SIGTERM (docs/client.md, "Ctrl-C and long commands").
#include "cli_commands.h"
#include "cli_support.h"
#include "interrupt.h"
#include "output_lines.h"
#include "robotalk/sequence_file.h"
#include "sequence_runner.h"

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <optional>
#include <sstream>

namespace robotalk::cli {
namespace {

struct SequenceFlags {
  SequenceOptions options;
  bool any = false;                            // a mode flag was given (only valid with --file)
  std::optional<Interpolation> interpolation;  // --interpolation: overrides the file's
  bool delay_given = false;                    // --delay
};

// Delay mode's default lead for an interpolated sequence: its first
// waypoints must arrive before their time, or the server skips them.
constexpr Duration kInterpolatedDelay = std::chrono::milliseconds(500);

// --mode direct|delay|playback, --delay S, --paced, --interpolation WORD.
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
    const double d = ParseSeconds(delay, "--delay");
    if (f.options.mode != CommandMode::kDelay) throw UsageError("--delay goes with --mode delay");
    f.options.delay = FromSeconds(d);
    f.delay_given = true;
    f.any = true;
  }
  if (TakeOption(args, "--paced", nullptr)) {
    f.options.paced = true;
    f.any = true;
  }
  std::string interpolation;
  if (TakeOption(args, "--interpolation", &interpolation)) {
    f.interpolation = ParseInterpolationWord(interpolation, "--interpolation");
    f.any = true;
  }
  if (f.options.mode == CommandMode::kDirect) f.options.paced = true;  // a handshake per frame, at its time
  return f;
}

void PrintOne(const Reply& r, bool json, std::ostream& out = std::cout) {
  if (json) {
    out << ReplyJson(r) << '\n' << std::flush;
  } else {
    PrintReply(r, out);
    out << std::flush;
  }
}

std::string ReplyText(const Reply& r, bool json) {
  std::ostringstream text;
  PrintOne(r, json, text);
  return text.str();
}

// After a signal: says what was stopped; returns 128 + signal.
int Interrupted(int signal, const std::string& note) {
  std::cerr << "robotalk: interrupted by " << Interrupter::Name(signal) << ": " << note << "\n";
  return Interrupter::ExitStatus(signal);
}

int SendFile(const GlobalOptions& g, const std::string& robot, const std::string& path,
             const SequenceFlags& flags, bool json) {
  std::ifstream file(path);
  if (!file) throw UsageError("cannot read sequence file '" + path + "'");
  std::stringstream text;
  text << file.rdbuf();
  const SequenceFile sequence = ParseSequenceFile(text.str(), path);  // all lines checked before connecting
  const auto& entries = sequence.entries;
  SequenceOptions options = flags.options;
  options.interpolation = flags.interpolation.value_or(sequence.interpolation.value_or(Interpolation::kStep));
  if (options.mode == CommandMode::kDirect && options.interpolation != Interpolation::kStep) {
    throw UsageError(std::string("interpolation ") + InterpolationName(options.interpolation) +
                     " needs --mode delay or playback (a direct frame has no start time, so it is a step)");
  }
  if (options.mode == CommandMode::kDelay && options.interpolation != Interpolation::kStep &&
      !flags.delay_given)
    options.delay = kInterpolatedDelay;
  std::vector<TimedCommand> frames;
  bool rates = false;
  for (const auto& e : entries) {
    frames.push_back({FromSeconds(e.offset_s), e.command});
    rates = rates || !e.command.velocities.empty() || !e.command.accelerations.empty();
  }
  if (rates && options.interpolation == Interpolation::kStep) {
    std::cerr << "robotalk: note: " << path
              << " gives velocities or accelerations, which a step sequence ignores "
                 "(--interpolation cubic, or an 'interpolation' line, uses them)\n";
  }

  auto client = ConnectClient(g, robot);
  std::cout.flush();  // before the reply lines' own thread writes to stdout
  OutputLines replies(STDOUT_FILENO);
  Interrupter::Defer(true);  // from here on a signal means: STOP what was sent
  std::optional<StopOnInterrupt> stop_at_once(std::in_place, *client);
  // Nothing more for the robot: the session ends before the tool waits for
  // its output (a stdout or stderr that takes nothing waits for ever; the
  // heartbeats would keep the last frame's motion alive meanwhile), and a
  // signal ends the tool at once.
  const auto end_session = [&] {
    stop_at_once.reset();
    client.reset();
    Interrupter::Defer(false);
  };
  const TtyProgress progress;
  int status = 0;
  RunReport report;
  try {
    report = RunFrames(
        *client, std::move(frames), options,
        [&](std::size_t, const Reply& r) {
          progress.Clear();
          replies.Add(ReplyText(r, json));  // never waits for stdout
          status = std::max(status, ExitStatus(r));
        },
        [&](const RunProgress& p) {
          if (replies.idle()) progress.Show("\r" + ProgressBar(p));  // never inside a reply line
        });
  } catch (...) {
    end_session();
    replies.Finish();
    throw;
  }
  progress.Clear();
  // After a signal the STOP has left; the tool ends within
  // StopOnInterrupt::kTakeOver if its output takes nothing.
  if (!report.signal) end_session();
  if (const std::uint64_t lost = replies.Finish(); lost > 0) {
    std::cerr << "robotalk: " << lost << " reply lines lost: stdout took no more\n";
    status = std::max(status, 1);
  }
  for (const auto& [index, why] : report.unknown_outcomes) {
    std::cerr << "robotalk: line " << entries[index].line << ": " << ErrorText(why) << "\n";
  }
  if (!report.unknown_outcomes.empty()) {
    std::cerr << "robotalk: " << report.unknown_outcomes.size() << " of " << entries.size()
              << " commands may or may not have run; check the robot's state before sending them again\n";
    status = std::max(status, 1);
  }
  if (report.playback_delay) {
    std::cerr << "robotalk: playback: the server starts the sequence "
              << FormatDuration(*report.playback_delay) << " after its first frame arrived\n";
  }
  if (report.signal) return Interrupted(report.signal, report.interrupt_note);
  return status;
}

// Commands that move on until stopped (kCommandTraits): the server's watchdog
// stops them when their client's session ends.
bool HeldWhileAlive(CommandType t) { return Traits(t).keeps_moving; }

int SendOne(const GlobalOptions& g, const std::string& robot, Command c, std::optional<double> at, bool hold,
            bool json) {
  auto client = ConnectClient(g, robot);
  if (at) c.start_time = client->ServerNow() + FromSeconds(*at);
  const CommandType type = c.type;
  const bool motion = IsMotionCommand(type);
  Interrupter::Defer(true);  // from here on a signal means: STOP what was sent
  std::optional<StopOnInterrupt> stop_at_once;
  if (motion) stop_at_once.emplace(*client);
  PendingReply pending = client->Send(std::move(c));
  const TtyProgress progress;
  const bool bar = progress.on() && (Traits(type).kind == CommandKind::kTask || at);
  const std::optional<Reply> r = AwaitReply(pending, [&](Duration waited) {
    if (bar && waited > std::chrono::milliseconds(300))
      progress.Show("\r" + std::string(ToString(type)) + " " + std::to_string(pending.id()) +
                    ": waiting for its end, " + FormatSeconds(std::round(ToSeconds(waited) * 10) / 10) +
                    " \033[K");
  });
  if (bar) progress.Clear();
  if (!r) {
    const int sig = Interrupter::Signal();
    if (!motion) return Interrupted(sig, "nothing was moving");
    const std::string note = StopNow(*client) + " for the " + ToString(type) + " this command started";
    try {
      PrintOne(pending.Wait(std::chrono::seconds(1)), json);  // usually INTERRUPTED by the STOP
    } catch (const std::exception&) {
    }
    return Interrupted(sig, note);
  }
  if (!hold || !Succeeded(r->signal) || !HeldWhileAlive(type)) {
    // Nothing more for the robot: the session ends before a word is written.
    // A stdout or stderr that takes nothing (a full pipe, a terminal stopped
    // with Ctrl-S) waits for ever, and the heartbeats would keep a motion
    // "kept only while this command runs" alive meanwhile (a SETSPEED drove
    // on); now the watchdog stops it after --session-timeout, and a signal
    // ends the tool at once.
    stop_at_once.reset();
    client.reset();
    Interrupter::Defer(false);
  }
  PrintOne(*r, json);
  if (!Succeeded(r->signal) || !HeldWhileAlive(type)) {
    if (hold) std::cerr << "robotalk: --hold applies to setspeed, joint_speed and joint_force only\n";
    return ExitStatus(*r);
  }
  if (!hold) {
    std::cerr
        << "robotalk: note: " << robot << " keeps this " << ToString(type)
        << " only while this command runs: the server's watchdog stops the robot about its "
           "--session-timeout (default 2 s) after robotalk exits. Use --hold to keep it until Ctrl-C.\n";
    return ExitStatus(*r);
  }
  stop_at_once->SignalIsTheEnd();  // Ctrl-C ends the hold: its status, not an interrupted run's
  std::cerr << "robotalk: holding " << ToString(type) << " on " << robot << " until Ctrl-C (then STOP)\n";
  while (!Interrupter::Signal()) Interrupter::WaitFor(std::chrono::seconds(1));
  // The STOP first, then the line: a stderr that takes nothing must not keep
  // the robot moving (the CLI's heartbeats keep its session alive meanwhile).
  bool stop_succeeded = false;
  const std::string stopped = StopNow(*client, &stop_succeeded);
  std::cerr << "robotalk: " << stopped << " (hold ended by " << Interrupter::Name(Interrupter::Signal())
            << ")\n";
  return stop_succeeded ? 0 : 1;  // as the take-over would (StopOnInterrupt::SignalIsTheEnd)
}

}  // namespace

int RunSend(const GlobalOptions& g, const std::vector<std::string>& in) {
  std::vector<std::string> args = in;
  std::string file, at;
  const bool has_file = TakeOption(args, "--file", &file);
  const bool has_at = TakeOption(args, "--at", &at);
  const bool hold = TakeOption(args, "--hold", nullptr);
  const bool json = TakeOption(args, "--json", nullptr);
  const SequenceFlags sequence = TakeSequenceFlags(args);
  RejectOptions(args);
  if (args.empty()) {
    throw UsageError(
        "usage: robotalk send ROBOT COMMAND ARGS... [--at S] [--hold] | send ROBOT --file SEQ.txt [--mode M] "
        "[--delay S] [--paced] [--interpolation step|linear|cubic|quintic]");
  }
  if (has_file) {
    if (args.size() != 1 || has_at || hold) throw UsageError("send ROBOT --file SEQ.txt takes nothing else");
    return SendFile(g, args[0], file, sequence, json);
  }
  if (sequence.any) throw UsageError("--mode, --delay, --paced and --interpolation go with --file");
  Command c = ParseCommandWords({args.begin() + 1, args.end()});
  if (!c.velocities.empty() || !c.accelerations.empty()) {
    throw UsageError(
        "velocity and acceleration are a waypoint's: give them in a sequence file with an interpolation "
        "(send ROBOT --file SEQ.txt --interpolation cubic)");
  }
  if (hold && !HeldWhileAlive(c.type))
    throw UsageError("--hold goes with setspeed, joint_speed or joint_force");
  std::optional<double> delay;
  if (has_at) {
    delay = ParseSeconds(at, "--at");
  }
  return SendOne(g, args[0], std::move(c), delay, hold, json);
}

}  // namespace robotalk::cli
