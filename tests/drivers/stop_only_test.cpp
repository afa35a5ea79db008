// Driver::StopOnly on both shipped drivers (issue 19, item 1): the
// watchdog's stop of what one vanished client owned. The base's part
// interrupts a GOTO although SETSPEED is refused with BUSY during it; a
// joint's part leaves the base (another client's GOTO) running; what is not
// in the scope runs on. The walking humanoid's walk stops as the base.
#include "kinematic_driver.h"
#include "ode_driver.h"
#include "robotalk/urdf_import.h"
#include "test_paths.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <string>
#include <vector>

namespace robotalk {
namespace {

using std::chrono::milliseconds;
using std::chrono::seconds;
using ::testing::HasSubstr;
using testing::ProjectModel;

bool Accepted(const DriverResult& r) { return r.signal == Signal::kSuccess || r.signal == Signal::kModified; }

// One driver of the registry on the Pioneer, stepped one period at a time.
class StopOnlyTest : public ::testing::TestWithParam<std::string> {
 protected:
  StopOnlyTest() {
    DriverRegistry registry;
    RegisterKinematicDriver(registry);
    RegisterOdeDriver(registry);
    driver_ = registry.Create(
        GetParam(),
        DriverConfig{.robot_name = "p", .urdf_path = ProjectModel("pioneer2dx_pantilt.urdf"), .options = {}});
    const RobotModel& m = driver_->model();
    pan_ = m.JointIndex("pan");
    for (Eigen::VectorXd* v : {&state_.position, &state_.velocity, &state_.effort}) v->setZero(m.num_dofs());
    state_.root_poses.resize(m.roots().size());
    driver_->Update(now_, done_);
  }
  DriverResult Exec(CommandId id, CommandType type, std::vector<double> values, int target = -1) {
    DriverCommand c{.id = id, .type = type, .target = target, .num_values = static_cast<int>(values.size())};
    for (std::size_t k = 0; k < values.size(); ++k) c.values[k] = values[k];
    return driver_->Execute(c, now_, done_);
  }
  void Advance(Duration d) {
    for (const TimePoint end = now_ + d; now_ < end;) {
      now_ += milliseconds(10);
      driver_->Update(now_, done_);
    }
  }
  void StopOnly(std::vector<int> joints, bool base) {
    driver_->StopOnly(StopScope{.joints = joints, .base = base}, now_, done_);
  }
  const RobotState& State() {
    driver_->ReadState(state_);
    return state_;
  }
  double Pan() { return State().position[driver_->model().dof_offset(pan_)]; }
  double X() { return State().root_poses[0].translation.x(); }

  std::unique_ptr<Driver> driver_;
  int pan_ = -1;
  RobotState state_;
  std::vector<Completion> done_;
  TimePoint now_{seconds(100)};
};

TEST_P(StopOnlyTest, TheBasePartInterruptsAGotoAndLeavesAnotherClientsJointMoving) {
  ASSERT_TRUE(Exec(1, CommandType::kGoto, {6, 0, 0}).in_progress);
  Advance(seconds(2));
  EXPECT_EQ(Exec(2, CommandType::kSetSpeed, {0, 0}).signal, Signal::kBusy) << "as the watchdog's hold met it";
  ASSERT_TRUE(Accepted(Exec(3, CommandType::kJointSpeed, {0.5}, pan_)));
  Advance(milliseconds(200));
  const double x_moving = X();
  EXPECT_GT(x_moving, 0.3) << "driving to x = 6";
  StopOnly({}, true);
  ASSERT_EQ(done_.size(), 1u);
  EXPECT_EQ(done_[0].id, 1);
  EXPECT_EQ(done_[0].signal, Signal::kInterrupted);
  EXPECT_THAT(done_[0].message, HasSubstr("GOTO"));
  Advance(milliseconds(500));  // the ode base brakes on physics
  const double x_stopped = X(), pan = Pan();
  EXPECT_LT(x_stopped - x_moving, 0.2);
  Advance(seconds(1));
  EXPECT_NEAR(X(), x_stopped, 0.01) << "the base stays stopped";
  EXPECT_GT(Pan(), pan + 0.3) << "the pan's speed command runs on";
}

TEST_P(StopOnlyTest, AJointPartStopsThatJointAndLeavesAnotherClientsGotoRunning) {
  ASSERT_TRUE(Exec(1, CommandType::kGoto, {6, 0, 0}).in_progress);
  ASSERT_TRUE(Accepted(Exec(2, CommandType::kJointSpeed, {0.5}, pan_)));
  Advance(seconds(1));
  StopOnly({pan_}, false);
  Advance(milliseconds(300));
  const double pan = Pan(), x = X();
  Advance(seconds(1));
  EXPECT_NEAR(Pan(), pan, 0.01) << "the pan stays stopped";
  EXPECT_GT(X(), x + 0.3) << "the GOTO drives on";
  EXPECT_TRUE(done_.empty()) << "nothing interrupted";
}

INSTANTIATE_TEST_SUITE_P(BothDrivers, StopOnlyTest, ::testing::Values("kinematic", "ode"));

TEST(StopOnlyWalk, TheBasePartStopsTheHumanoidsWalkAndInterruptsItsGoto) {
  DriverRegistry registry;
  RegisterOdeDriver(registry);
  auto created = registry.Create("ode", DriverConfig{.robot_name = "",
                                                     .urdf_path = ProjectModel("simple_humanoid.urdf"),
                                                     .options = {{"walk", "true"}, {"seed", "7"}}});
  auto& walker = static_cast<OdeDriver&>(*created);
  ASSERT_TRUE(walker.walk_status().has_value());
  std::vector<Completion> done;
  walker.Step(1000, done);
  DriverCommand go{.id = 1, .type = CommandType::kGoto, .num_values = 3};
  go.values = {1.5, 0, 0};
  ASSERT_TRUE(walker.Execute(go, walker.sim_time(), done).in_progress);
  walker.Step(3000, done);
  ASSERT_TRUE(walker.walk_status()->stepping);
  DriverCommand speed{.id = 2, .type = CommandType::kSetSpeed, .num_values = 2};
  EXPECT_EQ(walker.Execute(speed, walker.sim_time(), done).signal, Signal::kBusy);
  const int steps = walker.walk_status()->steps_taken;
  walker.StopOnly(StopScope{.joints = {}, .base = true}, walker.sim_time(), done);
  ASSERT_EQ(done.size(), 1u);
  EXPECT_EQ(done[0].signal, Signal::kInterrupted);
  for (int i = 0; i < 50 && walker.walk_status()->stepping; ++i) walker.Step(100, done);
  EXPECT_FALSE(walker.walk_status()->stepping) << "the walk ended";
  EXPECT_LE(walker.walk_status()->steps_taken - steps, 2);
  EXPECT_FALSE(walker.walk_status()->fallen);
}

}  // namespace
}  // namespace robotalk
