// RobotClient's command modes (paper §V): direct, delay and playback
// sequences, and broadcast state streams.
#include "client_impl.h"
#include "robotalk/error.h"
#include "robotalk/protocol_codec.h"

#include <algorithm>
#include <thread>

namespace robotalk {
namespace {

// When frame i should leave the client: paced frames go at their offset.
void WaitUntil(const Clock& clock, TimePoint t) {
  const Duration left = t - clock.Now();
  if (left > Duration(0)) std::this_thread::sleep_for(left);
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
  for (const TimedCommand& f : frames) {
    if (f.offset < Duration(0)) throw ClientError("RobotClient::RunSequence: a frame has a negative offset");
  }
  SequenceResult result;
  result.replies.resize(frames.size());
  if (frames.empty()) return result;
  // Frames leave in offset order; replies are returned in the order given.
  std::vector<std::size_t> order(frames.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return frames[a].offset < frames[b].offset; });
  const Duration duration = frames[order.back()].offset;
  const Clock& clock = impl_->clock_;
  const TimePoint t0 = clock.Now();
  result.first_sent = t0;

  if (options.mode == CommandMode::kDirect) {
    // The handshake: the next frame cannot leave before the previous reply is
    // in, so a slow channel stretches the sequence (the paper's Fig. 11).
    for (std::size_t i : order) {
      if (options.paced) WaitUntil(clock, t0 + frames[i].offset);
      Command c = std::move(frames[i].command);
      c.start_time.reset();
      result.replies[i] = Execute(std::move(c));
    }
    return result;
  }

  std::optional<PendingReply> delay_reply;
  Impl::Playback playback;
  TimePoint server_start{};
  if (options.mode == CommandMode::kPlayback) {
    playback = {impl_->NewId(), static_cast<std::int32_t>(frames.size()), duration, /*ask_for_delay=*/true};
    impl_->cache_->Expect(playback.id);
    delay_reply = impl_->MakePending(playback.id, "PLAYBACK " + std::to_string(playback.id));
  } else {
    server_start = ServerTime(t0) + options.delay;
    result.server_start = server_start;
  }

  std::vector<std::optional<PendingReply>> pending(frames.size());
  const std::size_t batch = options.paced ? 1 : std::max<std::size_t>(options.batch, 1);
  for (std::size_t k = 0; k < order.size(); k += batch) {
    const std::size_t end = std::min(order.size(), k + batch);
    if (options.paced) WaitUntil(clock, t0 + frames[order[k]].offset);
    std::vector<Command> commands;
    for (std::size_t j = k; j < end; ++j) {
      Command c = std::move(frames[order[j]].command);
      // Playback carries the offset itself; delay mode an absolute server time.
      c.start_time = options.mode == CommandMode::kPlayback
                         ? StartTime::After(frames[order[j]].offset)
                         : StartTime::At(server_start + frames[order[j]].offset);
      commands.push_back(std::move(c));
    }
    auto sent = impl_->SendPackage(std::move(commands), {}, false, Impl::Track::kRetransmit, false, playback);
    playback.ask_for_delay = false;  // only the first package asks
    for (std::size_t j = k; j < end; ++j) {
      pending[order[j]] = impl_->MakePending(sent.ids[j - k], "sequence frame " + std::to_string(order[j]));
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

// On the ReadDaemon: a bad sample is counted, a callback's exception stored.
void RobotClient::Impl::OnState(std::span<const std::uint8_t> bytes) {
  std::function<void(const StateSample&)> callback;
  int dofs = -1;
  {
    std::lock_guard lock(mu_);
    callback = on_state_;
    if (model_) dofs = model_->num_dofs();
  }
  if (!callback) return;
  StateSample state;
  try {
    state = DecodeStateSample(bytes, dofs);
  } catch (const ProtocolError&) {
    std::lock_guard lock(mu_);
    ++stats_.malformed_packages;
    return;
  }
  try {
    callback(state);
  } catch (...) {
    std::lock_guard lock(mu_);
    if (!daemon_error_) daemon_error_ = std::current_exception();
  }
}

}  // namespace robotalk
