// The RobotDaemon's base speed ramp (issue 22 item 2; speed_ramp.h): the
// SETSPEED frames of interpolated packages join the ramp when they arrive,
// and the ramp ends (TrackBaseRamp, which calls the driver, is
// robot_daemon.cpp's, beside its fault guard).
#include "robot_daemon.h"

namespace robotalk {

void RobotDaemon::AddSpeedFrames(TimePoint now) {
  if (speed_frames_.empty()) return;
  const BaseReference measured{.vx = state_.base_v, .vy = state_.base_vy, .omega = state_.base_omega};
  std::int64_t owner = 0;
  if (!GuardedPlanner("speed ramp", now, speed_frames_,
                      [&] { owner = ramp_.Add(speed_frames_, now, measured, ramped_); })) {
    speed_frames_.clear();
    return;
  }
  if (owner != 0) produced_.executed.push_back({owner, CommandType::kSetSpeed, -1});
  for (SpeedRamp::Answer& a : ramped_) Emit(a.client_id, std::move(a.reply));
  ramped_.clear();
  speed_frames_.clear();
}

void RobotDaemon::EndRamp(TimePoint now, const std::string& why) {
  if (!ramp_.active()) return;
  ramp_.End(now, why, ramped_);
  for (SpeedRamp::Answer& a : ramped_) Emit(a.client_id, std::move(a.reply));
  ramped_.clear();
}

}  // namespace robotalk
