// Issue 22 item 2 (last sentence): base SETSPEED frames of an interpolated
// package ramp within the base's acceleration limit, end to end in a
// RobotDaemon with the kinematic driver (which follows the base reference
// exactly) on a manual clock. A step package's SETSPEED still jumps at its
// time, as before. The figure docs/performance.md quotes (the largest base
// acceleration between control periods, ramped vs step, in one run) is
// printed by RandomFramesRampWithinTheLimitWhereAStepPackageJumps.
#include "kinematic_driver.h"
#include "queued_items.h"
#include "robot_daemon.h"
#include "support/test_clients.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>

namespace robotalk {
namespace {

using std::chrono::milliseconds;
using ::testing::HasSubstr;

using testing::kAlice;
using testing::kBob;
using testing::kT0;
constexpr double kLinear = 3.0, kAngular = 6.0;  // the server's defaults (m/s², rad/s²)

// A differential rover with a pan joint; `base` overrides its base type.
RobotModel Rover(BaseType base = BaseType::kDifferential) {
  RobotModelBuilder b("rover");
  b.AddLink(Link{.name = "body"}).AddLink(Link{.name = "head"});
  Joint pan{.name = "pan", .servo_types = ServoType::kSetPoint};
  pan.dofs = {Dof{.axis = Eigen::Vector3d::UnitZ(), .limits = {.lower = -2, .upper = 2, .velocity = 2}}};
  b.AddJoint(pan, "body", "head");
  b.SetRoot("body", Pose{}, base);
  return b.Build();
}

QueuedItem Speed(CommandId id, TimePoint at, double v, double omega,
                 Interpolation interpolation = Interpolation::kLinear, std::int64_t client = kAlice) {
  QueuedItem item = testing::Waypoint(id, -1, at, {v, omega}, interpolation, client, CommandType::kSetSpeed);
  item.received = at - milliseconds(300);
  return item;
}

QueuedItem Now(CommandId id, CommandType type, std::vector<double> values = {}, std::int64_t client = kBob) {
  QueuedItem item = testing::Motion(id, type, std::move(values));
  item.client_id = client;
  return item;
}

class RampedDaemonTest : public ::testing::Test {
 protected:
  explicit RampedDaemonTest(BaseType base = BaseType::kDifferential)
      : driver_(
            new KinematicDriver(Rover(base), KinematicDriverOptions{.base_max_v = 2, .base_max_omega = 4})),
        daemon_("rover", "kinematic", std::unique_ptr<Driver>(driver_), clock_,
                RobotDaemonOptions{.precise_timing = false}) {
    daemon_.Preallocate(out_);
  }
  struct Twist {
    TimePoint t;
    double v, omega;
  };
  // Runs the daemon to `t`; records the base's twist at every control period.
  std::vector<DaemonOutput::Answer> RunTo(TimePoint t) {
    std::vector<DaemonOutput::Answer> all;
    for (;;) {
      const TimePoint now = clock_.Now();
      const TimePoint next = daemon_.RunOnce(now);
      daemon_.TakeOutput(out_);
      for (auto& a : out_.replies) all.push_back(a);
      for (auto& e : out_.executed) executed_.push_back(e);
      if ((now - kT0) % milliseconds(10) == Duration(0) && (twists_.empty() || twists_.back().t < now)) {
        const RobotState s = State();
        twists_.push_back({now, s.base_v, s.base_omega});
      }
      if (now >= t) break;
      clock_.Set(std::min(next, t));
    }
    return all;
  }
  RobotState State() const {
    RobotState s;
    driver_->ReadState(s);
    return s;
  }
  double V() const { return State().base_v; }
  double Omega() const { return State().base_omega; }
  // The largest |Δv|/Δt and |Δω|/Δt between consecutive control periods.
  std::pair<double, double> MaxAcceleration() const {
    double linear = 0, angular = 0;
    for (std::size_t i = 1; i < twists_.size(); ++i) {
      const double dt = ToSeconds(twists_[i].t - twists_[i - 1].t);
      linear = std::max(linear, std::abs(twists_[i].v - twists_[i - 1].v) / dt);
      angular = std::max(angular, std::abs(twists_[i].omega - twists_[i - 1].omega) / dt);
    }
    return {linear, angular};
  }
  static const Reply* Find(const std::vector<DaemonOutput::Answer>& answers, CommandId id) {
    for (const auto& a : answers) {
      if (a.reply.id == id) return &a.reply;
    }
    return nullptr;
  }

  ManualClock clock_{kT0};
  KinematicDriver* driver_;  // owned by daemon_
  RobotDaemon daemon_;
  DaemonOutput out_;
  std::vector<Twist> twists_;
  std::vector<DaemonOutput::Executed> executed_;
};

// The measurement: a stream of random SETSPEED frames (10 Hz, 300 ms ahead,
// v in ±0.6 m/s, ω in ±1.5 rad/s: up to 12 m/s² between frames), ramped
// (linear) and as steps, then a SETSPEED 0 that brings the base to rest.
class RandomStream : public RampedDaemonTest {
 public:
  void TestBody() override {}
  std::pair<double, double> Run(Interpolation interpolation, int* modified, bool* at_rest) {
    std::mt19937 rng(22);
    std::uniform_real_distribution<double> v(-0.6, 0.6), w(-1.5, 1.5);
    constexpr int kFrames = 100;
    std::vector<DaemonOutput::Answer> answers;
    for (int k = 0; k < kFrames; ++k) {
      const bool last = k == kFrames - 1;
      daemon_.Submit(Speed(k + 1, kT0 + milliseconds(300 + 100 * k), last ? 0 : v(rng), last ? 0 : w(rng),
                           interpolation));
      for (auto& a : RunTo(kT0 + milliseconds(100 * (k + 1)))) answers.push_back(a);
    }
    for (auto& a : RunTo(kT0 + milliseconds(100 * kFrames + 2000))) answers.push_back(a);
    *modified = static_cast<int>(std::count_if(
        answers.begin(), answers.end(), [](const auto& a) { return a.reply.signal == Signal::kModified; }));
    int other = 0;
    for (const auto& a : answers) {
      if (a.reply.signal != Signal::kSuccess && a.reply.signal != Signal::kModified) ++other;
    }
    EXPECT_EQ(other, 0);
    EXPECT_EQ(answers.size(), static_cast<std::size_t>(kFrames));
    *at_rest = V() == 0 && Omega() == 0 && !State().moving;
    return MaxAcceleration();
  }
};

TEST(SpeedRampDaemon, RandomFramesRampWithinTheLimitWhereAStepPackageJumps) {
  int ramp_modified = 0, step_modified = 0;
  bool ramp_rest = false, step_rest = false;
  RandomStream ramped, stepped;
  const auto [ramp_lin, ramp_ang] = ramped.Run(Interpolation::kLinear, &ramp_modified, &ramp_rest);
  const auto [step_lin, step_ang] = stepped.Run(Interpolation::kStep, &step_modified, &step_rest);
  std::printf(
      "largest base acceleration between control periods (10 ms), 100 random frames at 10 Hz:\n"
      "  linear (ramped): %.6g m/s^2, %.6g rad/s^2 (limit %g, %g); %d frames MODIFIED\n"
      "  step:            %.4g m/s^2, %.4g rad/s^2\n",
      ramp_lin, ramp_ang, kLinear, kAngular, ramp_modified, step_lin, step_ang);
  EXPECT_LE(ramp_lin, kLinear * (1 + 1e-9));
  EXPECT_LE(ramp_ang, kAngular * (1 + 1e-9));
  EXPECT_GT(ramp_modified, 0) << "the limit bit (up to 12 m/s² between frames) and the frames said so";
  EXPECT_TRUE(ramp_rest) << "the last frame (SETSPEED 0) brings the base to rest";
  // The same frames as steps: the twist jumps by up to 1.2 m/s in one period.
  EXPECT_GT(step_lin, 10 * kLinear);
  EXPECT_EQ(step_modified, 0);
  EXPECT_TRUE(step_rest);
}

TEST_F(RampedDaemonTest, FramesWithinTheLimitAreMetAtTheirTimesAndInterpolatedLinearlyBetween) {
  // From rest at arrival (t = 0): 0.2 at 300 ms, 0.5 at 500 ms, 0.5 at 700 ms, 0 at 900 ms.
  daemon_.Submit(Speed(1, kT0 + milliseconds(300), 0.2, 0.6));
  daemon_.Submit(Speed(2, kT0 + milliseconds(500), 0.5, 0.0));
  daemon_.Submit(Speed(3, kT0 + milliseconds(700), 0.5, 0.0));
  daemon_.Submit(Speed(4, kT0 + milliseconds(900), 0.0, 0.0));
  std::vector<DaemonOutput::Answer> answers = RunTo(kT0 + milliseconds(150));
  EXPECT_NEAR(V(), 0.1, 1e-12) << "halfway to the first frame";
  EXPECT_NEAR(Omega(), 0.3, 1e-12);
  for (auto& a : RunTo(kT0 + milliseconds(300))) answers.push_back(a);
  EXPECT_NEAR(V(), 0.2, 1e-12);
  for (auto& a : RunTo(kT0 + milliseconds(400))) answers.push_back(a);
  EXPECT_NEAR(V(), 0.35, 1e-12);
  EXPECT_NEAR(Omega(), 0.3, 1e-12);
  for (auto& a : RunTo(kT0 + milliseconds(800))) answers.push_back(a);
  EXPECT_NEAR(V(), 0.25, 1e-12);
  for (auto& a : RunTo(kT0 + milliseconds(1200))) answers.push_back(a);
  EXPECT_EQ(V(), 0.0);
  EXPECT_EQ(Omega(), 0.0);
  for (CommandId id = 1; id <= 4; ++id) {
    const Reply* r = Find(answers, id);
    ASSERT_NE(r, nullptr) << id;
    EXPECT_EQ(r->signal, Signal::kSuccess) << id << ": " << r->message;
    EXPECT_EQ(r->exec_time, kT0 + milliseconds(100 + 200 * static_cast<int>(id))) << id;
  }
  const auto [linear, angular] = MaxAcceleration();
  EXPECT_LE(linear, 2.5 + 1e-9);
  EXPECT_LE(angular, 3.0 + 1e-9);
  // The client that sent the frames owns the base (the watchdog stops it if it vanishes).
  EXPECT_TRUE(std::any_of(executed_.begin(), executed_.end(), [](const DaemonOutput::Executed& e) {
    return e.client_id == kAlice && e.type == CommandType::kSetSpeed;
  }));
}

TEST_F(RampedDaemonTest, ATooSteepFrameIsApproachedAtTheLimitAndAnswersModifiedNamingIt) {
  daemon_.Submit(Speed(1, kT0 + milliseconds(200), 1.0, 0.0));  // 1 m/s in 0.2 s: 5 m/s²
  const auto answers = RunTo(kT0 + milliseconds(250));
  EXPECT_NEAR(V(), 0.75, 1e-9) << "3 m/s² from the arrival";
  const Reply* r = Find(answers, 1);
  ASSERT_NE(r, nullptr);
  EXPECT_EQ(r->signal, Signal::kModified);
  EXPECT_THAT(r->message, HasSubstr("5 m/s²"));
  EXPECT_THAT(r->message, HasSubstr("limit 3 m/s²"));
  EXPECT_THAT(r->message, HasSubstr("0.4 m/s from it at its time"));
  RunTo(kT0 + milliseconds(600));
  EXPECT_DOUBLE_EQ(V(), 1.0) << "reached, and held as a SETSPEED is";
  EXPECT_LE(MaxAcceleration().first, kLinear * (1 + 1e-9));
}

TEST_F(RampedDaemonTest, AStepPackagesSetSpeedStillJumpsAtItsTime) {
  daemon_.Submit(Speed(1, kT0 + milliseconds(500), 0.5, 1.0, Interpolation::kStep));
  const auto before = RunTo(kT0 + milliseconds(490));
  EXPECT_EQ(V(), 0.0) << "a step SETSPEED does not move the base before its time";
  const auto after = RunTo(kT0 + milliseconds(510));
  EXPECT_EQ(V(), 0.5) << "the period after its time runs at it";
  EXPECT_EQ(Omega(), 1.0);
  const Reply* r = Find(after, 1);
  ASSERT_NE(r, nullptr);
  EXPECT_EQ(r->signal, Signal::kSuccess);
}

TEST_F(RampedDaemonTest, AStopEndsTheRampAndTheBaseBrakesAsBefore) {
  daemon_.Submit(Speed(1, kT0 + milliseconds(300), 0.6, 0.0));
  daemon_.Submit(Speed(2, kT0 + milliseconds(600), 0.6, 1.0));
  RunTo(kT0 + milliseconds(200));
  EXPECT_GT(V(), 0.3);
  daemon_.Submit(Now(50, CommandType::kStop));
  const auto answers = RunTo(kT0 + milliseconds(1000));
  for (CommandId id : {1, 2}) {
    const Reply* r = Find(answers, id);
    ASSERT_NE(r, nullptr) << id;
    EXPECT_EQ(r->signal, Signal::kInterrupted) << id;
    EXPECT_EQ(r->message, "SETSPEED: stopped by STOP") << id;
  }
  EXPECT_EQ(V(), 0.0) << "STOP brakes at once (the driver's Stop), as before";
  EXPECT_EQ(Omega(), 0.0);
  EXPECT_FALSE(State().moving);
}

TEST_F(RampedDaemonTest, AGotoEndsTheRamp) {
  daemon_.Submit(Speed(1, kT0 + milliseconds(300), 0.3, 0.0));
  daemon_.Submit(Speed(2, kT0 + milliseconds(600), 0.3, 0.0));
  RunTo(kT0 + milliseconds(100));
  daemon_.Submit(Now(9, CommandType::kGoto, {0.5, 0.0, 0.0}));
  const auto answers = RunTo(kT0 + milliseconds(700));
  for (CommandId id : {1, 2}) {
    const Reply* r = Find(answers, id);
    ASSERT_NE(r, nullptr) << id;
    EXPECT_EQ(r->signal, Signal::kInterrupted) << id;
    EXPECT_EQ(r->message, "SETSPEED: superseded by GOTO 9") << id;
  }
}

TEST_F(RampedDaemonTest, APanicEndsTheRampAndNothingMovesTheBaseAfter) {
  daemon_.Submit(Speed(1, kT0 + milliseconds(300), 0.6, 0.0));
  RunTo(kT0 + milliseconds(100));
  std::vector<QueuedItem> flushed;
  daemon_.Panic(flushed);
  const auto answers = RunTo(kT0 + milliseconds(800));
  EXPECT_EQ(V(), 0.0);
  const Reply* r = Find(answers, 1);
  ASSERT_NE(r, nullptr);
  EXPECT_EQ(r->signal, Signal::kInterrupted);
  EXPECT_EQ(r->message, "SETSPEED: ended by panic");
}

TEST_F(RampedDaemonTest, TheWatchdogsStopOfTheBaseEndsTheRamp) {
  daemon_.Submit(Speed(1, kT0 + milliseconds(300), 0.6, 0.0));
  RunTo(kT0 + milliseconds(100));
  daemon_.QueueStopOnly({}, /*base=*/true);
  const auto answers = RunTo(kT0 + milliseconds(500));
  EXPECT_EQ(V(), 0.0);
  const Reply* r = Find(answers, 1);
  ASSERT_NE(r, nullptr);
  EXPECT_EQ(r->signal, Signal::kInterrupted);
  EXPECT_EQ(r->message, "SETSPEED: stopped: its client vanished");
}

TEST_F(RampedDaemonTest, ALateFramePastItsDeadlineExpiresAndTheBaseComesToRestWithinTheLimit) {
  daemon_.Submit(Speed(1, kT0 + milliseconds(300), 0.6, 0.0));
  RunTo(kT0 + milliseconds(500));
  EXPECT_DOUBLE_EQ(V(), 0.6);
  QueuedItem late = Speed(2, kT0 + milliseconds(200), 0.6, 0.0);
  late.received = kT0 + milliseconds(500);
  late.max_late = milliseconds(100);
  daemon_.Submit(late);
  const auto answers = RunTo(kT0 + milliseconds(550));
  const Reply* r = Find(answers, 2);
  ASSERT_NE(r, nullptr);
  EXPECT_EQ(r->signal, Signal::kInterrupted);
  EXPECT_THAT(r->message, HasSubstr("expired"));
  EXPECT_NEAR(V(), 0.45, 1e-9) << "decelerating at 3 m/s², not driving on at 0.6";
  RunTo(kT0 + milliseconds(900));
  EXPECT_EQ(V(), 0.0);
  EXPECT_LE(MaxAcceleration().first, kLinear * (1 + 1e-9));
}

class FixedBaseDaemonTest : public RampedDaemonTest {
 protected:
  FixedBaseDaemonTest() : RampedDaemonTest(BaseType::kFixed) {}
};

TEST_F(FixedBaseDaemonTest, AFrameOnAFixedBaseAnswersNa) {
  daemon_.Submit(Speed(1, kT0 + milliseconds(300), 0.6, 0.0));
  const auto answers = RunTo(kT0 + milliseconds(400));
  const Reply* r = Find(answers, 1);
  ASSERT_NE(r, nullptr);
  EXPECT_EQ(r->signal, Signal::kNa);
  EXPECT_THAT(r->message, HasSubstr("fixed base"));
}

}  // namespace
}  // namespace robotalk
