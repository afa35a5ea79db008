#include "sequence_runner.h"

#include "interrupt.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <future>
#include <memory>
#include <regex>
#include <thread>

namespace robotalk::cli {
namespace {

using std::chrono::milliseconds;
constexpr Duration kSlice = milliseconds(20);
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

RunReport RunPlayback(RobotClient& client, std::vector<TimedCommand> frames, const SequenceOptions& options,
                      const ReplyCallback& on_reply, const ProgressCallback& on_progress, Duration duration) {
  RunReport report;
  report.replies.resize(frames.size());
  const std::size_t total = frames.size();
  auto task = std::make_shared<std::packaged_task<SequenceResult()>>(
      [&client, frames = std::move(frames), options]() mutable {
        return client.RunSequence(frames, options);
      });
  std::future<SequenceResult> done = task->get_future();
  std::thread worker([task] { (*task)(); });
  const TimePoint t0 = SteadyNow();
  while (done.wait_for(std::chrono::seconds(0)) != std::future_status::ready) {
    if (const int sig = Interrupter::Signal()) {
      report.signal = sig;
      report.interrupt_note = StopNow(client) +
                              "; playback frames already queued on the server stay queued until this "
                              "client's session expires (then the watchdog stops the robot)";
      report.worker_abandoned = true;
      worker.detach();
      return report;
    }
    if (on_progress) on_progress({0, total, SteadyNow() - t0, duration});
    Interrupter::WaitFor(kProgressEvery);
  }
  worker.join();
  SequenceResult result = done.get();  // rethrows the worker's exception
  report.playback_delay = result.playback_delay;
  for (std::size_t i = 0; i < result.replies.size(); ++i) {
    report.replies[i] = result.replies[i];
    if (on_reply) on_reply(i, result.replies[i]);
  }
  return report;
}

RunReport RunDirect(RobotClient& client, std::vector<TimedCommand> frames,
                    const std::vector<std::size_t>& order, const ReplyCallback& on_reply,
                    const ProgressCallback& on_progress, Duration duration) {
  RunReport report;
  report.replies.resize(frames.size());
  const TimePoint t0 = SteadyNow();
  std::size_t answered = 0;
  for (std::size_t i : order) {
    // The handshake: a frame leaves at its time, never before the previous reply.
    while (SteadyNow() < t0 + frames[i].offset && !Interrupter::Signal())
      Interrupter::WaitFor(std::min(kSlice, t0 + frames[i].offset - SteadyNow()));
    if (!Interrupter::Signal()) {
      Command c = std::move(frames[i].command);
      c.start_time.reset();
      PendingReply p = client.Send(std::move(c));
      const auto r = AwaitReply(p, [&](Duration) {
        if (on_progress) on_progress({answered, frames.size(), SteadyNow() - t0, duration});
      });
      if (r) {
        report.replies[i] = *r;
        ++answered;
        if (on_reply) on_reply(i, *r);
        continue;
      }
    }
    report.signal = Interrupter::Signal();
    report.interrupt_note = StopNow(client) + "; the frames not yet sent were not sent";
    return report;
  }
  return report;
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

std::string StopNow(RobotClient& client) {
  try {
    const Reply r = client.Stop();
    return "STOP sent to " + client.robot() + ": " + std::string(ToString(r.signal)) +
           (r.message.empty() ? "" : " (" + r.message + ")");
  } catch (const std::exception& e) {
    return "STOP to " + client.robot() + " failed: " + TidyDurations(e.what());
  }
}

std::optional<Reply> AwaitReply(PendingReply& pending, const std::function<void(Duration)>& on_progress) {
  const TimePoint t0 = SteadyNow();
  TimePoint next_progress = t0;
  for (;;) {
    if (auto r = pending.Poll()) return r;  // throws TimeoutError once the client gave up
    if (Interrupter::Signal()) return std::nullopt;
    if (on_progress && SteadyNow() >= next_progress) {
      on_progress(SteadyNow() - t0);
      next_progress += kProgressEvery;
    }
    Interrupter::WaitFor(kSlice);
  }
}

RunReport RunFrames(RobotClient& client, std::vector<TimedCommand> frames, const SequenceOptions& options,
                    const ReplyCallback& on_reply, const ProgressCallback& on_progress) {
  std::vector<std::size_t> order(frames.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return frames[a].offset < frames[b].offset; });
  const Duration duration = frames.empty() ? Duration(0) : frames[order.back()].offset;
  if (options.mode == CommandMode::kPlayback)
    return RunPlayback(client, std::move(frames), options, on_reply, on_progress, duration);
  if (options.mode == CommandMode::kDirect)
    return RunDirect(client, std::move(frames), order, on_reply, on_progress, duration);

  // Delay mode: every frame stamped server now + delay + offset.
  RunReport report;
  report.replies.resize(frames.size());
  std::vector<std::optional<PendingReply>> pending(frames.size());
  std::vector<TimePoint> starts(frames.size());
  const TimePoint t0 = SteadyNow();
  const TimePoint server_start = client.ServerTime(t0) + options.delay;
  for (std::size_t i = 0; i < frames.size(); ++i) starts[i] = server_start + frames[i].offset;
  const std::size_t batch = std::max<std::size_t>(options.batch, 1);
  std::size_t next_send = 0, next_reply = 0;
  TimePoint next_progress = t0;
  while (next_reply < frames.size()) {
    if (Interrupter::Signal()) break;
    // Send what is due: everything at once, or (paced) each frame at its offset.
    while (next_send < order.size() &&
           (!options.paced || SteadyNow() >= t0 + frames[order[next_send]].offset)) {
      const std::size_t end = options.paced ? next_send + 1 : std::min(order.size(), next_send + batch);
      std::vector<Command> commands;
      for (std::size_t j = next_send; j < end; ++j) {
        commands.push_back(std::move(frames[order[j]].command));
        commands.back().start_time = starts[order[j]];
      }
      auto sent = client.SendBatch(std::move(commands), CommandMode::kDelay);
      for (std::size_t j = next_send; j < end; ++j) pending[order[j]] = std::move(sent[j - next_send]);
      next_send = end;
    }
    while (next_reply < frames.size() && pending[next_reply]) {
      std::optional<Reply> r;
      try {
        r = pending[next_reply]->Poll();
      } catch (const UnknownOutcomeError& e) {  // name each frame, go on
        report.unknown_outcomes.emplace_back(next_reply, e.what());
        ++next_reply;
        continue;
      }
      if (!r) break;
      report.replies[next_reply] = *r;
      if (on_reply) on_reply(next_reply, *r);
      ++next_reply;
    }
    if (next_reply == frames.size()) break;
    if (on_progress && SteadyNow() >= next_progress) {
      std::size_t answered = 0;
      for (const auto& r : report.replies) answered += r.has_value();
      on_progress({answered, frames.size(), client.ServerNow() - server_start, duration});
      next_progress += kProgressEvery;
    }
    Duration wait = kSlice;
    if (options.paced && next_send < order.size())
      wait = std::clamp(t0 + frames[order[next_send]].offset - SteadyNow(), Duration(0), kSlice);
    Interrupter::WaitFor(wait);
  }
  if (!Interrupter::Signal() || next_reply == frames.size()) return report;

  report.signal = Interrupter::Signal();
  std::string note = StopNow(client);
  // Frames already queued on the server would still run: end each as it begins.
  const TimePoint now = client.ServerNow();
  std::vector<TimePoint> queued;
  for (std::size_t i = 0; i < frames.size(); ++i) {
    if (!pending[i] || report.replies[i]) continue;
    if (auto r = pending[i]->Poll()) {
      report.replies[i] = *r;
    } else if (starts[i] > now) {
      queued.push_back(starts[i]);
    }
  }
  const std::size_t shadows = SendShadowStops(client, queued, batch);
  if (shadows > 0)
    note += "; " + std::to_string(shadows) +
            " frames already queued on the server each get a STOP at their start time "
            "(a queued command cannot be cancelled)";
  if (next_send < order.size()) note += "; " + std::to_string(order.size() - next_send) + " frames not sent";
  report.interrupt_note = note;
  return report;
}

}  // namespace robotalk::cli
