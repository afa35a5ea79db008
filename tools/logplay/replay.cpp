// robotalk-logplay replay: a recorded client's motion, sent again through
// RobotClient (never the recorded bytes) to a live robot.
#include "interrupt.h"
#include "logplay.h"
#include "robotalk/channels.h"
#include "sequence_runner.h"

#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <map>
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
  RobotClient client(co);
  client.Connect(o.robot);
  if (const auto unknown = UnknownTargets(client.model(), frames); !unknown.empty()) {
    std::string names;
    for (const std::string& n : unknown) names += (names.empty() ? "" : ", ") + n;
    throw LogError("robot '" + o.robot + "' has no joint or frame named " + names +
                   " (rename with --map old=new)");
  }
  const Duration duration = frames.back().offset;
  out << "replaying " << frames.size() << " commands of " << Describe(selection) << " onto '" << o.robot
      << "' in " << ToString(o.sequence.mode) << " mode over " << cli::FormatDuration(duration)
      << " (timing from " << timeline.clock << " clock" << InterpolationsOf(frames) << ")\n"
      << std::flush;

  std::map<std::string, int> signals;
  bool all_ok = true;
  cli::Interrupter::Defer(true);  // from here on a signal means: STOP what was sent
  const cli::StopOnInterrupt stop_at_once(client);
  const TimePoint t0 = SteadyClock().Now();
  const cli::RunReport report = cli::RunFrames(
      client, frames, o.sequence,
      [&](std::size_t i, const Reply& r) {
        ++signals[std::string(ToString(r.signal))];
        if (!Succeeded(r.signal)) {
          all_ok = false;
          if (o.progress) std::cerr << "\n";
          std::cerr << "robotalk-logplay: frame " << i + 1 << " " << ToString(frames[i].command.type) << ": "
                    << ToString(r.signal) << " " << r.message << "\n";
        }
      },
      [&](const cli::RunProgress& p) {
        if (o.progress) std::cerr << "\r" << cli::ProgressBar(p) << "  " << std::flush;
      });
  if (o.progress) std::cerr << "\n";
  std::size_t answered = 0;
  for (const auto& r : report.replies) answered += r.has_value();
  out << "replayed " << answered << "/" << frames.size() << " commands onto '" << o.robot << "' in "
      << cli::FormatDuration(SteadyClock().Now() - t0);
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
