// The sequence planner and pacer (sequence_plan.h) on a ManualClock.
#include "sequence_plan.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace robotalk::client {
namespace {

using std::chrono::milliseconds;
using ::testing::ElementsAre;

std::vector<TimedCommand> Frames(std::initializer_list<int> offsets_ms) {
  std::vector<TimedCommand> frames;
  for (int ms : offsets_ms) frames.push_back({milliseconds(ms), Command{.type = CommandType::kStop}});
  return frames;
}

std::vector<std::vector<std::size_t>> FramesOf(const SequencePlan& plan) {
  std::vector<std::vector<std::size_t>> out;
  for (const auto& s : plan.sends) out.push_back(s.frames);
  return out;
}

TEST(PlanSequence, PacedFramesLeaveOneByOneAtTheirOffsetsInOffsetOrder) {
  const auto plan = PlanSequence(Frames({200, 0, 100, 100}), {.mode = CommandMode::kDelay, .paced = true});
  EXPECT_THAT(FramesOf(plan), ElementsAre(ElementsAre(1), ElementsAre(2), ElementsAre(3), ElementsAre(0)));
  std::vector<Duration> at;
  for (const auto& s : plan.sends) at.push_back(s.send_at);
  EXPECT_THAT(at, ElementsAre(milliseconds(0), milliseconds(100), milliseconds(100), milliseconds(200)));
  EXPECT_EQ(plan.duration, milliseconds(200));
}

TEST(PlanSequence, UnpacedFramesLeaveAtOnceInBatches) {
  const auto plan =
      PlanSequence(Frames({30, 10, 20, 0, 40}), {.mode = CommandMode::kPlayback, .paced = false, .batch = 2});
  EXPECT_THAT(FramesOf(plan), ElementsAre(ElementsAre(3, 1), ElementsAre(2, 0), ElementsAre(4)));
  for (const auto& s : plan.sends) EXPECT_EQ(s.send_at, Duration(0));
}

TEST(PlanSequence, DirectModeSendsOneFramePerPackageEvenUnpaced) {
  const auto plan =
      PlanSequence(Frames({0, 10, 20}), {.mode = CommandMode::kDirect, .paced = false, .batch = 200});
  EXPECT_EQ(plan.sends.size(), 3u);
}

TEST(PlanSequence, RefusesANegativeOffsetNamingTheFrame) {
  try {
    PlanSequence(Frames({0, -5}), {});
    FAIL() << "no ClientError";
  } catch (const ClientError& e) {
    EXPECT_THAT(e.what(), ::testing::HasSubstr("frame 1 has a negative offset"));
  }
  EXPECT_TRUE(PlanSequence({}, {}).sends.empty());
}

// Issue 22 item 7: every package carries one interpolation.
TEST(PlanSequence, EveryPackageCarriesTheSequencesInterpolationAndAFramesOwnSplitsTheBatch) {
  auto frames = Frames({0, 10, 20, 30, 40});
  auto plan = PlanSequence(
      frames,
      {.mode = CommandMode::kDelay, .paced = false, .batch = 200, .interpolation = Interpolation::kCubic});
  ASSERT_EQ(plan.sends.size(), 1u);
  EXPECT_EQ(plan.sends[0].interpolation, Interpolation::kCubic);
  // A frame of its own interpolation (a replayed session of step and cubic
  // packages) travels in a package of its own kind.
  frames[2].interpolation = Interpolation::kStep;
  plan = PlanSequence(
      frames,
      {.mode = CommandMode::kDelay, .paced = false, .batch = 200, .interpolation = Interpolation::kCubic});
  EXPECT_THAT(FramesOf(plan), ElementsAre(ElementsAre(0, 1), ElementsAre(2), ElementsAre(3, 4)));
  std::vector<Interpolation> kinds;
  for (const auto& s : plan.sends) kinds.push_back(s.interpolation);
  EXPECT_THAT(kinds, ElementsAre(Interpolation::kCubic, Interpolation::kStep, Interpolation::kCubic));
  // Paced: one frame a package, each with its frame's interpolation.
  plan = PlanSequence(frames,
                      {.mode = CommandMode::kDelay, .paced = true, .interpolation = Interpolation::kLinear});
  ASSERT_EQ(plan.sends.size(), 5u);
  EXPECT_EQ(plan.sends[1].interpolation, Interpolation::kLinear);
  EXPECT_EQ(plan.sends[2].interpolation, Interpolation::kStep);
}

TEST(PlanSequence, RefusesAnInterpolationInDirectModeAndTwoInOnePlaybackSequence) {
  const auto error = [](const std::vector<TimedCommand>& frames, const SequenceOptions& options) {
    try {
      PlanSequence(frames, options);
    } catch (const ClientError& e) {
      return std::string(e.what());
    }
    return std::string("no ClientError");
  };
  EXPECT_EQ(error(Frames({0, 10}), {.mode = CommandMode::kDirect, .interpolation = Interpolation::kQuintic}),
            "RobotClient::RunSequence: frame 0: interpolation quintic needs mode delay or playback (a direct "
            "frame has no start time, so it is a step)");
  auto frames = Frames({0, 10, 20});
  frames[2].interpolation = Interpolation::kLinear;
  EXPECT_EQ(error(frames, {.mode = CommandMode::kPlayback, .interpolation = Interpolation::kCubic}),
            "RobotClient::RunSequence: a playback sequence has one interpolation: frame 2 is linear, frame 0 "
            "cubic");
  // Step in direct mode, and one interpolation in playback, are fine.
  EXPECT_EQ(PlanSequence(Frames({0, 10}), {.mode = CommandMode::kDirect}).sends.size(), 2u);
  frames[2].interpolation = Interpolation::kCubic;
  EXPECT_EQ(
      PlanSequence(frames,
                   {.mode = CommandMode::kPlayback, .paced = false, .interpolation = Interpolation::kCubic})
          .sends.size(),
      1u);
}

TEST(FrameStart, CarriesTheStartEachModeNeeds) {
  const TimePoint server_start(std::chrono::seconds(50));
  EXPECT_EQ(FrameStart(CommandMode::kDirect, milliseconds(300), server_start), StartTime::Now());
  EXPECT_EQ(FrameStart(CommandMode::kDelay, milliseconds(300), server_start),
            StartTime::At(server_start + milliseconds(300)));
  EXPECT_EQ(FrameStart(CommandMode::kPlayback, milliseconds(300), server_start),
            StartTime::After(milliseconds(300)));
}

TEST(SequencePacer, HandsOutEachPackageWhenTheClockReachesIt) {
  ManualClock clock;
  const auto plan = PlanSequence(Frames({0, 100, 250}), {.mode = CommandMode::kDelay, .paced = true});
  SequencePacer pacer(plan, clock.Now());
  ASSERT_NE(pacer.NextDue(clock.Now()), nullptr);
  EXPECT_EQ(pacer.NextDue(clock.Now()), nullptr);  // the second is 100 ms away
  EXPECT_EQ(pacer.NextDeadline(), clock.Now() + milliseconds(100));
  clock.Advance(milliseconds(99));
  EXPECT_EQ(pacer.NextDue(clock.Now()), nullptr);
  clock.Advance(milliseconds(1));
  const PlannedSend* second = pacer.NextDue(clock.Now());
  ASSERT_NE(second, nullptr);
  EXPECT_THAT(second->frames, ElementsAre(1));
  clock.Advance(milliseconds(500));  // late: the last one is due at once
  ASSERT_NE(pacer.NextDue(clock.Now()), nullptr);
  EXPECT_TRUE(pacer.done());
  EXPECT_FALSE(pacer.NextDeadline());
  EXPECT_EQ(pacer.NextDue(clock.Now()), nullptr);
}

}  // namespace
}  // namespace robotalk::client
