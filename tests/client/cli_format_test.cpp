// The CLI's pure helpers: durations as people write them, progress bars, JSON.
#include "cli_support.h"
#include "sequence_runner.h"

#include <gtest/gtest.h>

namespace robotalk::cli {
namespace {

TEST(FormatSeconds, DropsTrailingZeros) {
  EXPECT_EQ(FormatSeconds(5.0), "5 s");
  EXPECT_EQ(FormatSeconds(0.25), "0.25 s");
  EXPECT_EQ(FormatSeconds(1.5), "1.5 s");
  EXPECT_EQ(FormatSeconds(0.0), "0 s");
  EXPECT_EQ(FormatSeconds(2.0004), "2 s");  // milliseconds are enough
}

TEST(TidyDurations, RewritesPrintfSecondsInsideMessages) {
  EXPECT_EQ(TidyDurations("GOTO (id 3): no reply within 5.000000 s"), "GOTO (id 3): no reply within 5 s");
  EXPECT_EQ(TidyDurations("waited 0.500000 s, then 1.250000 s"), "waited 0.5 s, then 1.25 s");
  EXPECT_EQ(TidyDurations("nothing to change: 5 s, 3.5 sec"), "nothing to change: 5 s, 3.5 sec");
}

TEST(ProgressBar, FillsWithTheLaterOfTimeAndAnsweredFrames) {
  EXPECT_EQ(
      ProgressBar({.answered = 0, .total = 4, .elapsed = FromSeconds(1), .duration = FromSeconds(4)}, 8),
      "[##......] 0/4  1.0 s / 4 s");
  EXPECT_EQ(
      ProgressBar({.answered = 4, .total = 4, .elapsed = FromSeconds(1), .duration = FromSeconds(4)}, 8),
      "[########] 4/4  1.0 s / 4 s");
  // Before offset 0 (delay mode's lead) the clock shows 0.
  EXPECT_EQ(
      ProgressBar({.answered = 0, .total = 1, .elapsed = FromSeconds(-0.5), .duration = FromSeconds(2)}, 4),
      "[....] 0/1  0.0 s / 2 s");
}

TEST(Json, EscapesStringsAndWritesNullForNonFiniteNumbers) {
  EXPECT_EQ(JsonString("a\"b\\c\n"), "\"a\\\"b\\\\c\\u000a\"");
  EXPECT_EQ(JsonNumber(0.5), "0.5");
  EXPECT_EQ(JsonNumber(std::numeric_limits<double>::quiet_NaN()), "null");
  Reply r{.id = 7, .signal = Signal::kModified, .message = "clamped", .values = {1, 2}};
  const std::string j = ReplyJson(r);
  EXPECT_NE(j.find("\"id\":7"), std::string::npos);
  EXPECT_NE(j.find("\"signal\":\"MODIFIED\""), std::string::npos);
  EXPECT_NE(j.find("\"values\":[1,2]"), std::string::npos);
}

}  // namespace
}  // namespace robotalk::cli
