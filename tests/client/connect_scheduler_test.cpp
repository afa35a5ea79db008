// ConnectScheduler (robotalk/connect_scheduler.h) on a ManualClock: what is
// tried when, how many at once, and which names the table keeps. Connects are
// the scheduler's real threads, each held until the test answers it; the
// waits below only wait for those threads (bounded), they assert no timing.
#include "robotalk/connect_scheduler.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <map>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

namespace robotalk {
namespace {

using std::chrono::seconds;

// The connect function the scheduler runs: each call waits until the test
// answers its name (success or failure).
class Connects {
 public:
  ConnectScheduler::ConnectFn Fn() {
    return [this](const std::string& name, Duration timeout) {
      std::unique_lock lock(mu_);
      started_.push_back({name, timeout});
      cv_.notify_all();
      cv_.wait(lock, [&] { return all_ || answers_.contains(name); });
      const bool ok = answers_.contains(name) && answers_[name];
      answers_.erase(name);
      if (!ok) throw std::runtime_error("no answer from " + name);
    };
  }
  ConnectScheduler::FailedFn Failed() {
    return [this](const std::string& name, const std::string& error, Duration retry_in) {
      std::lock_guard lock(mu_);
      failed_.push_back({name, retry_in});
      errors_.push_back(error);
      cv_.notify_all();
    };
  }

  struct Call {
    std::string name;
    Duration time;  // the connect's timeout, or the failure's wait
  };
  /// The first `n` connects started (waits for their threads, at most 10 s).
  std::vector<Call> Started(std::size_t n) { return WaitFor(started_, n); }
  /// The first `n` failures reported.
  std::vector<Call> FailuresReported(std::size_t n) { return WaitFor(failed_, n); }
  std::vector<std::string> Errors() {
    std::lock_guard lock(mu_);
    return errors_;
  }

  /// Answers `name`'s connect and waits until the scheduler recorded it:
  /// the name is no longer connecting, or its next attempt started.
  void Answer(ConnectScheduler& s, const std::string& name, bool ok) {
    const auto attempts = [&] {
      std::lock_guard lock(mu_);
      return std::count_if(started_.begin(), started_.end(), [&](const Call& c) { return c.name == name; });
    };
    const auto before = attempts();
    {
      std::lock_guard lock(mu_);
      answers_[name] = ok;
      cv_.notify_all();
    }
    const auto recorded = [&] { return !(s.Find(name) && s.Find(name)->connecting) || attempts() > before; };
    for (int i = 0; i < 10000 && !recorded(); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(1));
    ASSERT_TRUE(recorded()) << name << "'s connect never ended";
  }
  /// Fails every connect waiting, and every one to come (at teardown).
  void FailAll() {
    std::lock_guard lock(mu_);
    all_ = true;
    cv_.notify_all();
  }

 private:
  std::vector<Call> WaitFor(std::vector<Call>& calls, std::size_t n) {
    std::unique_lock lock(mu_);
    cv_.wait_for(lock, seconds(10), [&] { return calls.size() >= n; });
    return calls;
  }

  std::mutex mu_;
  std::condition_variable cv_;
  std::vector<Call> started_, failed_;
  std::vector<std::string> errors_;
  std::map<std::string, bool> answers_;
  bool all_ = false;
};

class ConnectSchedulerTest : public ::testing::Test {
 protected:
  ConnectSchedulerOptions Options() {
    ConnectSchedulerOptions o;
    o.clock = &clock_;
    return o;
  }
  /// The scheduler under test, on clock_, running connects_.
  ConnectScheduler& Make(const ConnectSchedulerOptions& o) {
    scheduler_ = std::make_unique<ConnectScheduler>(connects_.Fn(), connects_.Failed(), o);
    return *scheduler_;
  }
  // Its destructor waits for the connects in flight: they are answered first.
  void TearDown() override {
    connects_.FailAll();
    scheduler_.reset();
  }

  ManualClock clock_;
  Connects connects_;
  std::unique_ptr<ConnectScheduler> scheduler_;
};

std::string Name(int i) { return "robot-" + std::to_string(i); }

TEST_F(ConnectSchedulerTest, NeverMoreThanMaxConnectingAtOnceAndNamesNotTriedYetGoInTheOrderTheyCame) {
  ConnectScheduler& s = Make(Options());
  // Announced in an order that is not the names' sort order.
  std::vector<std::string> order;
  for (int i = 39; i >= 0; --i) order.push_back(Name(i));
  for (const std::string& n : order) EXPECT_EQ(s.Announce(n), ConnectScheduler::Heard::kAdded);
  s.Poll();
  EXPECT_EQ(s.counts().connecting, 32u) << "the bound (max_connecting)";
  const auto started = connects_.Started(32);
  ASSERT_EQ(started.size(), 32u);
  for (std::size_t i = 0; i < 32; ++i) {
    EXPECT_TRUE(s.Find(order[i])->connecting) << order[i] << ", announced " << i << "th";
    EXPECT_EQ(started[i].time, seconds(1)) << "a first attempt waits 1 s";
  }
  s.Poll();
  EXPECT_EQ(s.counts().connecting, 32u) << "polling again starts no more";
  EXPECT_FALSE(s.Find(order[32])->connecting);

  connects_.Answer(s, order[0], false);
  connects_.Answer(s, order[1], true);
  EXPECT_EQ(s.counts().connecting, 32u) << "two slots freed, two more started at once, without a Poll()";
  EXPECT_TRUE(s.Find(order[32])->connecting);
  EXPECT_TRUE(s.Find(order[33])->connecting);
  EXPECT_FALSE(s.Find(order[34])->connecting);
  EXPECT_TRUE(s.Find(order[1])->served);
  EXPECT_FALSE(s.Find(order[0])->connecting) << "failed: it waits its back-off";
  s.Poll();
  EXPECT_EQ(s.counts().connecting, 32u);
}

TEST_F(ConnectSchedulerTest, FailedConnectsWaitLongerEachTimeAndGiveLaterAttemptsMoreTime) {
  ConnectScheduler& s = Make(Options());
  const std::string robot = "slow";
  const std::vector<Duration> waits = {seconds(2),  seconds(4),  seconds(8), seconds(16),
                                       seconds(32), seconds(64), seconds(64)};
  const std::vector<Duration> timeouts = {seconds(1), seconds(2), seconds(4), seconds(4),
                                          seconds(4), seconds(4), seconds(4), seconds(4)};
  s.Announce(robot);
  s.Poll();
  for (std::size_t k = 0; k < waits.size(); ++k) {
    ASSERT_EQ(connects_.Started(k + 1).size(), k + 1);
    EXPECT_EQ(connects_.Started(k + 1)[k].time, timeouts[k]) << "attempt " << k + 1 << "'s timeout";
    connects_.Answer(s, robot, false);
    const auto failed = connects_.FailuresReported(k + 1);
    ASSERT_EQ(failed.size(), k + 1);
    EXPECT_EQ(failed[k].time, waits[k]) << "the wait after failure " << k + 1;
    EXPECT_EQ(s.Find(robot)->failures, static_cast<int>(k + 1));
    // Just before the wait is over: not tried (the robot is announced all the while).
    for (Duration left = waits[k] - Duration(1); left > Duration(0);) {
      const Duration step = std::min<Duration>(left, seconds(1));
      clock_.Advance(step);
      left -= step;
      s.Announce(robot);
      s.Poll();
    }
    EXPECT_FALSE(s.Find(robot)->connecting) << "tried again before its wait of failure " << k + 1 << " ended";
    clock_.Advance(Duration(1));
    s.Poll();
    EXPECT_TRUE(s.Find(robot)->connecting)
        << "not tried again when its wait of failure " << k + 1 << " ended";
  }
  EXPECT_EQ(connects_.Errors().front(), "no answer from slow") << "the failure says why";
  connects_.Answer(s, robot, true);
  EXPECT_TRUE(s.Find(robot)->served);
  EXPECT_EQ(s.Find(robot)->failures, 0) << "served: its failures are forgotten";
}

TEST_F(ConnectSchedulerTest, ANameNotTriedYetGoesBeforeTheRetries) {
  ConnectSchedulerOptions o = Options();
  o.max_connecting = 1;
  ConnectScheduler& s = Make(o);
  s.Announce("old");
  s.Poll();
  connects_.Answer(s, "old", false);
  clock_.Advance(seconds(2));
  s.Announce("old");
  s.Announce("new");  // came after "old"'s retry fell due
  s.Poll();
  EXPECT_TRUE(s.Find("new")->connecting) << "the name never tried goes first";
  EXPECT_FALSE(s.Find("old")->connecting);
  connects_.Answer(s, "new", true);
  EXPECT_TRUE(s.Find("old")->connecting) << "then the retry";
}

TEST_F(ConnectSchedulerTest,
       AFullTableGivesANameWhoseConnectsFailedToANewNameNeverOneServedConnectingOrNotTried) {
  ConnectSchedulerOptions o = Options();
  o.max_names = 4;
  ConnectScheduler& s = Make(o);
  for (const char* n : {"served", "connecting", "failed-once", "failed-twice"}) s.Announce(n);
  s.Poll();
  connects_.Answer(s, "served", true);
  connects_.Answer(s, "failed-once", false);
  connects_.Answer(s, "failed-twice", false);
  clock_.Advance(seconds(2));
  for (const char* n : {"served", "connecting", "failed-once", "failed-twice"}) s.Announce(n);
  s.Poll();
  connects_.Answer(s, "failed-twice", false);
  ASSERT_EQ(s.Find("failed-twice")->failures, 2);
  ASSERT_TRUE(s.Find("failed-once")->connecting);
  connects_.Answer(s, "failed-once", false);  // failed again: 2 as well, but announced later

  clock_.Advance(seconds(1));
  s.Announce("failed-once");
  std::string evicted;
  EXPECT_EQ(s.Announce("real", &evicted), ConnectScheduler::Heard::kAdded) << "a full table takes a new name";
  EXPECT_EQ(evicted, "failed-twice") << "the one that failed most, then announced longest ago, goes";
  EXPECT_FALSE(s.Find("failed-twice"));
  EXPECT_EQ(s.counts().names, 4u);
  EXPECT_EQ(s.Announce("another", &evicted), ConnectScheduler::Heard::kAdded);
  EXPECT_EQ(evicted, "failed-once");
  // Left: served, connecting, and two never tried: none gives its place.
  EXPECT_EQ(s.Announce("third", &evicted), ConnectScheduler::Heard::kRefused);
  EXPECT_EQ(evicted, "");
  for (const char* n : {"served", "connecting", "real", "another"}) EXPECT_TRUE(s.Find(n)) << n;
  EXPECT_EQ(s.Announce("served"), ConnectScheduler::Heard::kKnown);
}

TEST_F(ConnectSchedulerTest, ANameNotTriedThatFellSilentGivesItsPlaceFirst) {
  ConnectSchedulerOptions o = Options();
  o.max_names = 3;
  o.max_connecting = 1;
  ConnectScheduler& s = Make(o);
  s.Announce("failed");
  s.Poll();
  connects_.Answer(s, "failed", false);
  s.Announce("silent");
  s.Announce("heard");
  clock_.Advance(seconds(4));  // past silent_after (3 s)
  s.Announce("failed");
  s.Announce("heard");
  s.Poll();
  EXPECT_TRUE(s.Find("silent")->silent);
  EXPECT_FALSE(s.Find("silent")->connecting) << "a silent name is not tried";
  std::string evicted;
  EXPECT_EQ(s.Announce("real", &evicted), ConnectScheduler::Heard::kAdded);
  EXPECT_EQ(evicted, "silent") << "silent (gone), before one that failed";
}

TEST_F(ConnectSchedulerTest, ANameSilentLongIsForgottenUnlessServedOrConnecting) {
  ConnectScheduler& s = Make(Options());
  for (const char* n : {"served", "connecting", "failed"}) s.Announce(n);
  s.Poll();
  connects_.Answer(s, "served", true);
  connects_.Answer(s, "failed", false);
  clock_.Advance(seconds(3 + 60));  // silent_after + forget_after: not yet
  EXPECT_TRUE(s.Poll().empty());
  clock_.Advance(Duration(1));
  EXPECT_EQ(s.Poll(), std::vector<std::string>{"failed"});
  EXPECT_FALSE(s.Find("failed"));
  EXPECT_TRUE(s.Find("served"));
  EXPECT_TRUE(s.Find("connecting"));
  connects_.Answer(s, "connecting", false);
  EXPECT_EQ(s.Poll(), std::vector<std::string>{"connecting"}) << "forgotten once its connect ended";
  EXPECT_EQ(s.counts().names, 1u);
}

TEST_F(ConnectSchedulerTest, ALostNameIsTriedAgainAtOnceAndALossDuringItsConnectCounts) {
  ConnectScheduler& s = Make(Options());
  s.Announce("robot");
  s.Poll();
  connects_.Answer(s, "robot", true);
  s.Poll();
  EXPECT_FALSE(s.Find("robot")->connecting) << "served: not tried";
  s.Lost("robot");
  EXPECT_FALSE(s.Find("robot")->served);
  s.Poll();
  EXPECT_TRUE(s.Find("robot")->connecting) << "lost: tried again at once";
  EXPECT_EQ(connects_.Started(2).back().time, seconds(1)) << "as a name not tried yet";
  s.Lost("robot");  // while its connect is in flight: the caller dropped what it got
  connects_.Answer(s, "robot", true);
  EXPECT_FALSE(s.Find("robot")->served);
  EXPECT_TRUE(s.Find("robot")->connecting) << "and tried again at once";
  EXPECT_EQ(connects_.Started(3).size(), 3u);
}

}  // namespace
}  // namespace robotalk
