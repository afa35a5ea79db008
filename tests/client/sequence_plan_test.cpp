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
