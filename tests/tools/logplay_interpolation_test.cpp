// Issue 22 item 7: robotalk-logplay replays a recorded interpolated session
// with its interpolation. The session is what the C++ client sent to the
// real server core in-process (client/wire_fixture.h), heard as a logger
// hears it (every REQUEST and REPLY message); replay is what `replay` does
// after connecting: SessionLog -> Timeline -> ToFrames -> cli::RunFrames,
// here through the same client, whose new packages are read back.
#include "client/wire_fixture.h"
#include "logplay.h"
#include "sequence_runner.h"

#include <gmock/gmock.h>

#include <sstream>

namespace robotalk {
namespace {

using namespace robotalk::testing;  // NOLINT: the fixture and its helpers
using ::testing::ElementsAre;
using ::testing::Pair;

using LogplayInterpolationTest = RobotClientWireTest;

std::vector<std::pair<Interpolation, std::size_t>> Kinds(const std::vector<Request>& sent) {
  std::vector<std::pair<Interpolation, std::size_t>> kinds;
  for (const Request& r : sent) {
    if (!r.commands.empty()) kinds.emplace_back(r.interpolation, r.commands.size());
  }
  return kinds;
}

TEST_F(LogplayInterpolationTest, AnInterpolatedSessionReplaysWithItsInterpolationAndRates) {
  // The session: a cubic trajectory of pan with a velocity, then a direct
  // set-point of pan (a step: no start time), then a quintic one of tilt. (A
  // step on a joint ends its trajectory, and waypoints the server already
  // holds for it are interrupted: docs/protocol.md, Trajectories; so the
  // step here moves the joint whose waypoints have all passed.)
  JointTrajectory pan{.joint = "pan"};
  for (int i = 1; i <= 3; ++i) pan.points.push_back({milliseconds(40 * i), {0.02 * i}, {}, {}});
  pan.points[1].velocities = {0.25};
  pan.points[1].accelerations = {0.5};
  SequenceResult recorded = client_->RunTrajectory(pan, {.interpolation = Interpolation::kCubic});
  for (const Reply& r : recorded.replies) ASSERT_TRUE(Succeeded(r.signal)) << r.message;
  ASSERT_TRUE(Succeeded(client_->SetJoint("pan", {0.05}).signal));
  JointTrajectory tilt{.joint = "tilt",
                       .points = {{milliseconds(30), {-0.1}, {}, {}}, {milliseconds(60), {-0.12}, {}, {}}}};
  recorded = client_->RunTrajectory(tilt, {.interpolation = Interpolation::kQuintic});
  for (const Reply& r : recorded.replies) ASSERT_TRUE(Succeeded(r.signal)) << r.message;

  logplay::SessionLog log;
  std::int64_t t = 1;
  for (const auto& [channel, bytes] : Heard()) log.Add(channel, t++, bytes);
  std::ostringstream info;
  logplay::PrintInfo(log, "session.lcmlog", info);
  EXPECT_THAT(info.str(), ::testing::HasSubstr("; interpolation step 1, cubic 3, quintic 2"));
  const logplay::Timeline timeline = log.MakeTimeline({.client_id = client_->client_id()});
  ASSERT_EQ(timeline.frames.size(), 6u);
  const std::vector<TimedCommand> frames = logplay::ToFrames(timeline, {.speed = 2.0});
  std::vector<Interpolation> kinds;
  for (const TimedCommand& f : frames) kinds.push_back(f.interpolation.value_or(Interpolation::kQuintic));
  // In time order: the pan waypoints, the step, the tilt waypoints.
  EXPECT_THAT(kinds, ElementsAre(Interpolation::kCubic, Interpolation::kCubic, Interpolation::kCubic,
                                 Interpolation::kStep, Interpolation::kQuintic, Interpolation::kQuintic));
  // Twice as fast: velocities twice, accelerations four times.
  EXPECT_EQ(frames[1].command.velocities, std::vector<double>{0.5});
  EXPECT_EQ(frames[1].command.accelerations, std::vector<double>{2.0});

  TakeSent();
  const cli::RunReport report = cli::RunFrames(
      *client_, frames, {.mode = CommandMode::kDelay, .delay = milliseconds(100), .paced = false}, {}, {},
      std::stop_token{});
  for (const auto& r : report.replies) {
    ASSERT_TRUE(r);
    EXPECT_TRUE(Succeeded(r->signal)) << r->message;
  }
  const std::vector<Request> replayed = TakeSent();
  EXPECT_THAT(Kinds(replayed), ElementsAre(Pair(Interpolation::kCubic, 3u), Pair(Interpolation::kStep, 1u),
                                           Pair(Interpolation::kQuintic, 2u)));
  for (const Request& r : replayed) {
    for (const Command& c : r.commands) {
      EXPECT_TRUE(c.start_time.is_at());  // every frame is timed on replay
      if (c.target == "pan" && c.values == std::vector<double>{0.04}) {
        EXPECT_EQ(c.velocities, std::vector<double>{0.5});
      }
    }
  }

  // A playback replay carries one interpolation: a mixed session is refused
  // before anything is sent, naming the frames.
  try {
    cli::RunFrames(*client_, frames, {.mode = CommandMode::kPlayback, .paced = false}, {}, {},
                   std::stop_token{});
    ADD_FAILURE() << "a mixed playback replay was sent";
  } catch (const ClientError& e) {
    EXPECT_THAT(e.what(), ::testing::HasSubstr("a playback sequence has one interpolation: frame 3 is step"));
  }
  EXPECT_TRUE(Kinds(TakeSent()).empty());
  // One trajectory alone replays in playback mode, its packages all cubic.
  const std::vector<TimedCommand> pan_only(frames.begin(), frames.begin() + 3);
  const cli::RunReport playback = cli::RunFrames(
      *client_, pan_only, {.mode = CommandMode::kPlayback, .paced = false}, {}, {}, std::stop_token{});
  for (const auto& r : playback.replies) EXPECT_TRUE(r && Succeeded(r->signal));
  EXPECT_THAT(Kinds(TakeSent()), ElementsAre(Pair(Interpolation::kCubic, 3u)));
}

}  // namespace
}  // namespace robotalk
