// One ServerDaemon serving "bot" and "arm" (FakeDriver, PanRobot) on an
// in-memory bus and a manual clock, without threads or sockets, and
// `client_`: anyone else on that bus. For the ServerDaemon tests that drive
// it with bytes (server_daemon_test.cpp, announce_conflict_test.cpp); a test
// adds its own subscriptions on `client_`.
#pragma once

#include "fake_driver.h"
#include "robotalk/memory_transport.h"
#include "server_daemon.h"

#include <gtest/gtest.h>

#include <map>
#include <memory>
#include <string>
#include <vector>

namespace robotalk::testing {

class TwoRobotServerTest : public ::testing::Test {
 protected:
  TwoRobotServerTest() : server_transport_(bus_), client_(bus_) {
    for (const char* name : {"bot", "arm"}) {
      auto driver = std::make_unique<FakeDriver>(PanRobot());
      fakes_[name] = driver.get();
      robots_.push_back(std::make_unique<RobotDaemon>(name, "fake", std::move(driver), clock_));
    }
    server_ = std::make_unique<ServerDaemon>(server_transport_, clock_, ServerDaemonOptions{.server_id = 42});
    for (auto& r : robots_) server_->AddRobot(*r, SessionOptions{});
  }

  // One ServerDaemon iteration, every RobotDaemon once, another ServerDaemon
  // iteration to send what they produced, then the client reads.
  void Step() {
    server_->RunOnce(Duration(0));
    for (auto& r : robots_) r->RunOnce(clock_.Now());
    server_->RunOnce(Duration(0));
    client_.HandleFor(Duration(0));
  }

  ManualClock clock_;
  std::shared_ptr<MemoryBus> bus_ = std::make_shared<MemoryBus>();
  MemoryTransport server_transport_;
  MemoryTransport client_;
  std::map<std::string, FakeDriver*> fakes_;
  std::vector<std::unique_ptr<RobotDaemon>> robots_;
  std::unique_ptr<ServerDaemon> server_;
};

}  // namespace robotalk::testing
