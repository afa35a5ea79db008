// Issue 22 item 7: a trajectory's points become sequence frames, and a bad
// argument is refused naming the point and the value (trajectory_frames.h),
// against the Pioneer's model (pan, tilt: 1 dof each; the camera frame).
#include "trajectory_frames.h"

#include "robotalk/urdf_import.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>

namespace robotalk::client {
namespace {

using std::chrono::milliseconds;

const RobotModel& Pioneer() {
  static const RobotModel model =
      LoadUrdfFile(std::string(ROBOTALK_MODELS_DIR) + "/pioneer2dx_pantilt.urdf").model;
  return model;
}

std::string ErrorOf(CommandType type, const std::string& target, const std::vector<TrajectoryPoint>& points) {
  try {
    TrajectoryFrames(Pioneer(), type, target, points, "SendTrajectory");
  } catch (const ClientError& e) {
    return e.what();
  }
  return "no ClientError";
}

TEST(TrajectoryFrames, EachPointIsASetPointFrameAtItsTimeWithItsVelocitiesAndAccelerations) {
  const auto frames = TrajectoryFrames(Pioneer(), CommandType::kJointSetPoint, "pan",
                                       {{milliseconds(100), {0.1}, {}, {}},
                                        {milliseconds(300), {0.3}, {0.5}, {}},
                                        {milliseconds(600), {0.0}, {0.0}, {0.0}}},
                                       "SendTrajectory");
  ASSERT_EQ(frames.size(), 3u);
  EXPECT_EQ(frames[1].offset, milliseconds(300));
  EXPECT_EQ(frames[1].command.type, CommandType::kJointSetPoint);
  EXPECT_EQ(frames[1].command.target, "pan");
  EXPECT_EQ(frames[1].command.values, std::vector<double>{0.3});
  EXPECT_EQ(frames[1].command.velocities, std::vector<double>{0.5});
  EXPECT_TRUE(frames[1].command.accelerations.empty());
  EXPECT_EQ(frames[2].command.accelerations, std::vector<double>{0.0});
  EXPECT_FALSE(frames[0].interpolation);  // the trajectory's, from its options

  const auto frame = TrajectoryFrames(
      Pioneer(), CommandType::kFrameSetPoint, "camera",
      {{milliseconds(0), {0.1, 0, 0.4, 1, 0, 0, 0}, {0, 0, 0, 0, 0, 0.2}, {}}}, "SendTrajectory");
  EXPECT_EQ(frame[0].command.type, CommandType::kFrameSetPoint);
  EXPECT_EQ(frame[0].command.velocities.size(), 6u);
}

TEST(TrajectoryFrames, RefusesBadPointsNamingThePointAndTheValue) {
  const auto joint = CommandType::kJointSetPoint;
  EXPECT_EQ(ErrorOf(joint, "pan", {}), "RobotClient::SendTrajectory: joint 'pan': no points");
  EXPECT_EQ(ErrorOf(joint, "pan", {{milliseconds(-5), {0.1}, {}, {}}}),
            "RobotClient::SendTrajectory: joint 'pan': point 0: time_from_start -0.005 s is negative");
  EXPECT_EQ(ErrorOf(joint, "pan", {{milliseconds(300), {0.1}, {}, {}}, {milliseconds(200), {0.2}, {}, {}}}),
            "RobotClient::SendTrajectory: joint 'pan': point 1: time_from_start 0.2 s is not after point 0's "
            "(0.3 s): times must increase");
  EXPECT_EQ(ErrorOf(joint, "pan", {{milliseconds(100), {0.1}, {}, {}}, {milliseconds(100), {0.2}, {}, {}}}),
            "RobotClient::SendTrajectory: joint 'pan': point 1: time_from_start 0.1 s is not after point 0's "
            "(0.1 s): times must increase");
  EXPECT_EQ(
      ErrorOf(joint, "pan", {{milliseconds(100), {0.1, 0.2}, {}, {}}}),
      "RobotClient::SendTrajectory: joint 'pan': point 0: JOINT_SETPOINT 'pan': expected 1 value (one per "
      "dof), got 2");
  EXPECT_EQ(ErrorOf(joint, "pan", {{milliseconds(100), {0.1}, {}, {}}, {milliseconds(200), {NAN}, {}, {}}}),
            "RobotClient::SendTrajectory: joint 'pan': point 1: JOINT_SETPOINT 'pan': value 0 is NaN");
  EXPECT_EQ(ErrorOf(joint, "pan", {{milliseconds(100), {0.1}, {0.1, 0.2}, {}}}),
            "RobotClient::SendTrajectory: joint 'pan': point 0: JOINT_SETPOINT 'pan': expected 0 or 1 "
            "velocities, got 2");
  EXPECT_EQ(ErrorOf(joint, "pan", {{milliseconds(100), {0.1}, {}, {INFINITY}}}),
            "RobotClient::SendTrajectory: joint 'pan': point 0: JOINT_SETPOINT 'pan': acceleration 0 is "
            "infinite");
  EXPECT_THAT(
      ErrorOf(joint, "nek", {{milliseconds(100), {0.1}, {}, {}}}),
      ::testing::HasSubstr("point 0: JOINT_SETPOINT: robot 'pioneer2dx_pantilt' has no joint named 'nek'"));
  // A wheel takes speeds only: the server would answer NA; said at once.
  EXPECT_THAT(ErrorOf(joint, "left_wheel_joint", {{milliseconds(100), {0.1}, {}, {}}}),
              ::testing::EndsWith("(NA)"));
  EXPECT_EQ(ErrorOf(CommandType::kFrameSetPoint, "camera",
                    {{milliseconds(0), {0.1, 0, 0.4, 1, 0, 0, 0}, {1, 2, 3}, {}}}),
            "RobotClient::SendTrajectory: frame 'camera': point 0: FRAME_SETPOINT 'camera': expected 0 or 6 "
            "velocities, got 3");
}

TEST(TrajectorySequence, SendsAtOnceInTheTrajectorysModeStartAndInterpolationAndRefusesDirect) {
  const auto frames = TrajectoryFrames(Pioneer(), CommandType::kJointSetPoint, "pan",
                                       {{milliseconds(100), {0.1}, {}, {}}}, "RunTrajectory");
  const TimePoint start(std::chrono::seconds(7));
  const SequenceOptions s = TrajectorySequence(
      {.mode = CommandMode::kPlayback, .interpolation = Interpolation::kQuintic, .start = start}, frames,
      "RunTrajectory");
  EXPECT_EQ(s.mode, CommandMode::kPlayback);
  EXPECT_EQ(s.interpolation, Interpolation::kQuintic);
  EXPECT_EQ(s.start, start);
  EXPECT_FALSE(s.paced);
  EXPECT_EQ(s.batch, 200u);  // small frames: the usual batch
  EXPECT_EQ(TrajectoryOptions{}.interpolation, Interpolation::kCubic);
  try {
    TrajectorySequence({.mode = CommandMode::kDirect}, frames, "RunTrajectory");
    ADD_FAILURE() << "direct mode accepted";
  } catch (const ClientError& e) {
    EXPECT_THAT(e.what(), ::testing::HasSubstr(
                              "RobotClient::RunTrajectory: a trajectory needs mode delay or playback"));
  }
  // 31 dofs with velocities and accelerations: a package of them stays under 48 KB.
  std::vector<TimedCommand> big(1);
  big[0].command = {
      .type = CommandType::kJointSetPoint, .target = "j", .values = std::vector<double>(31, 0.0)};
  big[0].command.velocities = big[0].command.accelerations = std::vector<double>(31, 0.0);
  const std::size_t batch = TrajectorySequence({}, big, "SendTrajectory").batch;
  EXPECT_LT(batch * (31 * 3 * 8), 48u * 1024);
  EXPECT_GT(batch, 50u);
}

}  // namespace
}  // namespace robotalk::client
