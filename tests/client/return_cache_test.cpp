#include "return_cache.h"

#include <gtest/gtest.h>

#include <atomic>
#include <thread>
#include <vector>

namespace robotalk::client {
namespace {

using Kind = ReturnCache::Outcome::Kind;
using std::chrono::milliseconds;

Reply MakeReply(CommandId id, Signal s = Signal::kSuccess, std::string message = "") {
  return Reply{.id = id, .signal = s, .message = std::move(message)};
}
std::chrono::steady_clock::time_point In(milliseconds d) { return std::chrono::steady_clock::now() + d; }

TEST(ReturnCache, FilesRepliesArrivingOutOfOrder) {
  ReturnCache cache;
  for (CommandId id = 1; id <= 5; ++id) cache.Expect(id);
  for (CommandId id = 5; id >= 1; --id)
    EXPECT_TRUE(cache.Put(MakeReply(id, Signal::kSuccess, std::to_string(id))));
  for (CommandId id = 1; id <= 5; ++id) {
    auto o = cache.Take(id);
    ASSERT_EQ(o.kind, Kind::kReply);
    EXPECT_EQ(o.reply.id, id);
    EXPECT_EQ(o.reply.message, std::to_string(id));
  }
  EXPECT_EQ(cache.size(), 0u);
}

TEST(ReturnCache, IgnoresADuplicateReply) {
  ReturnCache cache;
  cache.Expect(7);
  EXPECT_TRUE(cache.Put(MakeReply(7, Signal::kSuccess, "first")));
  EXPECT_FALSE(cache.Put(MakeReply(7, Signal::kError, "second")));
  auto o = cache.Take(7);
  ASSERT_EQ(o.kind, Kind::kReply);
  EXPECT_EQ(o.reply.message, "first");
  // And after collection, a late third copy is ignored too.
  EXPECT_FALSE(cache.Put(MakeReply(7)));
  EXPECT_EQ(cache.Take(7).kind, Kind::kUnknown);
  EXPECT_EQ(cache.ignored(), 2u);
}

TEST(ReturnCache, IgnoresRepliesForIdsNobodyExpects) {
  ReturnCache cache;
  EXPECT_FALSE(cache.Put(MakeReply(42)));
  cache.Expect(43);
  cache.Forget(43);
  EXPECT_FALSE(cache.Put(MakeReply(43)));
  EXPECT_EQ(cache.size(), 0u);
}

TEST(ReturnCache, PollIsPendingUntilTheReplyArrives) {
  ReturnCache cache;
  cache.Expect(1);
  EXPECT_EQ(cache.Take(1).kind, Kind::kPending);
  cache.Put(MakeReply(1));
  EXPECT_EQ(cache.Take(1).kind, Kind::kReply);
}

TEST(ReturnCache, WaitTimesOutWhenNoReplyComes) {
  ReturnCache cache;
  cache.Expect(1);
  const auto start = std::chrono::steady_clock::now();
  auto o = cache.WaitTake(1, In(milliseconds(50)));
  EXPECT_EQ(o.kind, Kind::kPending);
  EXPECT_GE(std::chrono::steady_clock::now() - start, milliseconds(50));
  // Still expected afterwards: a late reply can be collected.
  cache.Put(MakeReply(1));
  EXPECT_EQ(cache.Take(1).kind, Kind::kReply);
}

TEST(ReturnCache, FailWakesTheWaiterWithTheReason) {
  ReturnCache cache;
  cache.Expect(3);
  std::thread t([&] {
    // Real time (WaitTake's deadline is on the steady clock by design: blocking
    // calls time out in real time): 20 ms for the waiter to block first, so
    // that the wake-up is what is tested; a Fail before the wait gives the same.
    std::this_thread::sleep_for(milliseconds(20));
    cache.Fail(3, "gave up");
  });
  auto o = cache.WaitTake(3, In(milliseconds(2000)));
  t.join();
  ASSERT_EQ(o.kind, Kind::kFailed);
  EXPECT_EQ(o.failure, "gave up");
  EXPECT_TRUE(o.timed_out);
  // A reply after the failure is ignored.
  EXPECT_FALSE(cache.Put(MakeReply(3)));
}

TEST(ReturnCache, ConcurrentWaitersEachGetTheirOwnReply) {
  ReturnCache cache;
  constexpr int kN = 16;
  for (CommandId id = 1; id <= kN; ++id) cache.Expect(id);
  std::atomic<int> ok{0};
  std::vector<std::thread> waiters;
  for (CommandId id = 1; id <= kN; ++id) {
    waiters.emplace_back([&, id] {
      auto o = cache.WaitTake(id, In(milliseconds(5000)));
      if (o.kind == Kind::kReply && o.reply.id == id && o.reply.message == "r" + std::to_string(id)) ++ok;
    });
  }
  std::thread filer([&] {
    for (CommandId id = kN; id >= 1; --id) {  // reverse order, with duplicates
      cache.Put(MakeReply(id, Signal::kSuccess, "r" + std::to_string(id)));
      cache.Put(MakeReply(id, Signal::kError, "dup"));
    }
  });
  filer.join();
  for (auto& w : waiters) w.join();
  EXPECT_EQ(ok.load(), kN);
  EXPECT_EQ(cache.size(), 0u);
}

TEST(ReturnCache, EvictsTheOldestUncollectedRepliesBeyondCapacity) {
  ReturnCache cache(3);
  for (CommandId id = 1; id <= 5; ++id) {
    cache.Expect(id);
    cache.Put(MakeReply(id));
  }
  EXPECT_EQ(cache.size(), 3u);
  EXPECT_EQ(cache.Take(1).kind, Kind::kUnknown);
  EXPECT_EQ(cache.Take(2).kind, Kind::kUnknown);
  EXPECT_EQ(cache.Take(3).kind, Kind::kReply);
  EXPECT_EQ(cache.Take(5).kind, Kind::kReply);
}

TEST(ReturnCache, PendingIdsAreNeverEvicted) {
  ReturnCache cache(1);
  cache.Expect(1);  // stays pending
  for (CommandId id = 2; id <= 10; ++id) {
    cache.Expect(id);
    cache.Put(MakeReply(id));
  }
  EXPECT_EQ(cache.Take(1).kind, Kind::kPending);
  EXPECT_EQ(cache.Take(10).kind, Kind::kReply);
}

}  // namespace
}  // namespace robotalk::client
