// Issue 22 item 2: the pure SpeedRamp (robotalk-server/src/speed_ramp.h) on a
// manual clock: a twist plan through SETSPEED frames, a reference that is
// continuous and never changes faster than the base's limit, MODIFIED when
// the limit bites, splices, late frames, and End().
#include "speed_ramp.h"

#include "queued_items.h"
#include "support/test_clients.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace robotalk {
namespace {

using std::chrono::milliseconds;
using ::testing::HasSubstr;

using testing::kAlice;
using testing::kBob;
using testing::kT0;
constexpr Duration kPeriod = milliseconds(10);

// A SETSPEED frame of a linear package, due at `at`, received 200 ms before.
QueuedItem Frame(CommandId id, TimePoint at, std::vector<double> values, std::int64_t client = kAlice) {
  QueuedItem item = testing::Waypoint(id, -1, at, std::move(values), Interpolation::kLinear, client,
                                      CommandType::kSetSpeed);
  item.received = at - milliseconds(200);
  return item;
}

class SpeedRampTest : public ::testing::Test {
 protected:
  void Add(const QueuedItem& item, TimePoint now, BaseReference current = {}) {
    owner_ = ramp_.Add(std::span<const QueuedItem>(&item, 1), now, current, answers_);
  }
  // Samples every period from `from` to `to`, checking the reference against the limits.
  void SampleTo(TimePoint from, TimePoint to) {
    for (TimePoint t = from; t <= to; t += kPeriod) {
      const BaseReference before = ramp_.reference();
      if (!ramp_.Sample(t, answers_)) break;
      const BaseReference& r = ramp_.reference();
      if (sampled_) {
        const double dt = ToSeconds(kPeriod);
        max_linear_ = std::max(max_linear_, std::hypot(r.vx - before.vx, r.vy - before.vy) / dt);
        max_angular_ = std::max(max_angular_, std::abs(r.omega - before.omega) / dt);
      }
      sampled_ = true;
    }
  }
  const Reply* Find(CommandId id) const {
    for (const auto& a : answers_) {
      if (a.reply.id == id) return &a.reply;
    }
    return nullptr;
  }

  SpeedRamp ramp_{SpeedRampOptions{.linear_acceleration = 3, .angular_acceleration = 6, .period = kPeriod}};
  std::vector<SpeedRamp::Answer> answers_;
  std::int64_t owner_ = 0;
  double max_linear_ = 0, max_angular_ = 0;
  bool sampled_ = false;
};

TEST_F(SpeedRampTest, FramesWithinTheLimitAreInterpolatedLinearlyAndMetAtTheirTimes) {
  Add(Frame(1, kT0 + milliseconds(200), {0.2, 0.4}), kT0);
  Add(Frame(2, kT0 + milliseconds(400), {0.6, 0.0}), kT0);
  EXPECT_EQ(owner_, 0) << "the same client, the ramp already started";
  ASSERT_TRUE(ramp_.active());
  SampleTo(kT0, kT0 + milliseconds(100));
  EXPECT_NEAR(ramp_.reference().vx, 0.1, 1e-12);
  EXPECT_NEAR(ramp_.reference().omega, 0.2, 1e-12);
  SampleTo(kT0 + milliseconds(110), kT0 + milliseconds(300));
  EXPECT_NEAR(ramp_.reference().vx, 0.4, 1e-12);
  EXPECT_NEAR(ramp_.reference().omega, 0.2, 1e-12);
  EXPECT_NEAR(ramp_.reference().ax, 2.0, 1e-9) << "its rate, for a driver that interpolates";
  SampleTo(kT0 + milliseconds(310), kT0 + milliseconds(500));
  EXPECT_EQ(ramp_.reference().vx, 0.6);
  EXPECT_FALSE(ramp_.active()) << "there: the base keeps the twist, as after a SETSPEED";
  for (CommandId id : {1, 2}) {
    ASSERT_NE(Find(id), nullptr);
    EXPECT_EQ(Find(id)->signal, Signal::kSuccess) << Find(id)->message;
  }
  EXPECT_EQ(Find(2)->exec_time, kT0 + milliseconds(400));
}

TEST_F(SpeedRampTest, TheFirstFrameStartsFromTheMeasuredTwistAndMakesItsClientTheOwner) {
  Add(Frame(1, kT0 + milliseconds(100), {0.3, 0.0}), kT0, BaseReference{.vx = 0.5, .omega = -0.3});
  EXPECT_EQ(owner_, kAlice);
  SampleTo(kT0, kT0 + milliseconds(50));
  EXPECT_NEAR(ramp_.reference().vx, 0.4, 1e-12);
  EXPECT_NEAR(ramp_.reference().omega, -0.15, 1e-12);
  Add(Frame(2, kT0 + milliseconds(300), {0.3, 0.0}, kBob), kT0 + milliseconds(50));
  EXPECT_EQ(owner_, kBob) << "another client's frame takes the base over";
}

TEST_F(SpeedRampTest, RandomFramesGiveAContinuousReferenceNeverAboveTheLimit) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> v(-1, 1), w(-2, 2), gap(0.02, 0.3);
  TimePoint at = kT0;
  int modified = 0;
  for (CommandId id = 1; id <= 200; ++id) {
    at += FromSeconds(gap(rng));
    Add(Frame(id, at, {v(rng), 0.5 * v(rng), w(rng)}), kT0);
  }
  Add(Frame(201, at + milliseconds(100), {0, 0, 0}), kT0);
  SampleTo(kT0, at + std::chrono::seconds(3));
  EXPECT_LE(max_linear_, 3 * (1 + 1e-9));
  EXPECT_LE(max_angular_, 6 * (1 + 1e-9));
  for (const auto& a : answers_) {
    if (a.reply.signal == Signal::kModified) {
      ++modified;
      EXPECT_THAT(a.reply.message, HasSubstr("ramp limited"));
    } else {
      EXPECT_EQ(a.reply.signal, Signal::kSuccess);
    }
  }
  EXPECT_EQ(answers_.size(), 201u);
  EXPECT_GT(modified, 10) << "the frames are up to 100 m/s² apart";
  EXPECT_FALSE(ramp_.active());
  EXPECT_EQ(ramp_.reference().vx, 0.0) << "the last frame, SETSPEED 0, brought it to rest";
  EXPECT_EQ(ramp_.reference().vy, 0.0);
  EXPECT_EQ(ramp_.reference().omega, 0.0);
  EXPECT_TRUE(ramp_.reference().lateral) << "the frames gave vy";
}

TEST_F(SpeedRampTest, ATooSteepFrameIsApproachedAtTheLimitAndAnswersModifiedNamingTheLimitAndTheValue) {
  Add(Frame(1, kT0 + milliseconds(100), {0.0, 2.0}), kT0);  // 2 rad/s in 0.1 s: 20 rad/s²
  SampleTo(kT0, kT0 + milliseconds(100));
  const Reply* r = Find(1);
  ASSERT_NE(r, nullptr);
  EXPECT_EQ(r->signal, Signal::kModified);
  EXPECT_EQ(
      r->message,
      "SETSPEED: ramp limited: the plan's angular acceleration 20 rad/s² exceeds the base's limit 6 rad/s²; "
      "the reference was 1.4 rad/s from it at its time");
  EXPECT_NEAR(ramp_.reference().omega, 0.6, 1e-12);
  SampleTo(kT0 + milliseconds(110), kT0 + milliseconds(500));
  EXPECT_EQ(ramp_.reference().omega, 2.0);
  EXPECT_LE(max_angular_, 6 * (1 + 1e-9));
}

// A frame passed inside a control period whose sample is already limited on
// the way to the next frame was met: the next one answers MODIFIED, not it.
TEST_F(SpeedRampTest, TheLimitIsChargedToTheFrameItKeptTheReferenceFrom) {
  Add(Frame(1, kT0 + milliseconds(105), {0.0, 0.0}), kT0);
  Add(Frame(2, kT0 + milliseconds(205), {1.0, 0.0}), kT0);  // 10 m/s²
  SampleTo(kT0, kT0 + milliseconds(300));
  ASSERT_NE(Find(1), nullptr);
  EXPECT_EQ(Find(1)->signal, Signal::kSuccess) << Find(1)->message;
  ASSERT_NE(Find(2), nullptr);
  EXPECT_EQ(Find(2)->signal, Signal::kModified);
  EXPECT_THAT(Find(2)->message,
              HasSubstr("the plan's linear acceleration 10 m/s² exceeds the base's limit 3 m/s²"));
}

TEST_F(SpeedRampTest, ASpliceReplacesTheLaterFramesAndTheReferenceDoesNotJump) {
  Add(Frame(1, kT0 + milliseconds(200), {0.4, 0}), kT0);
  Add(Frame(2, kT0 + milliseconds(400), {0.4, 0}), kT0);
  SampleTo(kT0, kT0 + milliseconds(250));
  Add(Frame(3, kT0 + milliseconds(350), {0.1, 0}, kBob), kT0 + milliseconds(250));
  EXPECT_EQ(owner_, kBob);
  const Reply* r = Find(2);
  ASSERT_NE(r, nullptr);
  EXPECT_EQ(r->signal, Signal::kInterrupted);
  EXPECT_EQ(r->message, "SETSPEED: superseded by command 3");
  SampleTo(kT0 + milliseconds(260), kT0 + milliseconds(400));
  EXPECT_LE(max_linear_, 3 * (1 + 1e-9));
  EXPECT_EQ(ramp_.reference().vx, 0.1);
  ASSERT_NE(Find(3), nullptr);
  EXPECT_EQ(Find(3)->signal, Signal::kSuccess) << Find(3)->message;
}

TEST_F(SpeedRampTest, ALateFrameIsJoinedOnePeriodAheadOrSkippedWhenALaterOneIsPlanned) {
  Add(Frame(1, kT0 - milliseconds(30), {0.02, 0}), kT0);
  const Reply* skipped = nullptr;
  Add(Frame(2, kT0 + milliseconds(200), {0.2, 0}), kT0);
  Add(Frame(3, kT0 - milliseconds(20), {0.5, 0}), kT0);
  skipped = Find(3);
  ASSERT_NE(skipped, nullptr);
  EXPECT_EQ(skipped->signal, Signal::kInterrupted);
  EXPECT_THAT(skipped->message, HasSubstr("a later frame is already planned"));
  SampleTo(kT0, kT0 + milliseconds(300));
  const Reply* joined = Find(1);
  ASSERT_NE(joined, nullptr);
  EXPECT_EQ(joined->signal, Signal::kModified);
  EXPECT_THAT(joined->message, HasSubstr("arrived 0.03 s after its time: joined 0.01 s from its arrival"));
  EXPECT_EQ(joined->exec_time, kT0 + kPeriod);
}

TEST_F(SpeedRampTest, AnExpiredFrameBringsTheBaseToRestWithinTheLimit) {
  QueuedItem late = Frame(1, kT0 - milliseconds(300), {0.9, 0});
  late.max_late = milliseconds(100);
  late.received = kT0;
  Add(late, kT0, BaseReference{.vx = 0.6});
  const Reply* r = Find(1);
  ASSERT_NE(r, nullptr);
  EXPECT_EQ(r->signal, Signal::kInterrupted);
  EXPECT_THAT(r->message, HasSubstr("expired: arrived 0.3 s after its start, limit 0.1 s"));
  EXPECT_EQ(owner_, 0) << "an expired frame takes nothing over";
  SampleTo(kT0, kT0 + milliseconds(100));
  EXPECT_NEAR(ramp_.reference().vx, 0.3, 1e-12);
  SampleTo(kT0 + milliseconds(110), kT0 + milliseconds(300));
  EXPECT_EQ(ramp_.reference().vx, 0.0);
  EXPECT_FALSE(ramp_.active());
}

TEST_F(SpeedRampTest, EndInterruptsEveryFrameNotYetPassed) {
  Add(Frame(1, kT0 + milliseconds(100), {0.2, 0}), kT0);
  Add(Frame(2, kT0 + milliseconds(200), {0.3, 0}), kT0);
  SampleTo(kT0, kT0 + milliseconds(150));
  ramp_.End(kT0 + milliseconds(150), "stopped by STOP", answers_);
  EXPECT_FALSE(ramp_.active());
  EXPECT_EQ(ramp_.pending(), 0u);
  ASSERT_NE(Find(1), nullptr);
  EXPECT_EQ(Find(1)->signal, Signal::kSuccess);
  ASSERT_NE(Find(2), nullptr);
  EXPECT_EQ(Find(2)->signal, Signal::kInterrupted);
  EXPECT_EQ(Find(2)->message, "SETSPEED: stopped by STOP");
  EXPECT_FALSE(ramp_.Sample(kT0 + milliseconds(160), answers_)) << "no reference after End";
}

TEST_F(SpeedRampTest, TheDriversModifiedAnswerReachesTheFrame) {
  Add(Frame(1, kT0 + milliseconds(50), {0.1, 0, 0}), kT0);
  SampleTo(kT0, kT0 + milliseconds(20));
  ramp_.NoteDriver("SETSPEED: lateral speed vy = 0 m/s dropped (differential base)");
  SampleTo(kT0 + milliseconds(30), kT0 + milliseconds(60));
  ASSERT_NE(Find(1), nullptr);
  EXPECT_EQ(Find(1)->signal, Signal::kModified);
  EXPECT_THAT(Find(1)->message, HasSubstr("dropped (differential base)"));
}

TEST(SpeedRamp, OnAFixedBaseEveryFrameAnswersNa) {
  SpeedRamp ramp(SpeedRampOptions{.mobile = false, .robot = "arm"});
  std::vector<SpeedRamp::Answer> answers;
  const QueuedItem f = Frame(1, kT0 + milliseconds(100), {0.1, 0});
  EXPECT_EQ(ramp.Add(std::span<const QueuedItem>(&f, 1), kT0, {}, answers), 0);
  ASSERT_EQ(answers.size(), 1u);
  EXPECT_EQ(answers[0].reply.signal, Signal::kNa);
  EXPECT_EQ(answers[0].reply.message, "SETSPEED: robot 'arm' has a fixed base");
  EXPECT_FALSE(ramp.active());
}

}  // namespace
}  // namespace robotalk
