#include "command_queue.h"
#include "sequence_window.h"
#include "session.h"

#include <gtest/gtest.h>

namespace robotalk {
namespace {

using std::chrono::seconds;

QueuedItem Item(CommandId id, std::optional<TimePoint> start, std::uint64_t arrival) {
  QueuedItem item;
  item.command.id = id;
  item.arrival = arrival;
  if (start) {
    item.start = *start;
    item.has_start_time = true;
  }
  return item;
}

TEST(CommandQueue, RunsAStopAtFortySecondsAfterAGotoAtTwentyEvenIfTheStopArrivedFirst) {
  const TimePoint t0(seconds(100));
  CommandQueue q;
  q.Push(Item(/*STOP*/ 1, t0 + seconds(40), 1));
  q.Push(Item(/*GOTO*/ 2, t0 + seconds(20), 2));
  EXPECT_EQ(q.Pop().command.id, 2);
  EXPECT_EQ(q.Pop().command.id, 1);
  EXPECT_TRUE(q.empty());
}

TEST(CommandQueue, RunsEqualStartTimesInArrivalOrder) {
  const TimePoint t(seconds(5));
  CommandQueue q;
  for (int i = 1; i <= 50; ++i) q.Push(Item(i, t, static_cast<std::uint64_t>(i)));
  for (int i = 1; i <= 50; ++i) EXPECT_EQ(q.Pop().command.id, i);
}

TEST(CommandQueue, RunsImmediateItemsBeforeTimedOnes) {
  CommandQueue q;
  q.Push(Item(1, TimePoint(seconds(1)), 1));
  q.Push(Item(2, std::nullopt, 2));
  EXPECT_EQ(q.Top().command.id, 2);
}

TEST(CommandQueue, FlushesEverythingInRunOrder) {
  CommandQueue q;
  q.Push(Item(3, TimePoint(seconds(3)), 1));
  q.Push(Item(1, TimePoint(seconds(1)), 2));
  q.Push(Item(2, TimePoint(seconds(2)), 3));
  std::vector<QueuedItem> out;
  q.Flush(out);
  ASSERT_EQ(out.size(), 3u);
  EXPECT_EQ(out[0].command.id, 1);
  EXPECT_EQ(out[2].command.id, 3);
  EXPECT_TRUE(q.empty());
}

TEST(SequenceWindow, AcceptsEachSequenceOnceInAnyOrder) {
  SequenceWindow w;
  EXPECT_TRUE(w.Observe(1));
  EXPECT_TRUE(w.Observe(3));
  EXPECT_FALSE(w.Observe(3));
  EXPECT_TRUE(w.Observe(2));
  EXPECT_FALSE(w.Observe(1));
  EXPECT_FALSE(w.Observe(2));
  EXPECT_TRUE(w.Observe(4));
}

TEST(SequenceWindow, TreatsSequencesFarBelowTheHighestAsDuplicates) {
  SequenceWindow w;
  EXPECT_TRUE(w.Observe(1));
  EXPECT_TRUE(w.Observe(10 + SequenceWindow::kWindow));
  EXPECT_FALSE(w.Observe(5));  // a gap that fell out of the window
  EXPECT_TRUE(w.Observe(20 + SequenceWindow::kWindow - 1));
}

TEST(ReplyCache, ReturnsTheFinalRepliesOfAPackageAndForgetsOldPackages) {
  ReplyCache cache(ReplyCache::Limits{.max_packages = 2});
  cache.RecordPackage(1, {10, 11});
  cache.RecordReply(Reply{.id = 10, .signal = Signal::kSuccess});
  cache.RecordReply(Reply{.id = 99});  // not of a recorded package: ignored
  ASSERT_EQ(cache.RepliesFor(1).size(), 1u);
  EXPECT_EQ(cache.RepliesFor(1)[0].id, 10);
  cache.RecordPackage(2, {12});
  cache.RecordPackage(3, {13});  // evicts package 1
  EXPECT_TRUE(cache.RepliesFor(1).empty());
  cache.RecordReply(Reply{.id = 10});
  EXPECT_TRUE(cache.RepliesFor(1).empty());
}

}  // namespace
}  // namespace robotalk
