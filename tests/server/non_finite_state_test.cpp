// A driver reporting a non-finite state (issue 19: `query` answered
// "SUCCESS nan 0 0" while `watch` printed nothing). It is a driver fault: the
// robot is halted and held in panic, queries answer ERROR naming the value,
// and the state stream keeps coming, in panic, with what the driver said.
#include "robot_daemon.h"

#include "daemon_fixture.h"
#include "fake_driver.h"
#include "queued_items.h"
#include "robotalk/request.h"
#include "state_encoding.h"
#include "support/test_clients.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace robotalk {
namespace {

using std::chrono::milliseconds;
using ::testing::HasSubstr;

using testing::kAlice;

// A broken encoder: the pan joint's position (or the base's x) is NaN.
class BrokenSensorDriver final : public testing::FakeDriver {
 public:
  using FakeDriver::FakeDriver;
  void ReadState(RobotState& s) const override {
    FakeDriver::ReadState(s);
    if (nan_position) s.position[0] = std::nan("");
    if (inf_base_x) s.root_poses[0].translation.x() = std::numeric_limits<double>::infinity();
    if (throw_on_read) throw std::runtime_error("encoder bus timeout");
    if (lose_root) s.root_poses.clear();
  }
  bool nan_position = false;
  bool inf_base_x = false;
  bool throw_on_read = false;
  bool lose_root = false;  // a driver's bug: a state of the wrong shape
};

// A waypoint of an interpolated package for the pan joint (0), due at `at`.
QueuedItem Waypoint(CommandId id, TimePoint at, double q) { return testing::Waypoint(id, 0, at, {q}); }

// A finite state that fits PanRobot: one dof, one root, all zeros.
RobotState FittingState() {
  RobotState s;
  s.position = s.velocity = s.effort = Eigen::VectorXd::Zero(1);
  s.root_poses.resize(1);
  return s;
}

class NonFiniteStateTest : public testing::DaemonOnManualClock<BrokenSensorDriver> {};

TEST(NonFiniteState, NamesTheJointAndDofOrTheBaseField) {
  const RobotModel model = testing::PanRobot();
  RobotState s = FittingState();
  EXPECT_EQ(NonFiniteState(model, s), std::nullopt);
  s.velocity[0] = -std::numeric_limits<double>::infinity();
  EXPECT_EQ(NonFiniteState(model, s), "joint 'pan' dof 0 velocity is -inf");
  s.velocity[0] = 0;
  s.root_poses[0].translation.y() = std::nan("");
  EXPECT_EQ(NonFiniteState(model, s), "root 'base' y is NaN");
  s.root_poses[0].translation.y() = 0;
  s.base_v = std::nan("");
  EXPECT_EQ(NonFiniteState(model, s), "base v is NaN");
}

TEST_F(NonFiniteStateTest, HaltsTheRobotInPanicNamingTheValueEvenWhenNobodyReadsTheState) {
  Run();
  EXPECT_FALSE(daemon_->in_panic());
  fake_->nan_position = true;
  clock_.Advance(milliseconds(10));  // the driver's next period
  Run();
  EXPECT_TRUE(daemon_->in_panic());
  EXPECT_TRUE(fake_->halted);
  EXPECT_THAT(daemon_->fault(),
              HasSubstr("driver 'fake' reports a non-finite state: joint 'pan' dof 0 position is NaN"));
  ASSERT_FALSE(out_.log.empty());
  EXPECT_THAT(out_.log.front(), HasSubstr("DRIVER FAULT"));
}

TEST_F(NonFiniteStateTest, AQueryAnswersErrorNamingTheNonFiniteValue) {
  fake_->inf_base_x = true;
  Run();
  clock_.Advance(milliseconds(1));
  daemon_->Submit(testing::StateQuery(7, QueryType::kBasePose));
  const auto replies = Run();
  ASSERT_EQ(replies.size(), 1u);
  EXPECT_EQ(replies[0].reply.signal, Signal::kError);
  EXPECT_THAT(replies[0].reply.message,
              HasSubstr("BASE_POSE: driver 'fake' reports a non-finite state: root 'base' x is +inf"));
  EXPECT_TRUE(replies[0].reply.values.empty());
  // A reset with the sensor still broken: halted again at the next read.
  EXPECT_TRUE(daemon_->ResetPanic());
  clock_.Advance(milliseconds(10));
  Run();
  EXPECT_TRUE(daemon_->in_panic());
}

TEST_F(NonFiniteStateTest, TheStateStreamSaysPanicAndCarriesTheValueAClientDecodes) {
  daemon_->SetStream(kAlice, milliseconds(10));
  fake_->nan_position = true;
  Run();
  clock_.Advance(milliseconds(10));
  Run();
  ASSERT_GE(out_.num_samples, 1u);
  const RobotSample& sample = out_.samples[out_.num_samples - 1];
  EXPECT_TRUE(sample.panic);
  const StateSample decoded = DecodeStateSample(EncodeStateSample(ToStateSample("bot", 1, sample)));
  EXPECT_TRUE(decoded.panic);
  ASSERT_EQ(decoded.positions.size(), 1u);
  EXPECT_TRUE(std::isnan(decoded.positions[0])) << "watch prints it: nan, PANIC";
}

// Waypoints arriving in the period the sensor breaks (or its read throws):
// the trajectory would start from the broken state. Each is answered once,
// INTERRUPTED by the panic, and the RobotDaemon keeps running (it ended its
// thread: the Trajectory refused the NaN start by throwing).
void ExpectEachAnsweredOnceInterrupted(const std::vector<DaemonOutput::Answer>& replies,
                                       std::initializer_list<CommandId> ids, const std::string& why) {
  for (CommandId id : ids) {
    const auto n = std::count_if(replies.begin(), replies.end(),
                                 [id](const DaemonOutput::Answer& a) { return a.reply.id == id; });
    EXPECT_EQ(n, 1) << "waypoint " << id;
  }
  for (const DaemonOutput::Answer& a : replies) {
    EXPECT_EQ(a.reply.signal, Signal::kInterrupted) << a.reply.message;
    EXPECT_THAT(a.reply.message, HasSubstr(why));
  }
}

TEST_F(NonFiniteStateTest, WaypointsArrivingAsTheSensorBreaksAreInterruptedOnceAndTheDaemonRuns) {
  Run();
  fake_->nan_position = true;
  clock_.Advance(milliseconds(10));
  daemon_->Submit(Waypoint(1, clock_.Now() + milliseconds(500), 0.3));
  daemon_->Submit(Waypoint(2, clock_.Now() + milliseconds(900), 0.5));
  std::vector<DaemonOutput::Answer> replies = Run();
  EXPECT_TRUE(daemon_->in_panic());
  for (int i = 0; i < 100; ++i) {  // past both waypoints' times: nothing more
    clock_.Advance(milliseconds(10));
    const auto more = Run();
    replies.insert(replies.end(), more.begin(), more.end());
  }
  ExpectEachAnsweredOnceInterrupted(replies, {1, 2}, "joint 'pan' dof 0 position is NaN");
}

TEST_F(NonFiniteStateTest, WaypointsArrivingWhenTheDriverCannotReadItsStateAreInterruptedOnce) {
  Run();
  fake_->throw_on_read = true;
  clock_.Advance(milliseconds(1));  // within the period: read only for the waypoints
  daemon_->Submit(Waypoint(1, clock_.Now() + milliseconds(500), 0.3));
  std::vector<DaemonOutput::Answer> replies = Run();
  EXPECT_TRUE(daemon_->in_panic());
  for (int i = 0; i < 100; ++i) {
    clock_.Advance(milliseconds(10));
    const auto more = Run();
    replies.insert(replies.end(), more.begin(), more.end());
  }
  ExpectEachAnsweredOnceInterrupted(replies, {1}, "threw in ReadState: encoder bus timeout");
}

TEST(NonFiniteState, AStateOfTheWrongShapeIsNamed) {
  const RobotModel model = testing::PanRobot();
  RobotState s = FittingState();
  EXPECT_EQ(MisfitState(model, s), std::nullopt);
  s.velocity.resize(0);
  EXPECT_EQ(MisfitState(model, s), "velocity has 0 values, the model has 1 dofs");
  s.velocity = Eigen::VectorXd::Zero(1);
  s.root_poses.clear();
  EXPECT_EQ(MisfitState(model, s), "root_poses has 0 poses, the model has 1 roots");
}

// A driver whose state lost its root pose (every later read of it would run
// past the end): a fault naming the misfit, queries answer ERROR, samples stop
// (nothing of it can be sent), and waypoints are interrupted once.
TEST_F(NonFiniteStateTest, AStateThatDoesNotFitTheModelHaltsTheRobotAndIsNeverRead) {
  daemon_->SetStream(kAlice, milliseconds(10));
  Run();
  const std::size_t samples_before = out_.num_samples;
  EXPECT_GE(samples_before, 1u);
  fake_->lose_root = true;
  clock_.Advance(milliseconds(10));
  daemon_->Submit(Waypoint(1, clock_.Now() + milliseconds(500), 0.3));
  daemon_->Submit(testing::StateQuery(2, QueryType::kBasePose));
  std::vector<DaemonOutput::Answer> replies = Run();
  EXPECT_TRUE(daemon_->in_panic());
  EXPECT_THAT(daemon_->fault(), HasSubstr("driver 'fake' reports a state that does not fit the model: "
                                          "root_poses has 0 poses, the model has 1 roots"));
  EXPECT_EQ(out_.num_samples, 0u);
  ASSERT_EQ(replies.size(), 2u);
  for (const auto& a : replies) {
    if (a.reply.id == 1) {
      EXPECT_EQ(a.reply.signal, Signal::kInterrupted) << a.reply.message;
    } else {
      EXPECT_EQ(a.reply.signal, Signal::kError) << a.reply.message;
      EXPECT_THAT(a.reply.message, HasSubstr("does not fit the model"));
    }
  }
}

}  // namespace
}  // namespace robotalk
