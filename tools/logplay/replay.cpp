// robotalk-logplay replay: a recorded client's motion, sent again through
// RobotClient (never the recorded bytes) to a live robot.
#include "interrupt.h"
#include "logplay.h"
#include "output_lines.h"
#include "robotalk/channels.h"
#include "robotalk/log_writer.h"
#include "sequence_runner.h"

#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <map>
#include <memory>
#include <optional>
#include <set>

namespace robotalk::logplay {
namespace {

// Names the target robot lacks, so nothing is sent that would fail late.
std::set<std::string> UnknownTargets(const RobotModel& model, const std::vector<TimedCommand>& frames) {
  std::set<std::string> unknown;
  for (const TimedCommand& f : frames) {
    const Command& c = f.command;
    if (c.target.empty()) continue;
    const bool frame = Traits(c.type).target == CommandTarget::kFrame;
    if (frame ? !model.FindFrame(c.target) : !model.FindJoint(c.target)) unknown.insert(c.target);
  }
  return unknown;
}

// "; interpolation cubic 40, step 2", or "" when every frame is a step.
std::string InterpolationsOf(const std::vector<TimedCommand>& frames) {
  std::vector<Interpolation> each;
  for (const TimedCommand& f : frames) each.push_back(f.interpolation.value_or(Interpolation::kStep));
  return DescribeInterpolations(each);
}

std::string Describe(const Selection& s) {
  if (s.client_id) return "client " + Hex64(static_cast<std::uint64_t>(*s.client_id));
  return "robot '" + s.robot + "'";
}

}  // namespace

int Replay(const SessionLog& log, const ReplayOptions& o, std::ostream& out) {
  Selection selection = o.selection;
  if (!selection.client_id && selection.robot.empty()) selection.robot = o.robot;
  PrintRejected(log, "robotalk-logplay: ", std::cerr);
  const Timeline timeline = log.MakeTimeline(selection);
  for (const std::string& s : timeline.skipped) std::cerr << "robotalk-logplay: not replayed: " << s << "\n";
  const std::vector<TimedCommand> frames = ToFrames(timeline, o.frames);

  ClientOptions co;
  co.lcm_url = o.url;
  co.timeout = FromSeconds(o.timeout_s);
  co.connect_timeout = FromSeconds(o.timeout_s);
  auto client = std::make_unique<RobotClient>(co);
  client->Connect(o.robot);
  if (const auto unknown = UnknownTargets(client->model(), frames); !unknown.empty()) {
    std::string names;
    for (const std::string& n : unknown) names += (names.empty() ? "" : ", ") + n;
    throw LogError("robot '" + o.robot + "' has no joint or frame named " + names +
                   " (rename with --map old=new)");
  }
  const Duration duration = frames.back().offset;
  // Before anything moves: this line may wait for its stdout, nothing else.
  out << "replaying " << frames.size() << " commands of " << Describe(selection) << " onto '" << o.robot
      << "' in " << ToString(o.sequence.mode) << " mode over " << cli::FormatDuration(duration)
      << " (timing from " << timeline.clock << " clock" << InterpolationsOf(frames) << ")\n"
      << std::flush;

  std::map<std::string, int> signals;
  bool all_ok = true;
  std::cerr.flush();  // before the failure lines' own thread writes to stderr
  // While frames run nothing waits for an output (a stderr or terminal that
  // takes nothing would hold the frames, and the heartbeats the session): the
  // failure lines go through a thread of their own, the progress line never
  // waits (as robotalk send --file).
  cli::OutputLines failures(STDERR_FILENO);
  const cli::TtyProgress progress;
  const bool show = o.progress && progress.on();
  cli::Interrupter::Defer(true);  // from here on a signal means: STOP what was sent
  std::optional<cli::StopOnInterrupt> stop_at_once(std::in_place, *client);
  // Nothing more for the robot: the session ends before the tool waits for
  // its output, and a signal ends the tool at once.
  const auto end_session = [&] {
    stop_at_once.reset();
    client.reset();
    cli::Interrupter::Defer(false);
  };
  const TimePoint t0 = SteadyClock().Now();
  cli::RunReport report;
  try {
    report = cli::RunFrames(
        *client, frames, o.sequence,
        [&](std::size_t i, const Reply& r) {
          ++signals[std::string(ToString(r.signal))];
          if (!Succeeded(r.signal)) {
            all_ok = false;
            if (show) progress.Clear();
            failures.Add("robotalk-logplay: frame " + std::to_string(i + 1) + " " +
                         std::string(ToString(frames[i].command.type)) + ": " +
                         std::string(ToString(r.signal)) + " " + EscapeControls(r.message) + "\n");
          }
        },
        [&](const cli::RunProgress& p) {
          if (show && failures.idle()) progress.Show("\r" + cli::ProgressBar(p) + "  ");
        });
  } catch (...) {
    end_session();
    failures.Finish();
    throw;
  }
  if (show) progress.Clear();
  const Duration took = SteadyClock().Now() - t0;
  // After a signal the STOP has left; the tool ends within
  // StopOnInterrupt::kTakeOver if its output takes nothing.
  if (!report.signal) end_session();
  if (const std::uint64_t lost = failures.Finish(); lost > 0) {
    std::cerr << "robotalk-logplay: " << lost << " failure lines lost: stderr took no more\n";
  }
  std::size_t answered = 0;
  for (const auto& r : report.replies) answered += r.has_value();
  out << "replayed " << answered << "/" << frames.size() << " commands onto '" << o.robot << "' in "
      << cli::FormatDuration(took);
  if (report.playback_delay)
    out << " (server's playback delay " << cli::FormatDuration(*report.playback_delay) << ")";
  out << ":";
  for (const auto& [s, n] : signals) out << ' ' << s << ' ' << n;
  out << "\n" << std::flush;
  if (report.signal) {
    std::cerr << "robotalk-logplay: interrupted by " << cli::Interrupter::Name(report.signal) << ": "
              << report.interrupt_note << "\n";
    return cli::Interrupter::ExitStatus(report.signal);
  }
  return all_ok ? 0 : 1;
}

}  // namespace robotalk::logplay
