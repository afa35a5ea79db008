// Issue 22, end to end on the ODE driver: a RobotDaemon (ManualClock,
// in-process) runs the ODE iiwa14 while a delay-mode client streams a
// 0.5 Hz, 0.5 rad sine on one joint at 100 Hz frames, 300 ms ahead. With
// quintic interpolation the server hands the driver a reference (position,
// velocity, acceleration) every period and the ODE servos track it with
// velocity feed-forward; the measured joint must stay within 0.01 rad of the
// continuous sine. The same stream as step set-points (the default, and every
// protocol-3 client) behaves as before: a servo chasing steps, lagging by
// about kp⁻¹ · velocity (docs/performance.md, "Trajectories (issue 22)").
#include "ode_driver.h"
#include "robotalk/urdf_import.h"
#include "support/sine_stream.h"
#include "test_paths.h"

#include <gtest/gtest.h>

namespace robotalk {
namespace {

using testing::RunSineStream;
using testing::SharedRobot;
using testing::SineResult;
using testing::SineStream;

// iiwa_joint_6: a bending joint (it carries the wrist against gravity) whose
// URDF velocity limit, 2.36 rad/s, the sine's peak velocity (0.5·π = 1.57
// rad/s) respects; its peak acceleration (4.9 rad/s²) is within the server's
// default limit (20 rad/s²), so the reference is the plan, unmodified.
constexpr char kJoint[] = "iiwa_joint_6";

std::unique_ptr<Driver> OdeIiwa() {
  DriverRegistry registry;
  RegisterOdeDriver(registry);
  return registry.Create("ode", DriverConfig{.robot_name = "", .urdf_path = SharedRobot("iiwa14.urdf")});
}

SineResult StreamSine(Interpolation interpolation) {
  auto driver = OdeIiwa();
  SineStream s;
  s.joint = driver->model().JointIndex(kJoint);
  s.interpolation = interpolation;
  s.frame_hz = 100;
  s.seconds = 4;
  return RunSineStream(std::move(driver), s);
}

TEST(OdeTrackingTest, AQuinticSineAt100HzFramesIsTrackedWithinACentiradian) {
  ROBOTALK_REQUIRE_SHARED_ROBOTS();
  const SineResult r = StreamSine(Interpolation::kQuintic);
  ASSERT_GT(r.samples, 250) << "the measurement did not run";
  EXPECT_LE(r.max_error, 0.01) << "RMS " << r.rms_error;
  // The server's reference is the sine up to the interpolation's error
  // (and the limits': the first waypoint is reached from rest).
  EXPECT_LT(r.max_ref_error, 0.005);
  // Every waypoint is passed: SUCCESS, or MODIFIED naming a limit; none refused or interrupted.
  EXPECT_EQ(r.other, 0) << r.last_note;
  EXPECT_EQ(r.succeeded + r.modified, 401);
}

TEST(OdeTrackingTest, TheSameStreamAsStepSetPointsStillLagsAsBefore) {
  ROBOTALK_REQUIRE_SHARED_ROBOTS();
  const SineResult step = StreamSine(Interpolation::kStep);
  ASSERT_GT(step.samples, 250);
  EXPECT_EQ(step.other, 0);
  // A first-order servo (kp = 20/s) chasing steps: the lag error is about
  // peak velocity / kp = 1.57 / 20 = 0.08 rad; well above the quintic bound.
  EXPECT_GT(step.max_error, 0.05);
  EXPECT_LT(step.max_error, 0.2);
}

}  // namespace
}  // namespace robotalk
