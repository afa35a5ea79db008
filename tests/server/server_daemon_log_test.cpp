// The server log's limiter (robotalk/log_limiter.h, its own tests in
// tests/core/log_limiter_test.cpp) in a ServerDaemon whose driver fails in
// every Update (issue 19: 231 fault lines in 12 s).
#include "robotalk/log_limiter.h"

#include "fake_driver.h"
#include "robot_daemon.h"
#include "robotalk/memory_transport.h"
#include "server_daemon.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <sstream>

namespace robotalk {
namespace {

using std::chrono::milliseconds;
using std::chrono::seconds;
using ::testing::HasSubstr;

class FailingUpdateDriver final : public testing::FakeDriver {
 public:
  using FakeDriver::FakeDriver;
  void Update(TimePoint, std::vector<Completion>&) override { throw std::runtime_error("CAN bus timeout"); }
};

TEST(ServerDaemonLog, ADriverFailingInEveryUpdateLogsItsFaultOnceAndThenASummary) {
  ManualClock clock;
  auto bus = std::make_shared<MemoryBus>();
  MemoryTransport transport(bus);
  RobotDaemon robot("bot", "fake", std::make_unique<FailingUpdateDriver>(testing::PanRobot()), clock);
  ::testing::internal::CaptureStderr();
  {
    ServerDaemon server(transport, clock, ServerDaemonOptions{.server_id = 7, .fifo_priority = 0});
    server.AddRobot(robot, SessionOptions{});
    const TimePoint end = clock.Now() + seconds(12);
    while (clock.Now() < end) {  // the driver's 10 ms period
      robot.RunOnce(clock.Now());
      server.RunOnce(Duration(0));
      clock.Advance(milliseconds(10));
    }
  }
  const std::string log = ::testing::internal::GetCapturedStderr();
  std::istringstream lines(log);
  std::vector<std::string> faults;
  for (std::string line; std::getline(lines, line);) {
    if (line.find("DRIVER FAULT") != std::string::npos) faults.push_back(line);
  }
  ASSERT_FALSE(faults.empty()) << log;
  EXPECT_LE(faults.size(), 3u) << log;
  EXPECT_THAT(faults[0], HasSubstr("driver 'fake' threw in Update: CAN bus timeout"));
  EXPECT_THAT(faults[1], HasSubstr("(repeated "));
  EXPECT_TRUE(robot.in_panic());
}

}  // namespace
}  // namespace robotalk
