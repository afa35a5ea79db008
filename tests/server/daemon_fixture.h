// One RobotDaemon ("bot") over a scripted driver made from PanRobot(), on a
// manual clock, without threads or a transport: the fixture of the
// RobotDaemon's own tests (robot_daemon_test.cpp, driver_faults_test.cpp,
// non_finite_state_test.cpp). A test fixture derives from it; `Base` is
// ::testing::Test or a TestWithParam.
#pragma once

#include "fake_driver.h"
#include "robot_daemon.h"

#include <gtest/gtest.h>

#include <memory>
#include <utility>
#include <vector>

namespace robotalk::testing {

/// `D`: FakeDriver or a class derived from it, constructible from a RobotModel.
template <class D = FakeDriver, class Base = ::testing::Test>
class DaemonOnManualClock : public Base {
 protected:
  explicit DaemonOnManualClock(RobotDaemonOptions options = {}) {
    auto driver = std::make_unique<D>(PanRobot());
    fake_ = driver.get();
    daemon_ = std::make_unique<RobotDaemon>("bot", "fake", std::move(driver), clock_, std::move(options));
    daemon_->Preallocate(out_);
  }
  /// Runs the RobotDaemon once at the clock's time and takes its output
  /// (out_); returns its replies.
  std::vector<DaemonOutput::Answer> Run() {
    daemon_->RunOnce(clock_.Now());
    daemon_->TakeOutput(out_);
    return out_.replies;
  }

  ManualClock clock_;
  D* fake_ = nullptr;  // owned by daemon_
  std::unique_ptr<RobotDaemon> daemon_;
  DaemonOutput out_;
};

}  // namespace robotalk::testing
