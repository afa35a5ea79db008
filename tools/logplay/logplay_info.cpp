// robotalk-logplay: reading logs, frames and sequence files, info, CSV export.
#include "logplay.h"
#include "robotalk/channels.h"
#include "robotalk/log_writer.h"  // EscapeControls
#include "robotalk/sequence_file.h"
#include "sequence_runner.h"

#include <algorithm>
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <optional>
#include <ostream>
#include <sstream>

namespace robotalk::logplay {
namespace {

std::string Utc(std::int64_t us) {
  const std::time_t t = static_cast<std::time_t>(us / 1000000);
  std::tm tm{};
  gmtime_r(&t, &tm);
  char buf[40];
  std::strftime(buf, sizeof buf, "%Y-%m-%d %H:%M:%S UTC", &tm);
  return buf;
}

void PrintClient(const SessionLog& log, const LoggedClient& c, std::ostream& out) {
  std::map<std::string, int> types, signals;
  int commands = 0;
  for (const LoggedCommand& lc : log.commands()) {
    if (lc.client_id != c.id || lc.panic) continue;
    ++commands;
    ++types[ToString(lc.command.type)];
    if (lc.reply) ++signals[std::string(ToString(lc.reply->signal))];
  }
  out << "  " << Hex64(static_cast<std::uint64_t>(c.id)) << "  robot " << c.robot << "  packages "
      << c.packages << " (" << c.retransmissions << " retransmitted copies, " << c.heartbeats
      << " heartbeats)  queries " << c.queries << (c.panics ? "  PANIC x" + std::to_string(c.panics) : "");
  if (c.hellos > 0) {
    out << "  hellos " << c.hellos
        << (c.hellos_refused ? " (" + std::to_string(c.hellos_refused) + " refused)" : std::string());
  }
  out << "\n";
  if (commands == 0) return;
  out << "      commands " << commands << " in " << (c.modes.size() == 1 ? "mode" : "modes");
  for (RequestMode mode : c.modes) out << ' ' << ModeName(mode);
  out << ":";
  for (const auto& [t, n] : types) out << ' ' << t << ' ' << n;
  int absolute = 0, now = 0, playback = 0;
  for (const LoggedCommand& lc : log.commands()) {
    if (lc.client_id != c.id || lc.panic) continue;
    if (lc.mode == RequestMode::kPlayback) {
      ++playback;
    } else {
      ++(lc.start_us != 0 ? absolute : now);
    }
  }
  out << "; start times:";
  if (absolute) out << " absolute " << absolute;
  if (now) out << " now " << now;
  if (playback) out << " playback offsets " << playback;
  std::vector<Interpolation> interpolations;
  for (const LoggedCommand& lc : log.commands()) {
    if (lc.client_id == c.id && !lc.panic) interpolations.push_back(lc.interpolation);
  }
  out << DescribeInterpolations(interpolations);
  try {
    const Timeline t = log.MakeTimeline({.client_id = c.id});
    out << "; " << t.frames.size() << " frames over " << cli::FormatSeconds(t.frames.back().offset_s) << " ("
        << t.clock << " clock)";
  } catch (const LogError& e) {
    out << "; timing unknown (" << e.what() << ")";
  }
  if (!signals.empty()) {
    out << "; replies";
    for (const auto& [s, n] : signals) out << ' ' << s << ' ' << n;
  }
  out << "\n";
}

}  // namespace

std::string DescribeInterpolations(const std::vector<Interpolation>& each) {
  std::map<Interpolation, int> count;
  for (const Interpolation i : each) ++count[i];
  if (count.empty() || (count.size() == 1 && count.begin()->first == Interpolation::kStep)) return "";
  std::string text;
  for (const auto& [interpolation, n] : count)
    text += (text.empty() ? "; interpolation " : ", ") + std::string(InterpolationName(interpolation)) + " " +
            std::to_string(n);
  return text;
}

const char* ModeName(RequestMode mode) {
  switch (mode) {
    case RequestMode::kDirect:
      return "direct";
    case RequestMode::kDelay:
      return "delay";
    case RequestMode::kPlayback:
      return "playback";
  }
  return "?";
}

SessionLog ReadLog(const std::string& path) {
  LcmLogReader file = OpenLog(path);
  SessionLog log;
  while (const LcmLogEvent* e = file.Next()) log.Add(e->channel, e->timestamp_us, e->data);
  for (const std::string& d : file.damage()) log.AddDamage(d);
  if (file.damaged_stretches() > file.damage().size())
    log.AddDamage(std::to_string(file.damaged_stretches() - file.damage().size()) +
                  " more damaged stretches of '" + path + "'");
  return log;
}

LcmLogReader OpenLog(const std::string& path) {
  try {
    return LcmLogReader(path);
  } catch (const Error& e) {
    throw LogError(e.what());
  }
}

void PrintRejected(const SessionLog& log, const std::string& prefix, std::ostream& out) {
  const std::uint64_t n = log.rejections();
  if (n == 0) return;
  out << prefix << n << (n == 1 ? " log entry" : " log entries") << " rejected (not used):\n";
  for (const std::string& r : log.rejected()) out << prefix << "  " << r << "\n";
  if (n > log.rejected().size()) out << prefix << "  ... and " << n - log.rejected().size() << " more\n";
}

std::vector<TimedCommand> ToFrames(const Timeline& timeline, const FrameOptions& options) {
  if (!(options.speed > 0)) throw cli::UsageError("--speed must be positive");
  std::vector<TimedCommand> frames;
  for (const TimedFrame& f : timeline.frames) {
    if (f.offset_s < options.from_s - 1e-9 || f.offset_s > options.to_s + 1e-9) continue;
    Command c = f.source->command;
    c.id = 0;
    c.start_time.reset();
    if (auto it = options.rename.find(c.target); it != options.rename.end()) c.target = it->second;
    // F times faster: a waypoint's velocities F times, its accelerations F² times.
    for (double& v : c.velocities) v *= options.speed;
    for (double& a : c.accelerations) a *= options.speed * options.speed;
    // A set-point sent without a start time was a step whatever its package
    // said; replayed, every frame is timed, so it says step again.
    const bool was_timed = f.source->mode == RequestMode::kPlayback || f.source->start_us != 0;
    frames.push_back({FromSeconds((f.offset_s - options.from_s) / options.speed), std::move(c),
                      was_timed ? f.source->interpolation : Interpolation::kStep});
  }
  if (frames.empty()) throw LogError("the window holds no command");
  return frames;
}

std::string FormatSequence(const std::vector<TimedCommand>& frames, const std::string& header) {
  std::ostringstream out;
  std::istringstream lines(header);
  for (std::string line; std::getline(lines, line);) out << "# " << line << "\n";
  // The file has one interpolation line: that of its set-points (a GOTO's or
  // a STOP's package interpolation moves nothing; a frame without one takes
  // the file's). Set-points of two are refused rather than written as one of
  // them (replay keeps each).
  std::optional<std::size_t> first_setpoint;
  const auto interpolation = [&frames](std::size_t i) { return *frames[i].interpolation; };
  for (std::size_t i = 0; i < frames.size(); ++i) {
    if (WaypointRateCount(frames[i].command.type, 1) == 0 || !frames[i].interpolation) continue;
    if (!first_setpoint) {
      first_setpoint = i;
    } else if (interpolation(i) != interpolation(*first_setpoint)) {
      throw LogError("frame " + std::to_string(i + 1) + " " + ToString(frames[i].command.type) +
                     ": interpolation " + InterpolationName(interpolation(i)) + ", frame " +
                     std::to_string(*first_setpoint + 1) + "'s " +
                     InterpolationName(interpolation(*first_setpoint)) +
                     ": a sequence file has one interpolation (replay keeps each; --window can take one "
                     "stretch)");
    }
  }
  if (first_setpoint && interpolation(*first_setpoint) != Interpolation::kStep)
    out << "interpolation " << InterpolationName(interpolation(*first_setpoint)) << "\n";
  for (std::size_t i = 0; i < frames.size(); ++i) {
    const TimedCommand& f = frames[i];
    const std::string& target = f.command.target;
    // The file's words are split at blanks and cut at '#': a logged target
    // (anyone's bytes) that is not one such word would say something else.
    if (!target.empty() && (SplitWords(target) != std::vector<std::string>{target} ||
                            target.find('#') != std::string::npos || EscapeControls(target) != target)) {
      throw LogError(
          "frame " + std::to_string(i + 1) + " " + ToString(f.command.type) + ": target '" +
          Printable(target) +
          "' is not one word a sequence file can carry (blanks, '#' and control characters are not)");
    }
    char offset[32];
    std::snprintf(offset, sizeof offset, "%.6f", ToSeconds(f.offset));
    out << offset << ' ' << FormatCommandWords(f.command) << "\n";
  }
  return out.str();
}

std::pair<std::string, std::string> ParseRename(const std::string& text) {
  const auto eq = text.find('=');
  if (eq == std::string::npos || eq == 0 || eq + 1 == text.size())
    throw cli::UsageError("--map " + text + ": expected old=new");
  return {text.substr(0, eq), text.substr(eq + 1)};
}

std::pair<double, double> ParseWindow(const std::string& text) {
  const auto colon = text.find(':');
  if (colon == std::string::npos) throw cli::UsageError("--window " + text + ": expected A:B (seconds)");
  const std::string a = text.substr(0, colon), b = text.substr(colon + 1);
  const double from = a.empty() ? 0.0 : cli::ParseNumber(a, "--window start");
  const double to = b.empty() ? std::numeric_limits<double>::infinity() : cli::ParseNumber(b, "--window end");
  if (from < 0 || to <= from) throw cli::UsageError("--window " + text + ": need 0 <= A < B");
  return {from, to};
}

void PrintInfo(const SessionLog& log, const std::string& path, std::ostream& out) {
  out << "log " << path << ": " << log.events() << " events";
  if (log.events() > 0) {
    out << " over " << cli::FormatSeconds(static_cast<double>(log.last_us() - log.first_us()) * 1e-6) << ", "
        << Utc(log.first_us()) << " .. " << Utc(log.last_us());
  }
  out << "\nchannels:\n";
  for (const auto& [name, s] : log.channels()) {
    char line[200];
    std::snprintf(line, sizeof line, "  %-44s %7" PRIu64 " msgs %10" PRIu64 " bytes", name.c_str(),
                  s.messages, s.bytes);
    out << line << (s.undecodable ? "  (" + std::to_string(s.undecodable) + " undecodable)" : "") << "\n";
  }
  PrintRejected(log, "", out);
  const auto servers = log.servers();
  out << "servers: " << servers.size();
  for (std::int64_t s : servers) out << ' ' << Hex64(static_cast<std::uint64_t>(s));
  out << "\nrobots:\n";
  for (const LoggedRobot& r : log.robots()) {
    out << "  " << r.name << "  driver " << r.driver << "  dofs " << r.total_dofs << "  server "
        << Hex64(static_cast<std::uint64_t>(r.server_id)) << "  config " << Hex64(r.config_hash)
        << (r.panic_seen ? "  (panic seen)" : "") << "\n";
  }
  out << "clients: " << log.clients().size() << "\n";
  for (const auto& [id, c] : log.clients()) PrintClient(log, c, out);
  std::map<std::string, const StateSample*> last;
  std::map<std::string, int> counts;
  for (const StateSample& s : log.states()) {
    last[s.robot] = &s;
    ++counts[s.robot];
  }
  for (const auto& [robot, s] : last) {
    char line[200];
    std::snprintf(line, sizeof line, "state %s: %d samples; final base x %.4f y %.4f theta %.4f",
                  robot.c_str(), counts[robot], s->base[0], s->base[1], s->base[2]);
    out << line << "; q";
    for (double q : s->position) out << ' ' << FormatNumber(q);
    out << "\n";
  }
}

}  // namespace robotalk::logplay
