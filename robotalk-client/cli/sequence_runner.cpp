#include "sequence_runner.h"

#include "interrupt.h"
#include "robotalk/log_writer.h"  // EscapeControls

#include <algorithm>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <cstdlib>
#include <mutex>
#include <regex>
#include <utility>

namespace robotalk::cli {
namespace {

using std::chrono::milliseconds;
constexpr Duration kProgressEvery = milliseconds(50);

TimePoint SteadyNow() { return SteadyClock().Now(); }

// Sends a STOP at each of `starts` (server clock), in packages of `batch`.
std::size_t SendShadowStops(RobotClient& client, const std::vector<TimePoint>& starts, std::size_t batch) {
  std::size_t sent = 0;
  for (std::size_t k = 0; k < starts.size(); k += batch) {
    std::vector<Command> stops;
    for (std::size_t j = k; j < std::min(starts.size(), k + batch); ++j)
      stops.push_back({.type = CommandType::kStop, .start_time = starts[j]});
    try {
      // Part of the delay session; nobody waits: the handles may go.
      sent += client.SendBatch(std::move(stops), CommandMode::kDelay).size();
    } catch (const std::exception&) {
      break;
    }
  }
  return sent;
}

}  // namespace

std::string FormatSeconds(double seconds) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.3f", seconds);
  std::string s = buf;
  if (s.find('.') != std::string::npos) {
    while (!s.empty() && s.back() == '0') s.pop_back();
    if (!s.empty() && s.back() == '.') s.pop_back();
  }
  if (s == "-0") s = "0";
  return s + " s";
}

std::string TidyDurations(const std::string& message) {
  static const std::regex number(R"((-?\d+\.\d+) s\b)");
  std::string out;
  auto begin = std::sregex_iterator(message.begin(), message.end(), number);
  std::size_t last = 0;
  for (auto it = begin; it != std::sregex_iterator(); ++it) {
    out += message.substr(last, static_cast<std::size_t>(it->position()) - last);
    out += FormatSeconds(std::stod((*it)[1].str()));
    last = static_cast<std::size_t>(it->position() + it->length());
  }
  return out + message.substr(last);
}

std::string ErrorText(const std::string& message) {
  // A line break followed by an indent is kept (the client's own blocks: the
  // "key has CHANGED" warning); every other control character is escaped, so
  // a text of anyone's inside an error never begins a line of its own.
  const std::string tidy = TidyDurations(message);
  std::string out;
  std::size_t start = 0;
  for (std::size_t at; (at = tidy.find("\n  ", start)) != std::string::npos; start = at + 1)
    out += EscapeControls(std::string_view(tidy).substr(start, at - start)) + "\n";
  return out + EscapeControls(std::string_view(tidy).substr(start));
}

std::string ProgressBar(const RunProgress& p, int width) {
  const double total_s = ToSeconds(p.duration);
  const double elapsed_s = std::clamp(ToSeconds(p.elapsed), 0.0, std::max(total_s, 0.0));
  double fraction = total_s > 0 ? elapsed_s / total_s : 0.0;
  if (p.total > 0)
    fraction = std::max(fraction, static_cast<double>(p.answered) / static_cast<double>(p.total));
  const int filled = static_cast<int>(std::lround(std::clamp(fraction, 0.0, 1.0) * width));
  char tail[96];
  std::snprintf(tail, sizeof tail, "] %zu/%zu  %.1f s / ", p.answered, p.total, elapsed_s);
  return "[" + std::string(filled, '#') + std::string(width - filled, '.') + tail + FormatSeconds(total_s);
}

StopOnInterrupt::StopOnInterrupt(RobotClient& client, std::stop_token interrupt)
    : sender_([this, &client, interrupt](std::stop_token done) {
        std::mutex mu;
        std::condition_variable_any cv;
        const std::stop_callback wake(interrupt, [&] {
          std::lock_guard lock(mu);
          cv.notify_all();
        });
        {
          std::unique_lock lock(mu);
          if (!cv.wait(lock, done, [&] { return interrupt.stop_requested(); }))
            return;  // the tool ended first
        }
        std::optional<PendingReply> stop;
        try {
          stop = client.Send(Command{.type = CommandType::kStop});  // not waited for: StopNow follows
        } catch (const std::exception&) {
          // StopNow, when the tool's thread gets there, says what failed.
        }
        // A STOP does not cancel frames queued for later start times: the
        // tool's thread does (delay mode's shadow STOPs) or its exit does (the
        // session expires, the watchdog drops the queue). A thread still busy
        // after kTakeOver (waiting in a write) would keep the session, and
        // so those frames, alive: end the process instead.
        std::unique_lock lock(mu);
        cv.wait_for(lock, done, kTakeOver, [] { return false; });  // until the tool ends, at most kTakeOver
        if (done.stop_requested()) return;
        int status = Interrupter::ExitStatus(Interrupter::Signal());
        if (signal_ends_) {
          std::optional<Reply> r;
          try {
            if (stop) r = stop->WaitFor(Duration(0));
          } catch (const std::exception&) {
          }
          status = r && Succeeded(r->signal) ? 0 : 1;
        }
        std::_Exit(status);
      }) {}

std::string StopNow(RobotClient& client, bool* succeeded) {
  if (succeeded) *succeeded = false;
  try {
    const Reply r = client.Stop();
    if (succeeded) *succeeded = Succeeded(r.signal);
    return "STOP sent to " + client.robot() + ": " + std::string(ToString(r.signal)) +
           (r.message.empty() ? "" : " (" + ErrorText(r.message) + ")");
  } catch (const std::exception& e) {
    return "STOP to " + client.robot() + " failed: " + ErrorText(e.what());
  }
}

std::optional<Reply> AwaitReply(PendingReply& pending, const std::function<void(Duration)>& on_progress) {
  const TimePoint t0 = SteadyNow();
  const std::stop_token stop = Interrupter::StopToken();
  for (;;) {
    // Wakes for the reply at once; throws TimeoutError once the client gave up.
    if (auto r = pending.WaitFor(kProgressEvery, stop)) return r;
    if (Interrupter::Signal()) return std::nullopt;
    if (on_progress) on_progress(SteadyNow() - t0);
  }
}

RunReport RunFrames(RobotClient& client, std::vector<TimedCommand> frames, const SequenceOptions& options,
                    const ReplyCallback& on_reply, const ProgressCallback& on_progress,
                    std::stop_token stop) {
  const std::size_t total = frames.size();
  // The library runs every mode (RobotClient::RunSequence); the CLI waits
  // as long as the server answers, and in delay mode names each frame of
  // unknown outcome instead of giving up on the rest.
  const SequenceHooks hooks{.on_reply = on_reply,
                            .on_progress = on_progress,
                            .progress_every = kProgressEvery,
                            .stop = std::move(stop),
                            .wait_until_given_up = true,
                            .collect_unknown_outcomes = options.mode == CommandMode::kDelay};
  const SequenceResult result = client.RunSequence(std::move(frames), options, hooks);
  RunReport report;
  report.replies.resize(total);
  for (std::size_t i = 0; i < total; ++i)
    if (result.replies[i].id != 0) report.replies[i] = result.replies[i];
  report.playback_delay = result.playback_delay;
  report.unknown_outcomes = result.unknown_outcomes;
  if (!result.stopped) return report;

  report.signal = Interrupter::Signal();
  std::string note = StopNow(client);
  if (options.mode == CommandMode::kDirect) {
    note += "; the frames not yet sent were not sent";
  } else if (options.mode == CommandMode::kPlayback) {
    note +=
        "; playback frames already queued on the server stay queued until this client's session expires "
        "(then "
        "the watchdog stops the robot)";
  } else {
    // Frames already queued on the server would still run: end each as it begins.
    const std::size_t shadows =
        SendShadowStops(client, result.queued, std::max<std::size_t>(options.batch, 1));
    if (shadows > 0)
      note += "; " + std::to_string(shadows) +
              " frames already queued on the server each get a STOP at their start time "
              "(a queued command cannot be cancelled)";
    if (result.frames_sent < total)
      note += "; " + std::to_string(total - result.frames_sent) + " frames not sent";
  }
  report.interrupt_note = note;
  return report;
}

}  // namespace robotalk::cli
