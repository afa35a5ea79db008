// The CLI's pure helpers: durations as people write them, progress bars, JSON.
#include "cli_commands.h"
#include "cli_support.h"
#include "sequence_runner.h"

#include <gtest/gtest.h>

#include <limits>
#include <sstream>

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

// Review 12: a reply's message is the server's text (in open mode, anyone's
// who forges a reply): `robotalk send` printed it quoted but raw, so a line
// break forged a second reply line for the scripts that read them, and a
// terminal escape (C0, or C1 CSI encoded in UTF-8) reached the terminal.
// Control characters are now written \xNN; UTF-8 text is kept.
TEST(PrintReply, WritesTheMessagesControlCharactersEscapedOnOneLine) {
  std::ostringstream out;
  PrintReply(Reply{.id = 7,
                   .signal = Signal::kError,
                   .message = "unknown joint '\xc3\xa4'\n8 SUCCESS \"\"\x1b]0;owned\x07\xc2\x9b"
                              "2J"},
             out);
  EXPECT_EQ(out.str(),
            "7 ERROR \"unknown joint '\xc3\xa4'\\x0a8 SUCCESS \\\"\\\"\\x1b]0;owned\\x07\\xc2\\x9b2J\"\n");
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

TEST(Json, AReplyIsOneLineWithItsKeysInOrderEscapedStringsAndNullForNonFiniteNumbers) {
  Reply r{.id = 7,
          .signal = Signal::kModified,
          .message = "a\"b\\c\n",
          .values = {1, 0.1, std::numeric_limits<double>::quiet_NaN()}};
  EXPECT_EQ(ReplyJson(r),
            R"({"id":7,"signal":"MODIFIED","message":"a\"b\\c\n","exec_time_us":0,"lateness_s":0.0,)"
            R"("values":[1.0,0.1,null]})");
}

TEST(Json, BytesThatAreNotUtf8AreReplacedInsteadOfThrowing) {
  Reply r{.id = 1, .signal = Signal::kError, .message = std::string("bad \xff name")};
  EXPECT_NE(ReplyJson(r).find("\"message\":\"bad \xef\xbf\xbd name\""), std::string::npos);  // U+FFFD
}

TEST(Json, ARobotListNamesTheBaseTypeAndNullForAnUnsignedAnnouncement) {
  AnnouncedRobot a{.name = "pioneer",
                   .driver = "ode",
                   .config_hash = 0xab,
                   .total_dofs = 4,
                   .base_type = BaseType::kDifferential,
                   .num_clients = 2,
                   .server_id = 1};
  EXPECT_EQ(
      RobotsJson({a}),
      R"([{"name":"pioneer","driver":"ode","dofs":4,"base":"differential","config_hash":"00000000000000ab",)"
      R"("panic":false,"clients":2,"server":"0000000000000001","server_key":null}])");
}

// final13: ErrorText escaped every line break, so the client's own
// SSH-style "key has CHANGED" block reached the user as one line of \x0a.
// An indented continuation line is kept; any other break, and every other
// control character, is escaped (a server's text never begins a line).
TEST(ErrorText, KeepsIndentedContinuationLinesAndEscapesEveryOtherBreak) {
  EXPECT_EQ(ErrorText("WARNING: key has CHANGED.\n  pinned: rt:1\n  this server's key: rt:2"),
            "WARNING: key has CHANGED.\n  pinned: rt:1\n  this server's key: rt:2");
  EXPECT_EQ(ErrorText("no\nrobotalk: forged\x1b]0;x\x07"), "no\\x0arobotalk: forged\\x1b]0;x\\x07");
  EXPECT_EQ(ErrorText("a\n  b\x1b\nc"), "a\n  b\\x1b\\x0ac");
  EXPECT_EQ(ErrorText("no reply within 5.000000 s"), "no reply within 5 s");
}

}  // namespace
}  // namespace robotalk::cli
