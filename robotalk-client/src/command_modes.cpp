// RobotClient's command modes (paper §V): direct, delay and playback
// sequences, and broadcast state streams.
#include "client_impl.h"
#include "robotalk/error.h"
#include "sequence_plan.h"

#include <algorithm>
#include <thread>

namespace robotalk {
namespace {

// Waits until the client's clock reaches `t`, re-reading it at least every
// 10 ms of real time (a ManualClock moves when a test says so).
void WaitUntil(const Clock& clock, TimePoint t) {
  for (Duration left = t - clock.Now(); left > Duration(0); left = t - clock.Now()) {
    std::this_thread::sleep_for(std::min<Duration>(left, std::chrono::milliseconds(10)));
  }
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

SequenceResult RobotClient::RunSequence(std::vector<TimedCommand> frames, const SequenceOptions& options) {
  if (!connected()) throw ClientError("RobotClient::RunSequence: not connected (call Connect first)");
  const client::SequencePlan plan = client::PlanSequence(frames, options);
  SequenceResult result;
  result.replies.resize(frames.size());
  if (frames.empty()) return result;
  const Duration duration = plan.duration;
  const Clock& clock = impl_->clock_;
  const TimePoint t0 = clock.Now();
  result.first_sent = t0;
  client::SequencePacer pacer(plan, t0);

  if (options.mode == CommandMode::kDirect) {
    // The handshake: the next frame cannot leave before the previous reply is
    // in, so a slow channel stretches the sequence (the paper's Fig. 11).
    while (auto due = pacer.NextDeadline()) {
      WaitUntil(clock, *due);
      for (std::size_t i : pacer.NextDue(clock.Now())->frames) {
        Command c = std::move(frames[i].command);
        c.start_time = client::FrameStart(CommandMode::kDirect, frames[i].offset, {});
        result.replies[i] = Execute(std::move(c));
      }
    }
    return result;
  }

  std::optional<PendingReply> delay_reply;
  PackageOptions package{.mode = RequestMode::kDelay};
  TimePoint server_start{};
  if (options.mode == CommandMode::kPlayback) {
    package = {.mode = RequestMode::kPlayback,
               .playback = {impl_->NewId(), static_cast<std::int64_t>(frames.size()), duration},
               .ask_for_delay = true};
    impl_->cache_->Expect(package.playback.id);
    delay_reply = impl_->MakePending(package.playback.id, "PLAYBACK " + std::to_string(package.playback.id));
  } else {
    server_start = ServerTime(t0) + options.delay;
    result.server_start = server_start;
  }

  std::vector<std::optional<PendingReply>> pending(frames.size());
  while (auto due = pacer.NextDeadline()) {
    WaitUntil(clock, *due);
    const client::PlannedSend& send = *pacer.NextDue(clock.Now());
    std::vector<Command> commands;
    for (std::size_t i : send.frames) {
      Command c = std::move(frames[i].command);
      c.start_time = client::FrameStart(options.mode, frames[i].offset, server_start);
      commands.push_back(std::move(c));
    }
    auto sent = impl_->SendPackage(std::move(commands), {}, package);
    package.ask_for_delay = false;  // only the first package asks
    for (std::size_t j = 0; j < send.frames.size(); ++j) {
      pending[send.frames[j]] =
          impl_->MakePending(sent.ids[j], "sequence frame " + std::to_string(send.frames[j]));
    }
  }

  if (delay_reply) {
    // The server answers once it has seen enough frames to estimate.
    const Reply r = delay_reply->Wait(duration + impl_->options_.timeout);
    if (r.values.size() >= 2) {
      result.playback_delay = FromSeconds(r.values[0]);
      result.server_start = FromWireMicros(static_cast<std::int64_t>(r.values[1]));
      server_start = *result.server_start;
      std::vector<std::pair<CommandId, TimePoint>> starts;
      for (std::size_t i = 0; i < frames.size(); ++i) {
        if (pending[i]) starts.emplace_back(pending[i]->id(), server_start + frames[i].offset);
      }
      impl_->SetStartTimes(starts);
    }
  }
  for (std::size_t i = 0; i < frames.size(); ++i) {
    // Each reply can come no earlier than its start time.
    const Duration until_start = std::max(Duration(0), server_start + frames[i].offset - ServerNow());
    result.replies[i] = pending[i]->Wait(until_start + impl_->options_.timeout);
  }
  return result;
}

Duration RobotClient::StartStateStream(Duration period, std::function<void(const StateSample&)> on_sample) {
  if (!connected()) throw ClientError("RobotClient::StartStateStream: not connected (call Connect first)");
  impl_->SubscribeState(std::move(on_sample));
  const Reply r = Query(robotalk::Query{.type = QueryType::kStateStream, .period = period});
  if (r.signal != Signal::kSuccess) {
    throw ClientError("RobotClient::StartStateStream: " + std::string(robotalk::ToString(r.signal)) + ": " +
                      r.message);
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
