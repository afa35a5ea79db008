#include "robotalk/sequence_file.h"

#include <gtest/gtest.h>

#include <fstream>

namespace robotalk::cli {
namespace {

std::string ErrorOf(const std::string& text) {
  try {
    ParseSequence(text, "seq.txt");
  } catch (const UsageError& e) {
    return e.what();
  }
  return "";
}

TEST(SequenceFile, ParsesCommandsCommentsAndBlankLines) {
  const auto entries = ParseSequence(
      "# a comment\n"
      "\n"
      "0 goto 1 0 0   # trailing comment\n"
      "0.5 JOINT_SETPOINT pan_tilt 0.5 -0.2\n"
      "  2 setspeed 0.2 0.1\n"
      "3 stop\n",
      "seq.txt");
  ASSERT_EQ(entries.size(), 4u);
  EXPECT_EQ(entries[0].line, 3);
  EXPECT_EQ(entries[0].command.type, CommandType::kGoto);
  EXPECT_EQ(entries[0].command.values, (std::vector<double>{1, 0, 0}));
  EXPECT_EQ(entries[1].offset_s, 0.5);
  EXPECT_EQ(entries[1].command.target, "pan_tilt");
  EXPECT_EQ(entries[1].command.values, (std::vector<double>{0.5, -0.2}));
  EXPECT_EQ(entries[2].command.type, CommandType::kSetSpeed);
  EXPECT_EQ(entries[3].command.type, CommandType::kStop);
  EXPECT_TRUE(entries[3].command.start_time.is_now());
}

TEST(SequenceFile, ErrorsNameTheLine) {
  EXPECT_EQ(
      ErrorOf("0 stop\n\n1 jump 3\n"),
      "seq.txt:3: unknown command 'jump' (joint_setpoint, joint_speed, joint_force, frame_setpoint, goto, "
      "setspeed, stop, panic_reset)");
  EXPECT_EQ(ErrorOf("# c\nsoon goto 1 0 0\n"), "seq.txt:2: start time: 'soon' is not a number");
  EXPECT_EQ(ErrorOf("-1 stop\n"), "seq.txt:1: start time -1 is negative");
  EXPECT_EQ(ErrorOf("0 goto 1 0\n"), "seq.txt:1: GOTO takes 3 values (x y theta), got 2");
  EXPECT_EQ(ErrorOf("0 goto 1 0 x\n"), "seq.txt:1: GOTO value 3: 'x' is not a number");
  EXPECT_EQ(ErrorOf("0 setspeed nan 0\n"), "seq.txt:1: SETSPEED value 1: 'nan' is not finite");
  EXPECT_EQ(ErrorOf("0 joint_setpoint\n"), "seq.txt:1: JOINT_SETPOINT needs a target name");
  EXPECT_EQ(ErrorOf("0 joint_speed pan\n"),
            "seq.txt:1: JOINT_SPEED takes one value per dof of the joint, got 0");
  EXPECT_EQ(ErrorOf("0 stop 1\n"), "seq.txt:1: STOP takes no values, got 1");
  EXPECT_EQ(ErrorOf("1.5\n"), "seq.txt:1: missing command after the start time");
  EXPECT_EQ(ErrorOf("# nothing\n\n"), "seq.txt: no commands");
}

TEST(SequenceFile, CommandWordsForTheSendSubcommand) {
  Command c = ParseCommandWords({"frame_setpoint", "camera", "1", "2", "3", "1", "0", "0", "0"});
  EXPECT_EQ(c.type, CommandType::kFrameSetPoint);
  EXPECT_EQ(c.target, "camera");
  EXPECT_EQ(c.values.size(), 7u);
  EXPECT_EQ(ParseCommandWords({"setspeed", "0.1", "0.2", "0.3"}).values.size(), 3u);
  EXPECT_THROW(ParseCommandWords({}), UsageError);
  EXPECT_THROW(ParseCommandWords({"setspeed", "0.1"}), UsageError);
}

TEST(SequenceFile, TheExampleSquareParses) {
  std::ifstream in(std::string(ROBOTALK_EXAMPLES_DIR) + "/square.txt");
  ASSERT_TRUE(in.good());
  std::stringstream text;
  text << in.rdbuf();
  const auto entries = ParseSequence(text.str(), "square.txt");
  EXPECT_EQ(entries.size(), 10u);
  EXPECT_EQ(entries.back().command.type, CommandType::kStop);
}

}  // namespace
}  // namespace robotalk::cli
