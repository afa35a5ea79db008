// The pure part of RobotClient::SendTrajectory / RunTrajectory: a joint's or
// a control frame's waypoints, checked against the robot's model, become the
// frames of a sequence (JOINT_SETPOINT / FRAME_SETPOINT commands with their
// velocities and accelerations), sent as RunSequence sends a sequence, never
// paced, in packages that stay under LCM's ~60 KB. No I/O.
//
// Thread safety: pure functions.
#pragma once

#include "robotalk/robot_client.h"

#include <string>
#include <vector>

namespace robotalk::client {

/// `points` of `target` as sequence frames (offset = time_from_start) of
/// `type` (kJointSetPoint or kFrameSetPoint). Throws ClientError
/// "RobotClient::<call>: joint 'pan': point 2: <what>" for no points, a
/// negative, non-finite or not increasing time, and whatever CheckCommand
/// refuses (unknown target, wrong number of positions, velocities or
/// accelerations, NaN, a servo type the target does not take).
std::vector<TimedCommand> TrajectoryFrames(const RobotModel& model, CommandType type,
                                           const std::string& target,
                                           const std::vector<TrajectoryPoint>& points, const char* call);

/// The sequence options a trajectory travels with: its mode, start and
/// interpolation, not paced, `batch` frames per package so that a package
/// of the largest frame stays under ~48 KB. Throws ClientError for kDirect.
SequenceOptions TrajectorySequence(const TrajectoryOptions& options, const std::vector<TimedCommand>& frames,
                                   const char* call);

}  // namespace robotalk::client
