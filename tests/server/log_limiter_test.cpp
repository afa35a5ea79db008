// The server log's limiter (log_limiter.h), alone on a manual clock and in a
// ServerDaemon whose driver fails in every Update (issue 19: 231 fault lines
// in 12 s).
#include "log_limiter.h"

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
using ::testing::ElementsAre;
using ::testing::HasSubstr;

TEST(LogLimiter, PrintsARepeatedLineOnceThenOneSummaryPerWindow) {
  LogLimiter limiter(LogLimiterOptions{.lines_per_second = 20, .repeat_window = seconds(10)});
  std::vector<std::string> out;
  TimePoint t{seconds(100)};
  for (int i = 0; i < 1200; ++i, t += milliseconds(10)) limiter.Add("robot 'r': DRIVER FAULT: boom", t, out);
  // 12 s: the first line, the summary of the first 10 s; the last 2 s wait.
  EXPECT_THAT(out, ElementsAre("robot 'r': DRIVER FAULT: boom",
                               "robot 'r': DRIVER FAULT: boom (repeated 999 times in 9.99 s)"));
  limiter.Flush(t, out);
  ASSERT_EQ(out.size(), 3u);
  EXPECT_THAT(out[2], HasSubstr("(repeated 200 times in"));
}

TEST(LogLimiter, ForgetsALineThatStoppedSoItPrintsInFullWhenItComesBack) {
  LogLimiter limiter(LogLimiterOptions{.repeat_window = seconds(10)});
  std::vector<std::string> out;
  const TimePoint t{seconds(100)};
  limiter.Add("a", t, out);
  limiter.Tick(t + seconds(11), out);  // no repeat: no summary, forgotten
  limiter.Add("a", t + seconds(12), out);
  limiter.Add("b", t + seconds(12), out);
  EXPECT_THAT(out, ElementsAre("a", "a", "b"));
}

TEST(LogLimiter, CapsDistinctLinesPerSecondAndSaysHowManyWereSuppressed) {
  LogLimiter limiter(LogLimiterOptions{.lines_per_second = 3});
  std::vector<std::string> out;
  const TimePoint t{seconds(100)};
  for (int i = 0; i < 10; ++i) limiter.Add("line " + std::to_string(i), t, out);
  limiter.Tick(t + seconds(1), out);
  EXPECT_THAT(out,
              ElementsAre("line 0", "line 1", "line 2", "(7 more log lines suppressed in the last second)"));
}

TEST(LogLimiter, RemembersAtMostItsBoundOfDistinctLines) {
  LogLimiter limiter(LogLimiterOptions{.lines_per_second = 1000000, .max_tracked = 2});
  std::vector<std::string> out;
  const TimePoint t{seconds(100)};
  for (int round = 0; round < 2; ++round) {
    for (const char* line : {"a", "b", "c"}) limiter.Add(line, t, out);
  }
  EXPECT_THAT(out, ElementsAre("a", "b", "c", "c")) << "a and b are tracked; c only rate-limited";
}

// A driver whose Update always throws (a broken bus, say).
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
