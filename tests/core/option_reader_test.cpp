#include "robotalk/option_reader.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace robotalk {
namespace {

using ::testing::ThrowsMessage;

TEST(OptionReader, ReadsWordsInOrderAndTakesAnOptionsValue) {
  OptionReader r({"--port", "80", "--stats", "-h", "--version"});
  ASSERT_TRUE(r.Next());
  EXPECT_TRUE(r.Is("--port"));
  EXPECT_EQ(r.Value(), "80");
  EXPECT_EQ(r.word(), "--port");  // still the option after its value is taken
  ASSERT_TRUE(r.Next());
  EXPECT_EQ(r.word(), "--stats");
  ASSERT_TRUE(r.Next());
  EXPECT_TRUE(r.IsHelp());
  ASSERT_TRUE(r.Next());
  EXPECT_TRUE(r.IsVersion());
  EXPECT_FALSE(r.Next());
}

TEST(OptionReader, SkipsTheProgramNameOfArgv) {
  const char* argv[] = {"tool", "--help"};
  OptionReader r(2, argv);
  ASSERT_TRUE(r.Next());
  EXPECT_TRUE(r.IsHelp());
  EXPECT_FALSE(r.Next());
  EXPECT_FALSE(OptionReader(1, argv).Next());
}

TEST(OptionReader, NamesAnOptionWithoutItsValue) {
  OptionReader r({"--port"});
  ASSERT_TRUE(r.Next());
  EXPECT_THAT([&] { r.Value(); }, ThrowsMessage<UsageError>("--port needs a value"));
}

TEST(OptionReader, NamesAnUnknownOptionTheSameWayForEveryTool) {
  OptionReader r({"--colour"});
  ASSERT_TRUE(r.Next());
  EXPECT_THAT([&] { r.Unknown(); }, ThrowsMessage<UsageError>("unknown option '--colour' (see --help)"));
}

}  // namespace
}  // namespace robotalk
