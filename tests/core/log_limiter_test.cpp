// The log limiter (robotalk/log_limiter.h) alone on a manual clock; the
// server's use of it is tests/server/server_daemon_log_test.cpp.
#include "robotalk/log_limiter.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <string>
#include <vector>

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

}  // namespace
}  // namespace robotalk
