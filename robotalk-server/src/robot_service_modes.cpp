// RobotService's playback and broadcast modes (paper §V-C, §V-D): the
// playback queue and its delay estimate, and the self-rescheduling state
// stream. Split from robot_service.cpp; the class is in robot_service.h.
#include "robot_service.h"
#include "robot_service_helpers.h"
#include "robotalk/channels.h"
#include "robotalk/protocol_codec.h"

#include <cmath>
#include <cstdio>

namespace robotalk {

using service_detail::AppendPose;
using service_detail::MakeReply;

void RobotService::EnqueuePlayback(Session& s, const robotalk_msgs::package_t& package, TimePoint now,
                                   std::vector<Reply>& immediate) {
  const auto& h = package.header;
  const Duration duration = std::chrono::microseconds(h.playback_duration_us);
  auto [it, created] = s.playbacks.try_emplace(h.playback_id, static_cast<size_t>(h.playback_frames),
                                               duration, options_.playback);
  PlaybackSequence& seq = it->second;
  const auto refuse_all = [&](const std::string& why) {
    for (const auto& c : package.commands) immediate.push_back(MakeReply(c.id, Signal::kError, why, now));
  };
  if (!created && (seq.total != static_cast<size_t>(h.playback_frames) || seq.duration != duration)) {
    refuse_all("PLAYBACK " + std::to_string(h.playback_id) + ": declared " + std::to_string(seq.total) +
               " frames over " + std::to_string(ToSeconds(seq.duration)) + " s before, now " +
               std::to_string(h.playback_frames) + " over " + std::to_string(ToSeconds(duration)) + " s");
    return;
  }
  if (!seq.first_arrival) seq.first_arrival = now;
  for (const auto& wire : package.commands) {
    std::optional<QueuedItem> item = PrepareCommand(s, wire, now, immediate, /*playback=*/true);
    if (!item) continue;
    const Duration offset = item->start == TimePoint::min() ? Duration(0) : item->start.time_since_epoch();
    if (offset > seq.duration || ++seq.received > seq.total) {
      immediate.push_back(MakeReply(wire.id, Signal::kError,
                                    "PLAYBACK " + std::to_string(h.playback_id) + ": frame at " +
                                        std::to_string(ToSeconds(offset)) + " s is beyond the declared " +
                                        std::to_string(seq.total) + " frames over " +
                                        std::to_string(ToSeconds(seq.duration)) + " s",
                                    now));
      continue;
    }
    item->has_start_time = true;
    if (seq.start) {  // already playing: straight to the command queue
      item->start = *seq.start + offset;
      s.commands.Push(std::move(*item));
    } else {
      seq.estimator.Add(offset, now);
      item->start = TimePoint(offset);
      seq.frames.push_back(std::move(*item));
    }
  }
  if (!seq.start && seq.estimator.ready()) {
    seq.start = seq.estimator.StartTime();
    for (QueuedItem& frame : seq.frames) {
      frame.start = *seq.start + frame.start.time_since_epoch();
      s.commands.Push(std::move(frame));
    }
    seq.frames.clear();
    const Duration delay = *seq.start - *seq.first_arrival;
    Reply r = MakeReply(
        h.playback_id, Signal::kSuccess,
        "playback of " + std::to_string(seq.total) + " frames starts " + std::to_string(ToSeconds(delay)) +
            " s after its first frame arrived (mean " +
            std::to_string(ToSeconds(seq.estimator.mean_command_interval())) + " s between commands, " +
            std::to_string(ToSeconds(seq.estimator.mean_arrival_interval())) + " s between arrivals)",
        now);
    r.values = {ToSeconds(delay), static_cast<double>(ToWireMicros(*seq.start))};
    immediate.push_back(std::move(r));
  }
  wake_flag_ = true;
  wake_.notify_one();
}

void RobotService::UpdateStream(TimePoint now) {
  Duration period{0};
  for (const auto& [client, p] : stream_requests_) period = period.count() == 0 ? p : std::min(period, p);
  if (period == stream_period_) return;
  // A new or faster stream starts sampling now; slower keeps its phase.
  if (stream_period_.count() == 0 || period < stream_period_) next_sample_ = now;
  stream_period_ = period;
  ++stream_generation_;
  wake_flag_ = true;
  wake_.notify_one();
}

Duration RobotService::stream_period() const {
  std::lock_guard lock(mutex_);
  return stream_period_;
}

void RobotService::TakeStates(std::vector<robotalk_msgs::robot_state_t>& out) {
  std::lock_guard lock(mutex_);
  for (auto& m : state_outbox_) out.push_back(std::move(m));
  state_outbox_.clear();
}

void RobotService::SampleState(TimePoint now, Duration period) {
  const RobotModel& m = model();
  driver_->ReadState(state_);
  robotalk_msgs::robot_state_t msg{};
  msg.server_time_us = ToWireMicros(now);
  msg.period_us = ToWireMicros(period);
  msg.sample = ++samples_;
  msg.robot = name_;
  msg.config_hash = static_cast<std::int64_t>(config_hash_);
  msg.panic = panic_.load();
  msg.moving = state_.moving;
  msg.num_dofs = m.num_dofs();
  msg.position.assign(state_.position.data(), state_.position.data() + m.num_dofs());
  msg.velocity.assign(state_.velocity.data(), state_.velocity.data() + m.num_dofs());
  msg.effort.assign(state_.effort.data(), state_.effort.data() + m.num_dofs());
  const Eigen::Isometry3d base = state_.root_poses.front().ToIsometry();
  msg.base[0] = base.translation().x();
  msg.base[1] = base.translation().y();
  msg.base[2] = std::atan2(base.linear()(1, 0), base.linear()(0, 0));
  msg.base[3] = state_.base_v;
  msg.base[4] = state_.base_omega;
  msg.num_frames = static_cast<std::int32_t>(m.frames().size());
  if (msg.num_frames > 0) {
    std::vector<Eigen::Isometry3d> roots;
    for (const Pose& p : state_.root_poses) roots.push_back(p.ToIsometry());
    try {
      kinematics_.Update(state_.position, roots);
      for (int f = 0; f < msg.num_frames; ++f) {
        std::vector<double> pose;
        AppendPose(kinematics_.frame_pose(f), pose);
        msg.frame_poses.push_back(pose);
      }
    } catch (const std::exception&) {
      msg.num_frames = 0;  // a driver reporting a non-finite state: send the rest
      msg.frame_poses.clear();
    }
  }
  sampled_.push_back(std::move(msg));
}

}  // namespace robotalk
