// RobotClient's trajectory calls (docs/client.md, "Trajectories"): a joint's
// or a control frame's waypoints, sent as a sequence of interpolated
// set-points (trajectory_frames.h) in delay or playback mode.
#include "client_impl.h"
#include "sequence_plan.h"
#include "trajectory_frames.h"

#include <type_traits>

namespace robotalk {
namespace {

template <typename T>
std::vector<TimedCommand> Frames(const RobotClient& client, const T& trajectory, const char* call) {
  if (!client.connected())
    throw ClientError(std::string("RobotClient::") + call + ": not connected (call Connect first)");
  if constexpr (std::is_same_v<T, FrameTrajectory>) {
    return client::TrajectoryFrames(client.model(), CommandType::kFrameSetPoint, trajectory.frame,
                                    trajectory.points, call);
  } else {
    return client::TrajectoryFrames(client.model(), CommandType::kJointSetPoint, trajectory.joint,
                                    trajectory.points, call);
  }
}

}  // namespace

std::vector<PendingReply> RobotClient::SendTrajectory(const JointTrajectory& trajectory,
                                                      const TrajectoryOptions& options) {
  return SendFrames(Frames(*this, trajectory, "SendTrajectory"), options);
}

std::vector<PendingReply> RobotClient::SendTrajectory(const FrameTrajectory& trajectory,
                                                      const TrajectoryOptions& options) {
  return SendFrames(Frames(*this, trajectory, "SendTrajectory"), options);
}

SequenceResult RobotClient::RunTrajectory(const JointTrajectory& trajectory, const TrajectoryOptions& options,
                                          const SequenceHooks& hooks) {
  auto frames = Frames(*this, trajectory, "RunTrajectory");
  const SequenceOptions sequence = client::TrajectorySequence(options, frames, "RunTrajectory");
  return RunSequence(std::move(frames), sequence, hooks);
}

SequenceResult RobotClient::RunTrajectory(const FrameTrajectory& trajectory, const TrajectoryOptions& options,
                                          const SequenceHooks& hooks) {
  auto frames = Frames(*this, trajectory, "RunTrajectory");
  const SequenceOptions sequence = client::TrajectorySequence(options, frames, "RunTrajectory");
  return RunSequence(std::move(frames), sequence, hooks);
}

std::vector<PendingReply> RobotClient::SendFrames(std::vector<TimedCommand> frames,
                                                  const TrajectoryOptions& options) {
  const SequenceOptions sequence_options = client::TrajectorySequence(options, frames, "SendTrajectory");
  const client::SequencePlan plan = client::PlanSequence(frames, sequence_options);
  // Nobody waits for a playback sequence's delay reply here: dropping its
  // handle lets the client file it as unwanted when it comes.
  std::optional<PendingReply> delay_reply;
  SequenceSend sequence =
      impl_->BeginSequence(sequence_options, frames.size(), plan.duration, impl_->clock_.Now(), &delay_reply);
  std::vector<std::optional<PendingReply>> by_frame(frames.size());
  for (const client::PlannedSend& send : plan.sends) {
    std::vector<PendingReply> sent = impl_->SendPlanned(frames, send, sequence);
    for (std::size_t j = 0; j < send.frames.size(); ++j) by_frame[send.frames[j]] = std::move(sent[j]);
  }
  std::vector<PendingReply> pending;
  pending.reserve(frames.size());
  for (auto& p : by_frame) pending.push_back(std::move(*p));
  return pending;
}

}  // namespace robotalk
