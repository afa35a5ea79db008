// Issue 22 item 7: what RobotClient's trajectory calls put on the wire, read
// back with the server's decoder (wire_fixture.h): the interpolation on every
// package of the trajectory, each point's velocities and accelerations, the
// start times of delay and playback mode; and that each point is answered.
// The server on this branch does not interpolate yet: only replies and wire
// content are asserted, never the motion.
#include "client/wire_fixture.h"

#include <gmock/gmock.h>

namespace robotalk {
namespace {

using namespace robotalk::testing;  // NOLINT: the fixture and its helpers
using ::testing::HasSubstr;

using TrajectoryWireTest = RobotClientWireTest;

// The command packages of `sent`, each checked to decode cleanly.
std::vector<Request> CommandPackages(const std::vector<Request>& sent) {
  std::vector<Request> out;
  for (const Request& r : sent) {
    EXPECT_EQ(r.header_error, "") << "package " << r.sequence;
    if (!r.commands.empty()) out.push_back(r);
  }
  return out;
}

JointTrajectory PanTrajectory(int points) {
  JointTrajectory t{.joint = "pan"};
  for (int i = 1; i <= points; ++i) {
    TrajectoryPoint p{.time_from_start = milliseconds(40 * i), .positions = {0.01 * i}};
    if (i % 2 == 0) p.velocities = {0.2};
    if (i == points) p.accelerations = {0.0};
    t.points.push_back(p);
  }
  return t;
}

TEST_F(TrajectoryWireTest, ADelayTrajectoryPutsItsInterpolationOnEveryPackageAndEachPointsRatesInItsCommand) {
  TakeSent();
  // Whole microseconds: what the wire carries.
  const TimePoint start =
      std::chrono::floor<std::chrono::microseconds>(client_->ServerNow() + milliseconds(200));
  const JointTrajectory trajectory = PanTrajectory(5);
  std::vector<PendingReply> pending =
      client_->SendTrajectory(trajectory, {.interpolation = Interpolation::kQuintic, .start = start});
  ASSERT_EQ(pending.size(), 5u);
  for (PendingReply& p : pending) {
    const Reply r = p.Wait(seconds(5));
    EXPECT_TRUE(Succeeded(r.signal)) << ToString(r.signal) << " " << r.message;
  }
  const std::vector<Request> packages = CommandPackages(TakeSent());
  ASSERT_FALSE(packages.empty());
  std::size_t k = 0;
  for (const Request& r : packages) {
    EXPECT_EQ(r.interpolation, Interpolation::kQuintic) << "package " << r.sequence;
    EXPECT_EQ(r.mode, RequestMode::kDelay);
    for (const Command& c : r.commands) {
      ASSERT_LT(k, trajectory.points.size());
      const TrajectoryPoint& p = trajectory.points[k++];
      EXPECT_EQ(c.type, CommandType::kJointSetPoint);
      EXPECT_EQ(c.target, "pan");
      EXPECT_EQ(c.start_time, StartTime::At(start + p.time_from_start));
      EXPECT_EQ(c.values, p.positions);
      EXPECT_EQ(c.velocities, p.velocities);
      EXPECT_EQ(c.accelerations, p.accelerations);
    }
  }
  EXPECT_EQ(k, 5u);
}

TEST_F(TrajectoryWireTest, APlaybackFrameTrajectoryDeclaresOneSequenceWhosePackagesAllSayItsInterpolation) {
  const Reply pose = client_->Query(QueryType::kFramePoses, "camera");
  ASSERT_EQ(pose.values.size(), 7u) << pose.message;
  FrameTrajectory camera{.frame = "camera"};
  for (int i = 1; i <= 4; ++i)  // where the camera is: reachable whatever the IK
    camera.points.push_back({milliseconds(30 * i), pose.values, {0, 0, 0, 0, 0, 0}, {}});
  TakeSent();
  const SequenceResult result = client_->RunTrajectory(
      camera, {.mode = CommandMode::kPlayback, .interpolation = Interpolation::kLinear});
  ASSERT_EQ(result.replies.size(), 4u);
  for (const Reply& r : result.replies)
    EXPECT_TRUE(Succeeded(r.signal)) << ToString(r.signal) << " " << r.message;
  EXPECT_TRUE(result.playback_delay);
  const std::vector<Request> packages = CommandPackages(TakeSent());
  std::size_t commands = 0;
  for (const Request& r : packages) {
    EXPECT_EQ(r.mode, RequestMode::kPlayback);
    EXPECT_EQ(r.interpolation, Interpolation::kLinear);
    EXPECT_EQ(r.playback.frames, 4);
    EXPECT_EQ(r.playback.duration, milliseconds(120));
    for (const Command& c : r.commands) {
      EXPECT_EQ(c.type, CommandType::kFrameSetPoint);
      EXPECT_EQ(c.start_time, StartTime::After(milliseconds(30 * static_cast<int>(++commands))));
      EXPECT_EQ(c.velocities.size(), 6u);
    }
  }
  EXPECT_EQ(commands, 4u);
}

// A whole sequence (a sequence file) sent interpolated, batched and paced.
TEST_F(RobotClientWireTest, ASequenceSentInterpolatedCarriesItOnEveryPackageAndAStepFrameTravelsApart) {
  std::vector<TimedCommand> frames;
  for (int i = 0; i < 6; ++i) {
    frames.push_back({milliseconds(30 * i),
                      Command{.type = CommandType::kJointSetPoint, .target = "tilt", .values = {-0.01 * i}}});
  }
  // A step frame between waypoints of the same joint would end the joint's
  // trajectory (docs/protocol.md, Trajectories): this one moves another joint.
  frames[3].interpolation = Interpolation::kStep;
  frames[3].command.target = "pan";
  TakeSent();
  SequenceResult result = client_->RunSequence(
      frames,
      {.delay = milliseconds(100), .paced = false, .batch = 200, .interpolation = Interpolation::kCubic});
  for (const Reply& r : result.replies)
    EXPECT_TRUE(Succeeded(r.signal)) << ToString(r.signal) << ": " << r.message;
  std::vector<std::pair<Interpolation, std::size_t>> kinds;
  for (const Request& r : CommandPackages(TakeSent())) kinds.emplace_back(r.interpolation, r.commands.size());
  EXPECT_THAT(kinds, ::testing::ElementsAre(std::pair{Interpolation::kCubic, std::size_t{3}},
                                            std::pair{Interpolation::kStep, std::size_t{1}},
                                            std::pair{Interpolation::kCubic, std::size_t{2}}));
  // Paced: one frame a package, each with the sequence's interpolation.
  frames.resize(3);
  result =
      client_->RunSequence(frames, {.delay = milliseconds(100), .interpolation = Interpolation::kLinear});
  for (const Reply& r : result.replies) EXPECT_TRUE(Succeeded(r.signal)) << r.message;
  const std::vector<Request> paced = CommandPackages(TakeSent());
  ASSERT_EQ(paced.size(), 3u);
  for (const Request& r : paced) EXPECT_EQ(r.interpolation, Interpolation::kLinear);
}

TEST_F(RobotClientWireTest, SingleCallsAndUninterpolatedSequencesStillSayStep) {
  TakeSent();
  EXPECT_EQ(client_->SetJoint("pan", {0.05}).signal, Signal::kSuccess);
  client_->RunSequence(Frames(2), {.mode = CommandMode::kDelay, .delay = milliseconds(50)});
  const std::vector<Request> packages = CommandPackages(TakeSent());
  ASSERT_EQ(packages.size(), 3u);  // the set-point, then one package a paced frame
  for (const Request& r : packages) EXPECT_EQ(r.interpolation, Interpolation::kStep);
}

TEST_F(TrajectoryWireTest, ABadTrajectoryIsRefusedBeforeAnythingIsSent) {
  TakeSent();
  const auto refused = [&](const auto& trajectory, const TrajectoryOptions& options) {
    try {
      client_->SendTrajectory(trajectory, options);
    } catch (const ClientError& e) {
      return std::string(e.what());
    }
    return std::string("sent");
  };
  JointTrajectory bad = PanTrajectory(3);
  bad.points[2].time_from_start = milliseconds(10);
  EXPECT_THAT(refused(bad, {}),
              HasSubstr("joint 'pan': point 2: time_from_start 0.01 s is not after point 1's"));
  bad = PanTrajectory(3);
  bad.points[1].velocities = {0.1, 0.2};
  EXPECT_THAT(refused(bad, {}),
              HasSubstr("point 1: JOINT_SETPOINT 'pan': expected 0 or 1 velocities, got 2"));
  EXPECT_THAT(refused(PanTrajectory(2), {.mode = CommandMode::kDirect}),
              HasSubstr("needs mode delay or playback"));
  EXPECT_THAT(
      refused(FrameTrajectory{.frame = "lens", .points = {{milliseconds(10), {0, 0, 0, 1, 0, 0, 0}, {}, {}}}},
              {}),
      HasSubstr("no control frame named 'lens'"));
  EXPECT_THROW(client_->RunTrajectory(PanTrajectory(2), {.mode = CommandMode::kDirect}), ClientError);
  EXPECT_TRUE(CommandPackages(TakeSent()).empty());

  MemoryTransport elsewhere(std::make_shared<MemoryBus>());
  RobotClient unconnected({.transport = &elsewhere});
  EXPECT_THROW(unconnected.SendTrajectory(PanTrajectory(1)), ClientError);
  EXPECT_THROW(unconnected.RunTrajectory(PanTrajectory(1)), ClientError);
}

}  // namespace
}  // namespace robotalk
