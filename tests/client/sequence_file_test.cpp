#include "robotalk/sequence_file.h"
#include "robotalk/urdf_import.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cerrno>
#include <clocale>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
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

// NumberOf is the rule every number option is read by (the CLI, the server,
// robotalk-web, the ROS 2 bridge, the relay, the drivers' key=value options):
// std::stod's, the whole word.
TEST(NumberText, AWholeWordInADoublesRangeIsANumberAndNothingElseIs) {
  EXPECT_EQ(NumberOf("0.25"), 0.25);
  EXPECT_EQ(NumberOf("-1e3"), -1000.0);
  EXPECT_EQ(NumberOf(" 5"), 5.0);  // blanks before it, as std::stod
  EXPECT_EQ(NumberOf("0x10"), 16.0);
  EXPECT_TRUE(std::isinf(*NumberOf("inf")));
  EXPECT_TRUE(std::isnan(*NumberOf("nan")));
  for (const char* bad : {"", " ", "5 ", "5x", "x5", "1,5", "1e999", "1e-400", "--"})
    EXPECT_FALSE(NumberOf(bad).has_value()) << "'" << bad << "'";
  errno = EINTR;
  (void)NumberOf("1e999");
  EXPECT_EQ(errno, EINTR) << "the caller's errno survives";
  EXPECT_EQ(ParseNumber("2", "--n"), 2.0);
  EXPECT_THROW(ParseNumber("inf", "--n"), UsageError);
}

// ParseNumberIn is the one reader of a number option (the server, robotalk-web,
// the ROS 2 bridge, robotalk-fig11): whatever is wrong, the flag, the word and
// what it accepts.
TEST(NumberText, ANumberOptionOutsideItsRangeNamesTheFlagTheWordAndTheRange) {
  EXPECT_EQ(ParseNumberIn("0.5", "--rate", {.min = 0.5, .max = 2}), 0.5);
  EXPECT_EQ(ParseNumberIn("2", "--rate", {.min = 0.5, .max = 2}), 2.0);
  EXPECT_EQ(ParseNumberIn("3e0", "--port", {.min = 0, .max = 65535, .whole = true}), 3.0);
  const auto error = [](const std::string& word, const NumberRange& range) {
    try {
      ParseNumberIn(word, "--x", range);
    } catch (const UsageError& e) {
      return std::string(e.what());
    }
    return std::string("(no error)");
  };
  EXPECT_EQ(error("0.4", {.min = 0.5, .max = 2}), "--x: '0.4' is not a number in [0.5, 2]");
  EXPECT_EQ(error("2.5", {.min = 0.5, .max = 2}), "--x: '2.5' is not a number in [0.5, 2]");
  EXPECT_EQ(error("0", {.min = 0, .max = 60, .above_min = true}), "--x: '0' is not a number in (0, 60]");
  EXPECT_EQ(error("2.5", {.min = 1, .max = 4096, .whole = true}),
            "--x: '2.5' is not a whole number in [1, 4096]");
  for (const char* bad : {"", "x", "5x", "nan", "inf", "-inf", "1e999"})
    EXPECT_EQ(error(bad, {.min = 0, .max = 1e9}),
              "--x: '" + std::string(bad) + "' is not a number in [0, 1e+09]");
}

// Review 13: NumberOf, and the <robotalk> block's xyz/rpy triples, were read
// with strtod, which follows the process's LC_NUMERIC: in a program that sets
// a locale whose decimal separator is a comma (Python after
// locale.setlocale(locale.LC_ALL, "") in Germany or France) "0.25" was
// refused as not a number, "0,25" taken as 0.25, and load_urdf refused every
// shipped model with a <robotalk> block ("0.05 0 0.05 is not three finite
// numbers"). RoboTalk's numbers are written with a point whatever the locale.
class CommaLocale : public ::testing::Test {
 protected:
  void SetUp() override {
    old_ = std::setlocale(LC_NUMERIC, nullptr);
    if (!std::setlocale(LC_NUMERIC, "de_DE.UTF-8")) {
      // Not installed: made for this test, if the system has the sources.
      dir_ = std::filesystem::temp_directory_path() / ("robotalk_locale_" + std::to_string(::getpid()));
      std::filesystem::create_directories(dir_);
      const std::string make =
          "localedef -i de_DE -f UTF-8 '" + (dir_ / "de_DE.UTF-8").string() + "' >/dev/null 2>&1";
      if (std::system(make.c_str()) == 0) {
        ::setenv("LOCPATH", dir_.c_str(), 1);
        std::setlocale(LC_NUMERIC, "de_DE.UTF-8");
      }
    }
    if (std::string(std::localeconv()->decimal_point) != ",")
      GTEST_SKIP() << "no locale with a decimal comma here";
  }
  void TearDown() override {
    std::setlocale(LC_NUMERIC, old_.c_str());
    if (!dir_.empty()) {
      ::unsetenv("LOCPATH");
      std::filesystem::remove_all(dir_);
    }
  }
  std::string old_;
  std::filesystem::path dir_;
};

TEST_F(CommaLocale, NumbersAreReadWithADecimalPointWhateverTheLocale) {
  EXPECT_EQ(NumberOf("0.25"), 0.25);
  EXPECT_FALSE(NumberOf("0,25").has_value());
  EXPECT_EQ(ParseNumber("-1.5e-3", "--n"), -1.5e-3);
  EXPECT_EQ(ErrorOf("0.5 setspeed 0.3 0\n"), "");
  const UrdfImportResult r = ParseUrdf(R"(<robot name="r">
  <link name="a"/><link name="b"/>
  <joint name="j" type="revolute"><parent link="a"/><child link="b"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
  <robotalk version="1"><control_frame name="tool" link="b" servo="setpoint">
    <origin xyz="0.05 0 0.05" rpy="0 0 1.5"/></control_frame></robotalk>
</robot>)");
  ASSERT_EQ(r.model.frames().size(), 1u);
  EXPECT_DOUBLE_EQ(r.model.frame(0).pose_in_link.translation.x(), 0.05);
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

// Issue 22 item 7: a sequence file's interpolation line and waypoint rates.
TEST(SequenceFile, TakesAnInterpolationLineAndAWaypointsVelocitiesAndAccelerations) {
  const SequenceFile file = ParseSequenceFile(
      "# pan, smoothly\n"
      "interpolation Cubic   # any case\n"
      "0 joint_setpoint pan 0\n"
      "0.5 joint_setpoint pan 0.3 velocity 0.4\n"
      "1 joint_setpoint pan_tilt 0 0.1 velocities 0 0 accelerations 0 0.5\n"
      "1.5 frame_setpoint camera 1 0 0.3 1 0 0 0 acceleration 0 0 0 0 0 0 velocity 0 0 0 0 0 0.1\n"
      "2 stop\n",
      "seq.txt");
  EXPECT_EQ(file.interpolation, Interpolation::kCubic);
  ASSERT_EQ(file.entries.size(), 5u);
  EXPECT_TRUE(file.entries[0].command.velocities.empty());
  EXPECT_EQ(file.entries[1].command.values, std::vector<double>{0.3});
  EXPECT_EQ(file.entries[1].command.velocities, std::vector<double>{0.4});
  EXPECT_EQ(file.entries[2].command.velocities, (std::vector<double>{0, 0}));
  EXPECT_EQ(file.entries[2].command.accelerations, (std::vector<double>{0, 0.5}));
  EXPECT_EQ(file.entries[3].command.values.size(), 7u);
  EXPECT_EQ(file.entries[3].command.velocities.back(), 0.1);
  EXPECT_EQ(file.entries[3].command.accelerations.size(), 6u);
  // Without the line: none (step), and ParseSequence gives the commands alone.
  EXPECT_FALSE(ParseSequenceFile("0 stop\n", "seq.txt").interpolation);
  EXPECT_EQ(ParseSequence("interpolation quintic\n0 stop\n", "seq.txt").size(), 1u);
  // What FormatCommandWords writes reads back.
  const Command c = file.entries[2].command;
  const Command back = ParseCommandWords(SplitWords(FormatCommandWords(c)));
  EXPECT_EQ(back.values, c.values);
  EXPECT_EQ(back.velocities, c.velocities);
  EXPECT_EQ(back.accelerations, c.accelerations);
  EXPECT_EQ(FormatCommandWords(file.entries[1].command), "joint_setpoint pan 0.3 velocity 0.4");
  // Each value the shortest text of its bits: exact, and as a person wrote it.
  for (const double v : {1.0 / 3, -0.0, 2.2250738585072014e-308, 1.7976931348623157e308, 1e21, 123456.789}) {
    SCOPED_TRACE(v);
    const Command one{.type = CommandType::kJointSetPoint, .target = "pan", .values = {v}};
    const std::string text = FormatCommandWords(one);
    const double read = ParseCommandWords(SplitWords(text)).values.at(0);
    EXPECT_EQ(std::memcmp(&read, &v, sizeof v), 0) << text;
  }
  EXPECT_EQ(FormatCommandWords({.type = CommandType::kGoto, .values = {1.0 / 3, 1e-7, 2.5}}),
            "goto 0.3333333333333333 1e-07 2.5");
}

TEST(SequenceFile, ABadInterpolationOrRateNamesTheWordAndWhatIsAccepted) {
  EXPECT_EQ(ErrorOf("interpolation cubc\n0 stop\n"),
            "seq.txt:1: interpolation: 'cubc' is not an interpolation (step, linear, cubic, quintic)");
  EXPECT_EQ(ErrorOf("interpolation\n0 stop\n"),
            "seq.txt:1: interpolation takes one word (step, linear, cubic, quintic)");
  EXPECT_EQ(ErrorOf("interpolation cubic\ninterpolation linear\n0 stop\n"),
            "seq.txt:2: interpolation given twice (first on line 1)");
  EXPECT_EQ(ErrorOf("0 stop\ninterpolation linear\n"),
            "seq.txt:2: the interpolation line goes before the first command");
  EXPECT_EQ(ErrorOf("cubic\n0 stop\n"),
            "seq.txt:1: 'cubic' is an interpolation: write 'interpolation cubic'");
  EXPECT_EQ(ErrorOf("0 joint_setpoint pan 0.1 velocity 0.1 0.2\n"),
            "seq.txt:1: JOINT_SETPOINT velocity takes one value per position (1), got 2");
  EXPECT_EQ(
      ErrorOf("0 frame_setpoint camera 1 0 0.3 1 0 0 0 velocity 0 0 0\n"),
      "seq.txt:1: FRAME_SETPOINT velocity takes 6 values (linear x y z, then angular x y z, in the world), "
      "got 3");
  EXPECT_EQ(ErrorOf("0 joint_setpoint pan 0.1 velocity\n"),
            "seq.txt:1: JOINT_SETPOINT: velocity needs its values");
  EXPECT_EQ(ErrorOf("0 joint_setpoint pan 0.1 velocity 1 velocity 2\n"),
            "seq.txt:1: JOINT_SETPOINT: velocity given twice");
  EXPECT_EQ(
      ErrorOf("0 joint_setpoint pan 0.1 velocity nan\n"),
      "seq.txt:1: JOINT_SETPOINT velocity 1: 'nan' is not finite (a joint_setpoint ends with its values, "
      "then optionally velocity V... and acceleration A...)");
  EXPECT_EQ(ErrorOf("0 joint_setpoint pan 0.1 velocty 0.2\n"),
            "seq.txt:1: JOINT_SETPOINT value 2: 'velocty' is not a number (a joint_setpoint ends with its "
            "values, then optionally velocity V... and acceleration A...)");
  EXPECT_EQ(ErrorOf("0 goto 1 0 0 velocity 1 0 0\n"),
            "seq.txt:1: GOTO takes no velocity (only a joint_setpoint or frame_setpoint waypoint does)");
  EXPECT_EQ(ErrorOf("0 joint_setpoint pan velocity 0.1\n"),
            "seq.txt:1: JOINT_SETPOINT takes one value per dof of the joint, got 0");
  EXPECT_EQ(ErrorOf("0 frame_setpoint camera 1 0 0.3 velocity 0 0 0 0 0 0\n"),
            "seq.txt:1: FRAME_SETPOINT takes 7 values (x y z qw qx qy qz), got 3");
}

// The text of examples/<name>.
std::string Example(const std::string& name) {
  std::ifstream in(std::string(ROBOTALK_EXAMPLES_DIR) + "/" + name);
  EXPECT_TRUE(in.good()) << name;
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

TEST(SequenceFile, TheExampleSquareParses) {
  const auto entries = ParseSequence(Example("square.txt"), "square.txt");
  EXPECT_EQ(entries.size(), 10u);
  EXPECT_EQ(entries.back().command.type, CommandType::kStop);
}

TEST(SequenceFile, TheExamplePanWaypointsParsesInterpolated) {
  const SequenceFile file = ParseSequenceFile(Example("pan_waypoints.txt"), "pan_waypoints.txt");
  EXPECT_EQ(file.interpolation, Interpolation::kCubic);
  EXPECT_EQ(file.entries.size(), 7u);
  EXPECT_EQ(file.entries.back().command.accelerations, std::vector<double>{0.0});
}

TEST(SequenceFile, TheExampleSpeedRampParsesInterpolated) {
  const SequenceFile file = ParseSequenceFile(Example("speed_ramp.txt"), "speed_ramp.txt");
  EXPECT_EQ(file.interpolation, Interpolation::kLinear);
  ASSERT_EQ(file.entries.size(), 8u);
  EXPECT_EQ(file.entries.back().command.type, CommandType::kSetSpeed);
}

}  // namespace
}  // namespace robotalk::cli
