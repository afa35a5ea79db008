#include "command_queue.h"
#include "sequence_window.h"
#include "session.h"

#include <gtest/gtest.h>

#include <limits>

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
  using V = SequenceWindow::Verdict;
  SequenceWindow w;
  EXPECT_EQ(w.Observe(1), V::kNew);
  EXPECT_EQ(w.Observe(3), V::kNew);
  EXPECT_EQ(w.Observe(3), V::kDuplicate);
  EXPECT_EQ(w.Observe(2), V::kNew);
  EXPECT_EQ(w.Observe(1), V::kDuplicate);
  EXPECT_EQ(w.Observe(2), V::kDuplicate);
  EXPECT_EQ(w.Observe(4), V::kNew);
  EXPECT_EQ(w.Observe(0), V::kDuplicate);
  EXPECT_EQ(w.unseen(), 0);
}

// Issue 19 item 12: strides of +4000, each under the old 4096-jump guard,
// pushed the victim's next number out of the window; its package was then
// dropped as a duplicate and never ran.
TEST(SequenceWindow, ANumberNeverSeenStaysNewHoweverFarBelowTheHighest) {
  using V = SequenceWindow::Verdict;
  SequenceWindow w;
  ASSERT_EQ(w.Observe(1), V::kNew);
  EXPECT_EQ(w.Observe(4001), V::kNew);
  EXPECT_EQ(w.Observe(8001), V::kTooManyGaps) << "7999 numbers would be unseen";
  for (std::int64_t s = 4002; s < 20000; ++s) ASSERT_EQ(w.Observe(s), V::kNew) << s;
  EXPECT_EQ(w.Observe(2), V::kNew) << "the victim's next number, 18000 below the highest";
  EXPECT_EQ(w.Observe(2), V::kDuplicate);
  EXPECT_EQ(w.unseen(), 3998);
}

TEST(SequenceWindow, BoundsTheUnseenNumbersNotTheJump) {
  using V = SequenceWindow::Verdict;
  SequenceWindow w;
  ASSERT_EQ(w.Observe(100000), V::kNew) << "a client may keep counting across sessions";
  EXPECT_EQ(w.unseen(), SequenceWindow::kLead);
  EXPECT_EQ(w.Observe(99990), V::kNew) << "reordered at the session's start";
  EXPECT_EQ(w.Observe(99000), V::kDuplicate) << "before the session";
  const std::int64_t room = SequenceWindow::kMaxUnseen - w.unseen();
  EXPECT_EQ(w.Check(100000 + room + 2), V::kTooManyGaps);
  EXPECT_EQ(w.Observe(100000 + room + 1), V::kNew);
  EXPECT_EQ(w.Observe(100000 + room + 3), V::kTooManyGaps) << "no room left";
  EXPECT_EQ(w.Observe(100000 + room + 2), V::kNew) << "the next number is always fine";
  EXPECT_EQ(w.Observe(100001), V::kNew) << "filling a gap makes room";
  EXPECT_EQ(w.Observe(100000 + room + 4), V::kNew);
  EXPECT_EQ(w.Observe(std::numeric_limits<std::int64_t>::max()), V::kTooManyGaps);
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
