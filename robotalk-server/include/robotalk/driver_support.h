// Small helpers for driver writers, so every driver answers in the same words
// (docs/drivers.md): results, numbers and names in messages, and the checks
// and answers of a FRAME_SETPOINT solved with InverseKinematics.
#pragma once

#include "robotalk/driver.h"
#include "robotalk/inverse_kinematics.h"

#include <optional>
#include <string>

namespace robotalk::driver_support {

/// A final (not in-progress) result.
DriverResult Answer(Signal signal, std::string message = {});
/// A number in a message: short and exact enough to read ("0.5411").
std::string Num(double v);
/// "rad" or "m".
const char* Unit(DofType t);
/// 'name'
std::string Quote(const std::string& name);

/// Before solving a FRAME_SETPOINT: NA when no set-point joint moves the
/// frame, ERROR for a zero or non-finite orientation; nullopt to go on.
std::optional<DriverResult> CheckFrameSetPoint(const RobotModel& model, const InverseKinematics& ik,
                                               const DriverCommand& command);
/// The goal of a FRAME_SETPOINT: x y z and the orientation qw qx qy qz.
Eigen::Vector3d FrameGoalPosition(const DriverCommand& command);
Eigen::Quaterniond FrameGoalOrientation(const DriverCommand& command);
/// After solving: SUCCESS within the solver's tolerance, else MODIFIED with the residual.
DriverResult AnswerFrameSetPoint(const std::string& frame, const InverseKinematics::Result& result);

}  // namespace robotalk::driver_support
