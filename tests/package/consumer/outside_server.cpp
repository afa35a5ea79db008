// A robot server written outside the RoboTalk tree, as a hardware developer
// would: two drivers of its own registered beside the shipped kinematic one,
// and the whole robotalk-server command line from ServerMain().
#include <kinematic_driver.h>
#include <robotalk/server_main.h>
#include <robotalk/urdf_import.h>

#include <stdexcept>

namespace {

// Holds every joint where it was last told, at once.
class HoldingArm : public robotalk::Driver {
 public:
  explicit HoldingArm(robotalk::RobotModel model)
      : model_(std::move(model)), q_(Eigen::VectorXd::Zero(model_.num_dofs())) {}
  const robotalk::RobotModel& model() const override { return model_; }
  robotalk::Duration period() const override { return std::chrono::milliseconds(10); }
  robotalk::DriverResult Execute(const robotalk::DriverCommand& c, robotalk::TimePoint,
                                 std::vector<robotalk::Completion>&) override {
    if (c.type != robotalk::CommandType::kJointSetPoint)
      return {robotalk::Signal::kNa, false, "set-points only"};
    for (int k = 0; k < c.num_values; ++k)
      q_[model_.dof_offset(c.target) + k] = c.values[static_cast<size_t>(k)];
    return {};
  }
  void Stop(robotalk::TimePoint, std::vector<robotalk::Completion>&) override {}
  void Update(robotalk::TimePoint, std::vector<robotalk::Completion>&) override {}
  void ReadState(robotalk::RobotState& s) const override { s.position = q_; }
  void Halt(std::vector<robotalk::Completion>&) override {}
  void Resume() override {}

 private:
  robotalk::RobotModel model_;
  Eigen::VectorXd q_;
};

// A driver whose hardware fails: every command throws.
class FailingArm : public HoldingArm {
 public:
  using HoldingArm::HoldingArm;
  robotalk::DriverResult Execute(const robotalk::DriverCommand&, robotalk::TimePoint,
                                 std::vector<robotalk::Completion>&) override {
    throw std::runtime_error("serial port write failed");
  }
};

}  // namespace

int main(int argc, char** argv) {
  robotalk::DriverRegistry registry;
  robotalk::RegisterKinematicDriver(registry);
  registry.Register("holding_arm", [](const robotalk::DriverConfig& c) {
    return std::make_unique<HoldingArm>(robotalk::LoadUrdfFile(c.urdf_path).model);
  });
  registry.Register("failing_arm", [](const robotalk::DriverConfig& c) {
    return std::make_unique<FailingArm>(robotalk::LoadUrdfFile(c.urdf_path).model);
  });
  return robotalk::ServerMain(argc, argv, registry);
}
