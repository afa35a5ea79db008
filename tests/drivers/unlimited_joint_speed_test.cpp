// Review (session 6): a joint whose URDF gives no velocity limit (a
// continuous joint without <limit>). docs/ode_sim.md promises `default_velocity`
// is the "speed limit of dofs whose limit is infinite"; a JOINT_SET_POINT
// honours it (the servo's velocity is clamped to it), but JOINT_SPEED clamped
// only to the model's limit, infinity, so any finite speed ran as asked.
#include "ode_driver.h"

#include <gtest/gtest.h>

#include <unistd.h>
#include <cmath>
#include <filesystem>
#include <fstream>

namespace robotalk {
namespace {

using namespace std::chrono_literals;

// A fixed post and a disc on a continuous joint without <limit>.
constexpr const char* kUrdf = R"(<?xml version="1.0"?>
<robot name="spinner">
  <link name="post">
    <inertial><mass value="5"/><inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial>
  </link>
  <link name="disc">
    <inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>
  </link>
  <joint name="spin" type="continuous">
    <parent link="post"/><child link="disc"/>
    <origin xyz="0 0 1"/><axis xyz="0 0 1"/>
  </joint>
</robot>
)";

class UnlimitedJointSpeedTest : public ::testing::Test {
 protected:
  void SetUp() override {
    path_ =
        std::filesystem::temp_directory_path() / ("robotalk_spinner_" + std::to_string(::getpid()) + ".urdf");
    std::ofstream(path_) << kUrdf;
    DriverRegistry registry;
    RegisterOdeDriver(registry);
    driver_ = registry.Create(
        "ode", DriverConfig{.robot_name = "", .urdf_path = path_.string(), .options = {{"base", "fixed"}}});
    driver_->Update(t_, done_);
  }
  void TearDown() override { std::filesystem::remove(path_); }

  DriverResult Speed(double v) {
    DriverCommand c;
    c.id = 1;
    c.type = CommandType::kJointSpeed;
    c.target = driver_->model().JointIndex("spin");
    c.num_values = 1;
    c.values[0] = v;
    return driver_->Execute(c, t_, done_);
  }
  double Run(double seconds) {  // the largest |velocity| seen
    double fastest = 0;
    for (int i = 0; i < std::lround(seconds / 0.01); ++i) {
      t_ += 10ms;
      driver_->Update(t_, done_);
      RobotState s;
      driver_->ReadState(s);
      fastest = std::max(fastest, std::abs(s.velocity[0]));
    }
    return fastest;
  }

  std::filesystem::path path_;
  std::unique_ptr<Driver> driver_;
  TimePoint t_{std::chrono::seconds(100)};
  std::vector<Completion> done_;
};

TEST_F(UnlimitedJointSpeedTest, AJointSpeedIsClampedToTheDefaultVelocityAndSaysSo) {
  const DriverResult r = Speed(50);
  EXPECT_EQ(r.signal, Signal::kModified) << r.message;
  EXPECT_NE(r.message.find("clamped to the velocity limit 1"), std::string::npos) << r.message;
  EXPECT_LE(Run(2.0), 1.0 * 1.05) << "the disc spun faster than default_velocity (1 rad/s)";
}

}  // namespace
}  // namespace robotalk
