// robotalk-ros2's command line (ros2_options.h): values out of range are
// named, never cast past what a Duration holds.
#include "ros2_options.h"

#include "robotalk/error.h"

#include <gtest/gtest.h>

#include <chrono>

namespace robotalk::ros2 {
namespace {

std::string ErrorOf(std::vector<std::string> args) {
  try {
    ParseRos2Options(args);
  } catch (const Error& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(Ros2Options, ADurationIsParsedInSeconds) {
  EXPECT_EQ(ParseRos2Options({"--duration", "2.5"}).duration, std::chrono::milliseconds(2500));
}

// Review 10: --duration 1e300 went through an unchecked double-to-int64 cast
// (undefined behaviour); a time past what a time holds is now named.
TEST(Ros2Options, ADurationOutOfRangeOrNotPositiveIsNamed) {
  EXPECT_EQ(ErrorOf({"--duration", "1e300"}), "--duration 1e300 is out of range (at most 1e+09 s)");
  EXPECT_EQ(ErrorOf({"--duration", "0"}), "--duration: 0 s is not positive");
  EXPECT_NE(ErrorOf({"--duration", "nan"}), "(no error)");
  EXPECT_NE(ErrorOf({"--duration", "-1"}), "(no error)");
}

// Review 12: `--robot` took any name but the empty one; a name no server
// can serve (32+ characters, a space) was tried and refused by every
// connect, for ever, instead of refused at start naming the rule.
TEST(Ros2Options, ARobotNameOutsideTheRobotNameRuleIsRefusedNamingIt) {
  EXPECT_EQ(ParseRos2Options({"--robot", std::string(31, 'a')}).robots.at(0), std::string(31, 'a'));
  EXPECT_NE(ErrorOf({"--robot", std::string(32, 'a')})
                .find("--robot '" + std::string(32, 'a') + "': a robot name has at most 31 characters"),
            std::string::npos);
  EXPECT_NE(ErrorOf({"--robot", "arm one"}).find("a robot name is letters, digits"), std::string::npos);
  EXPECT_NE(ErrorOf({"--robot", ""}).find("--robot"), std::string::npos);
}

// A number option is read by the one reader of every tool (robotalk::ParseNumberIn;
// NumberText tests it): the same words as the server's and robotalk-web's.
TEST(Ros2Options, ANumberOptionIsReadByTheOneRuleOfEveryTool) {
  EXPECT_EQ(ErrorOf({"--rate", "50x"}), "--rate: '50x' is not a number in [1, 1000]");
  EXPECT_EQ(ErrorOf({"--cmd-vel-timeout", "nan"}), "--cmd-vel-timeout: 'nan' is not a number in (0, 60]");
  EXPECT_EQ(ErrorOf({"--domain", "233"}), "--domain: '233' is not a whole number in [0, 232]");
}

}  // namespace
}  // namespace robotalk::ros2
