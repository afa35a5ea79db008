#include "scheduler.h"

#include "support/test_clients.h"

#include <gtest/gtest.h>

namespace robotalk {
namespace {

using std::chrono::milliseconds;
using std::chrono::seconds;

using testing::kT0;

QueuedItem Item(std::int64_t client, CommandId id, std::optional<TimePoint> start = std::nullopt,
                CommandType type = CommandType::kJointSetPoint) {
  QueuedItem item;
  item.client_id = client;
  item.command.id = id;
  item.command.type = type;
  item.has_start_time = start.has_value();
  if (start) item.start = *start;
  return item;
}

std::vector<CommandId> Ids(const std::vector<QueuedItem>& items) {
  std::vector<CommandId> ids;
  for (const auto& i : items) ids.push_back(i.command.id);
  return ids;
}

TEST(Scheduler, RunsAStopAtFortySecondsAfterAGotoAtTwentyEvenIfTheStopArrivedFirst) {
  Scheduler s;
  s.Push(Item(1, 1, kT0 + seconds(40), CommandType::kStop));
  s.Push(Item(2, 2, kT0 + seconds(20), CommandType::kGoto));
  std::vector<QueuedItem> due;
  s.TakeDue(kT0 + seconds(19), due);
  EXPECT_TRUE(due.empty());
  EXPECT_EQ(s.NextDeadline(), kT0 + seconds(20));
  s.TakeDue(kT0 + seconds(60), due);
  EXPECT_EQ(Ids(due), (std::vector<CommandId>{2, 1}));
  EXPECT_EQ(s.size(), 0u);
  EXPECT_EQ(s.NextDeadline(), TimePoint::max()) << "idle";
}

TEST(Scheduler, TakesItemsWithoutAStartTimeFirstAndEqualStartsInArrivalOrderAcrossClients) {
  Scheduler s;
  s.Push(Item(1, 10, kT0));
  s.Push(Item(2, 20, kT0));
  s.Push(Item(1, 11, kT0));
  s.Push(Item(2, 21));  // now
  std::vector<QueuedItem> due;
  s.TakeDue(kT0, due);
  EXPECT_EQ(Ids(due), (std::vector<CommandId>{21, 10, 20, 11}));
}

TEST(Scheduler, RunsTheServersOwnStopBeforeAnyDueClientItem) {
  Scheduler s;
  s.Push(Item(1, 1));
  QueuedItem stop = Item(0, 0, std::nullopt, CommandType::kStop);
  s.Push(stop);
  std::vector<QueuedItem> due;
  s.TakeDue(kT0, due);
  ASSERT_EQ(due.size(), 2u);
  EXPECT_EQ(due[0].client_id, 0);
}

TEST(Scheduler, CountsAndFlushesOneClientWithoutTouchingOthers) {
  Scheduler s;
  s.Push(Item(1, 1, kT0 + seconds(2)));
  s.Push(Item(1, 2, kT0 + seconds(1)));
  s.Push(Item(2, 3, kT0 + seconds(1)));
  EXPECT_EQ(s.queued(1), 2u);
  std::vector<QueuedItem> flushed;
  s.FlushClient(1, flushed);
  EXPECT_EQ(Ids(flushed), (std::vector<CommandId>{2, 1})) << "in run order";
  EXPECT_EQ(s.queued(1), 0u);
  EXPECT_EQ(s.queued(2), 1u);
  flushed.clear();
  s.FlushAll(flushed);
  EXPECT_EQ(Ids(flushed), (std::vector<CommandId>{3}));
  EXPECT_EQ(s.size(), 0u);
}

TEST(Scheduler, SamplesOnAnAbsoluteGridAndSkipsMissedSamplesInsteadOfBursting) {
  Scheduler s;
  EXPECT_EQ(s.SetStream(1, milliseconds(100), kT0), milliseconds(100));
  EXPECT_EQ(s.NextDeadline(), kT0);
  EXPECT_TRUE(s.TakeSampleDue(kT0));
  EXPECT_FALSE(s.TakeSampleDue(kT0 + milliseconds(99)));
  EXPECT_TRUE(s.TakeSampleDue(kT0 + milliseconds(103)));
  EXPECT_EQ(s.NextDeadline(), kT0 + milliseconds(200)) << "the grid, not 103 + 100";
  // Late by 3.5 periods: one sample, then back on the grid.
  EXPECT_TRUE(s.TakeSampleDue(kT0 + milliseconds(550)));
  EXPECT_FALSE(s.TakeSampleDue(kT0 + milliseconds(560)));
  EXPECT_EQ(s.NextDeadline(), kT0 + milliseconds(600));
}

TEST(Scheduler, StreamsAtTheShortestPeriodAskedAndStopsWhenTheLastClientCancels) {
  Scheduler s;
  s.SetStream(1, milliseconds(200), kT0);
  EXPECT_EQ(s.SetStream(2, milliseconds(50), kT0), milliseconds(50));
  EXPECT_EQ(s.SetStream(2, Duration(0), kT0), milliseconds(200));
  EXPECT_EQ(s.SetStream(1, Duration(0), kT0), Duration(0));
  EXPECT_FALSE(s.TakeSampleDue(kT0 + seconds(10)));
}

}  // namespace
}  // namespace robotalk
