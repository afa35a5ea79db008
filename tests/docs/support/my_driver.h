// What docs/drivers.md's snippets leave to the reader: a driver class
// (MyDriver) and a factory (MakeMyArm). Force-included by
// doc_snippets_test.sh into the snippets whose marker says include=my_driver.h.
#pragma once

#include <robotalk/driver.h>
#include <robotalk/urdf_import.h>

#include <memory>
#include <vector>

class MyDriver : public robotalk::Driver {
 public:
  explicit MyDriver(const robotalk::DriverConfig& config)
      : model_(robotalk::LoadUrdfFile(config.urdf_path).model) {}
  const robotalk::RobotModel& model() const override { return model_; }
  robotalk::Duration period() const override { return std::chrono::milliseconds(10); }
  robotalk::DriverResult Execute(const robotalk::DriverCommand&, robotalk::TimePoint,
                                 std::vector<robotalk::Completion>&) override {
    return {robotalk::Signal::kNa, false, "nothing to move"};
  }
  void Stop(robotalk::TimePoint, std::vector<robotalk::Completion>&) override {}
  void Update(robotalk::TimePoint, std::vector<robotalk::Completion>&) override {}
  void ReadState(robotalk::RobotState&) const override {}
  void Halt(std::vector<robotalk::Completion>&) override {}
  void Resume() override {}

 private:
  robotalk::RobotModel model_;
};

inline std::unique_ptr<robotalk::Driver> MakeMyArm(const robotalk::DriverConfig& config) {
  return std::make_unique<MyDriver>(config);
}
