// RobotClient's command modes (paper §V): direct, delay and playback
// sequences, and broadcast state streams.
#include "client_impl.h"
#include "robotalk/error.h"
#include "sequence_plan.h"

#include <algorithm>
#include <condition_variable>
#include <mutex>
#include <stop_token>

namespace robotalk {
namespace {

using std::chrono::milliseconds;

// How long to block now, for a deadline on the client's clock: a clock other
// than the steady one (a ManualClock moves when a test says so) is re-read
// at least every 10 ms of real time.
Duration RealWait(const Clock& clock, bool steady, TimePoint t) {
  const Duration left = std::max(Duration(0), t - clock.Now());
  return steady ? left : std::min<Duration>(left, milliseconds(10));
}

// Sleeps until the client's clock reaches `t`; false when `stop` came first.
bool SleepUntil(const Clock& clock, bool steady, TimePoint t, const std::stop_token& stop) {
  std::mutex mu;
  std::condition_variable_any cv;
  std::unique_lock lock(mu);
  while (clock.Now() < t) {
    cv.wait_for(lock, stop, RealWait(clock, steady, t), [] { return false; });
    if (stop.stop_requested()) return false;
  }
  return !stop.stop_requested();
}

}  // namespace

const char* ToString(CommandMode mode) {
  switch (mode) {
    case CommandMode::kDirect:
      return "direct";
    case CommandMode::kDelay:
      return "delay";
    case CommandMode::kPlayback:
      return "playback";
  }
  return "unknown";
}

std::optional<CommandMode> ParseCommandMode(const std::string& name) {
  for (CommandMode m : {CommandMode::kDirect, CommandMode::kDelay, CommandMode::kPlayback}) {
    if (name == ToString(m)) return m;
  }
  return std::nullopt;
}

void RobotClient::Impl::SetStartTimes(const std::vector<std::pair<CommandId, TimePoint>>& server_starts) {
  std::lock_guard lock(mu_);
  const TimePoint now = clock_.Now();
  for (const auto& [id, start] : server_starts)
    outstanding_.UpdateStart(id, clock_sync_.ClientTime(start), now);
}

CommandId RobotClient::Impl::NewId() {
  std::lock_guard lock(mu_);
  return next_id_++;
}

SequenceSend RobotClient::Impl::BeginSequence(const SequenceOptions& options, std::size_t frames,
                                              Duration duration, TimePoint t0,
                                              std::optional<PendingReply>* delay_reply) {
  SequenceSend sequence;
  sequence.mode = options.mode;
  sequence.t0 = t0;
  sequence.package.mode = RequestMode::kDirect;
  sequence.package.max_late = options.max_late;
  if (options.mode == CommandMode::kPlayback) {
    sequence.package.mode = RequestMode::kPlayback;
    sequence.package.playback = {NewId(), static_cast<std::int64_t>(frames), duration};
    sequence.package.ask_for_delay = true;
    cache_->Expect(sequence.package.playback.id);
    *delay_reply =
        MakePending(sequence.package.playback.id, "PLAYBACK " + std::to_string(sequence.package.playback.id));
  } else if (options.mode == CommandMode::kDelay) {
    sequence.package.mode = RequestMode::kDelay;
    TimePoint server_t0;
    {
      std::lock_guard lock(mu_);
      server_t0 = clock_sync_.ServerTime(t0);
    }
    sequence.server_start = options.start.value_or(server_t0 + options.delay);
    sequence.start_known = true;
  }
  return sequence;
}

std::vector<PendingReply> RobotClient::Impl::SendPlanned(std::vector<TimedCommand>& frames,
                                                         const client::PlannedSend& send,
                                                         SequenceSend& sequence) {
  std::vector<Command> commands;
  std::optional<Duration> earliest;
  for (std::size_t i : send.frames) {
    earliest = std::min(earliest.value_or(frames[i].offset), frames[i].offset);
    Command c = std::move(frames[i].command);
    c.start_time = client::FrameStart(sequence.mode, frames[i].offset, sequence.server_start);
    commands.push_back(std::move(c));
  }
  sequence.package.interpolation = send.interpolation;
  if (sequence.mode == CommandMode::kPlayback && earliest) {
    // Its earliest frame is due this long after the package arrives: its
    // offset ahead of the sequence's clock on top of the server's buffer
    // (before the delay reply, at least the offset ahead).
    const Duration ahead = std::max(Duration(0), *earliest - (clock_.Now() - sequence.t0));
    sequence.package.playback_headroom = sequence.chosen_delay.value_or(Duration(0)) + ahead;
  }
  const Sent sent = SendPackage(std::move(commands), {}, sequence.package);
  sequence.package.ask_for_delay = false;  // only the first package asks
  std::vector<PendingReply> pending;
  for (std::size_t j = 0; j < send.frames.size(); ++j)
    pending.push_back(MakePending(sent.ids[j], "sequence frame " + std::to_string(send.frames[j])));
  return pending;
}

SequenceResult RobotClient::RunSequence(std::vector<TimedCommand> frames, const SequenceOptions& options,
                                        const SequenceHooks& hooks) {
  if (!connected()) throw ClientError("RobotClient::RunSequence: not connected (call Connect first)");
  const client::SequencePlan plan = client::PlanSequence(frames, options);
  SequenceResult result;
  result.replies.resize(frames.size());
  if (frames.empty()) return result;
  const Clock& clock = impl_->clock_;
  const bool steady = &clock == &impl_->steady_clock_;
  const std::stop_token& stop = hooks.stop;
  const TimePoint t0 = clock.Now();
  result.first_sent = t0;
  client::SequencePacer pacer(plan, t0);

  std::optional<PendingReply> delay_reply;
  SequenceSend sequence = impl_->BeginSequence(options, frames.size(), plan.duration, t0, &delay_reply);
  // Known from the start in delay mode, after the delay reply in playback.
  TimePoint& server_start = sequence.server_start;
  bool& start_known = sequence.start_known;
  if (options.mode == CommandMode::kDelay) result.server_start = server_start;

  std::vector<std::optional<PendingReply>> pending(frames.size());
  std::size_t answered = 0;
  std::chrono::steady_clock::time_point next_progress = std::chrono::steady_clock::now();
  // Without on_progress, next_progress still moves on (an hour at a time):
  // the waits below wake at it, and one left in the past made them spin.
  const auto progress = [&] {
    const auto now = std::chrono::steady_clock::now();
    if (now < next_progress) return;
    if (hooks.on_progress) {
      hooks.on_progress({answered, frames.size(), start_known ? ServerNow() - server_start : clock.Now() - t0,
                         plan.duration});
    }
    const Duration every = hooks.on_progress
                               ? std::max<Duration>(hooks.progress_every, std::chrono::milliseconds(1))
                               : Duration(std::chrono::hours(1));
    next_progress = now + std::chrono::duration_cast<std::chrono::steady_clock::duration>(every);
  };
  // Sends the next package of the plan (due now).
  const auto send_next = [&] {
    const client::PlannedSend& send = *pacer.NextDue(clock.Now());
    std::vector<PendingReply> sent = impl_->SendPlanned(frames, send, sequence);
    for (std::size_t j = 0; j < send.frames.size(); ++j) pending[send.frames[j]] = std::move(sent[j]);
    result.frames_sent += send.frames.size();
  };
  // Waits for frame i's reply until `until` on the client's clock (nullopt:
  // until its own deadline), waking for the reply, a stop, and progress.
  // Returns whether frame i is settled (answered, or of unknown outcome).
  std::optional<std::chrono::steady_clock::time_point> deadline;  // of the frame waited for
  Duration allowed{0};                                            // what `deadline` allows
  const auto wait_frame = [&](std::size_t i, std::optional<TimePoint> until) {
    // Playback: no frame's start is known before the delay reply.
    if (!deadline && !hooks.wait_until_given_up && !delay_reply) {
      // Each reply can come no earlier than its start time.
      Duration until_start{0};
      if (start_known) until_start = std::max(Duration(0), server_start + frames[i].offset - ServerNow());
      allowed = until_start + impl_->options_.timeout;
      deadline = std::chrono::steady_clock::now() +
                 std::chrono::duration_cast<std::chrono::steady_clock::duration>(allowed);
    }
    for (;;) {
      progress();
      auto wake = std::min(next_progress, deadline.value_or(std::chrono::steady_clock::time_point::max()));
      if (until) wake = std::min(wake, std::chrono::steady_clock::now() + RealWait(clock, steady, *until));
      std::optional<Reply> r;
      try {
        r = pending[i]->WaitFor(std::max(Duration(0), wake - std::chrono::steady_clock::now()), stop);
      } catch (const UnknownOutcomeError& e) {
        if (!hooks.collect_unknown_outcomes) throw;
        result.unknown_outcomes.emplace_back(i, e.what());
        deadline.reset();
        return true;
      }
      if (r) {
        result.replies[i] = *r;
        ++answered;
        deadline.reset();
        if (hooks.on_reply) hooks.on_reply(i, result.replies[i]);
        return true;
      }
      if (stop.stop_requested() || (until && clock.Now() >= *until)) return false;
      if (deadline && std::chrono::steady_clock::now() >= *deadline) {
        impl_->RethrowDaemonError();
        throw TimeoutError("sequence frame " + std::to_string(i) + " (id " +
                           std::to_string(pending[i]->id()) + "): no reply within " +
                           std::to_string(ToSeconds(allowed)) + " s");
      }
    }
  };

  std::size_t next_reply = 0;  // frames are reported in the order given (direct: in plan order)
  std::vector<std::size_t> report_order(frames.size());
  if (options.mode == CommandMode::kDirect) {
    report_order.clear();
    for (const auto& send : plan.sends)
      report_order.insert(report_order.end(), send.frames.begin(), send.frames.end());
  } else {
    for (std::size_t i = 0; i < frames.size(); ++i) report_order[i] = i;
  }
  while (next_reply < frames.size() && !stop.stop_requested()) {
    const std::optional<TimePoint> due = pacer.NextDeadline();
    const std::size_t i = report_order[next_reply];
    if (options.mode == CommandMode::kDirect) {
      // The handshake: a frame leaves at its time, never before the previous
      // reply, so a slow channel stretches the sequence (the paper's Fig. 11).
      if (!SleepUntil(clock, steady, *due, stop)) break;
      send_next();
      if (!wait_frame(i, std::nullopt)) break;
      ++next_reply;
      continue;
    }
    if (due && clock.Now() >= *due) {
      send_next();
      continue;
    }
    if (!due && delay_reply && !start_known) {
      // Playback: the server answers once it has seen enough frames to estimate.
      const Duration most = plan.duration + impl_->options_.timeout;
      const auto give_up = std::chrono::steady_clock::now() +
                           std::chrono::duration_cast<std::chrono::steady_clock::duration>(most);
      std::optional<Reply> r;
      while (!r && !stop.stop_requested()) {
        progress();
        const auto now = std::chrono::steady_clock::now();
        if (!hooks.wait_until_given_up && now >= give_up) {
          throw TimeoutError("PLAYBACK " + std::to_string(delay_reply->id()) + ": no delay reply within " +
                             std::to_string(ToSeconds(most)) + " s");
        }
        r = delay_reply->WaitFor(
            std::min(next_progress, hooks.wait_until_given_up ? next_progress : give_up) - now, stop);
      }
      if (!r) break;
      start_known = true;
      if (r->values.size() >= 2) {
        result.playback_delay = FromSeconds(r->values[0]);
        sequence.chosen_delay = result.playback_delay;
        result.server_start = FromWireMicros(static_cast<std::int64_t>(r->values[1]));
        server_start = *result.server_start;
        std::vector<std::pair<CommandId, TimePoint>> starts;
        for (std::size_t k = 0; k < frames.size(); ++k) {
          if (pending[k]) starts.emplace_back(pending[k]->id(), server_start + frames[k].offset);
        }
        impl_->SetStartTimes(starts);
      } else {
        start_known = false;
      }
      delay_reply.reset();
      continue;
    }
    if (!pending[i]) {  // not sent yet (paced, a later offset than frames sent after it)
      if (!SleepUntil(clock, steady, *due, stop)) break;
      continue;
    }
    if (wait_frame(i, due)) ++next_reply;
  }
  if (!stop.stop_requested() || next_reply == frames.size()) return result;

  result.stopped = true;
  if (options.mode != CommandMode::kDelay) return result;
  // Frames already queued on the server would still run: say which.
  const TimePoint now = ServerNow();
  for (std::size_t i = 0; i < frames.size(); ++i) {
    if (!pending[i] || result.replies[i].id != 0) continue;
    try {
      if (auto r = pending[i]->Poll()) {
        result.replies[i] = *r;
        continue;
      }
    } catch (const Error&) {
      continue;  // given up on: nothing to stop
    }
    if (server_start + frames[i].offset > now) result.queued.push_back(server_start + frames[i].offset);
  }
  return result;
}

Duration RobotClient::StartStateStream(Duration period, std::function<void(const StateSample&)> on_sample) {
  if (!connected()) throw ClientError("RobotClient::StartStateStream: not connected (call Connect first)");
  impl_->SubscribeState(std::move(on_sample));
  const Reply r = Query(robotalk::Query{.type = QueryType::kStateStream, .period = period});
  if (r.signal != Signal::kSuccess) {
    throw ClientError("RobotClient::StartStateStream: " + client::Answered(r));
  }
  return r.values.empty() ? period : FromSeconds(r.values[0]);
}

void RobotClient::StopStateStream() {
  if (!connected()) return;
  Query(robotalk::Query{.type = QueryType::kStateStreamCancel});
  std::lock_guard lock(impl_->mu_);
  impl_->on_state_ = nullptr;
}

void RobotClient::Impl::SubscribeState(std::function<void(const StateSample&)> on_sample) {
  std::lock_guard lock(mu_);
  on_state_ = std::move(on_sample);
  if (state_subscription_) return;
  try {
    state_subscription_ = transport_->Subscribe(
        StateChannel(robot_), [this](const std::string&, std::span<const std::uint8_t> b) { OnState(b); });
  } catch (const TransportError& e) {
    throw ClientError("RobotClient: cannot subscribe to " + StateChannel(robot_) + ": " + e.what());
  }
}

}  // namespace robotalk
