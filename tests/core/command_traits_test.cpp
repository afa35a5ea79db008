// kCommandTraits (command.h) is the one place a command type is described:
// these tests tie it to the wire constants in command_t.lcm and check that
// every command it lists survives the sequence-file text and the codec.
#include "robotalk/command.h"
#include "robotalk/request.h"
#include "robotalk/sequence_file.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fstream>
#include <map>
#include <regex>
#include <sstream>

namespace robotalk {
namespace {

using ::testing::HasSubstr;

// NAME -> code of every `const int8_t NAME = code;` in command_t.lcm.
std::map<std::string, int> WireConstants() {
  std::ifstream in(std::string(ROBOTALK_LCMTYPES_DIR) + "/robotalk_msgs/command_t.lcm");
  std::stringstream text;
  text << in.rdbuf();
  const std::string s = text.str();
  std::map<std::string, int> constants;
  const std::regex constant(R"(const\s+int8_t\s+([A-Z_]+)\s*=\s*(-?[0-9]+)\s*;)");
  for (auto it = std::sregex_iterator(s.begin(), s.end(), constant); it != std::sregex_iterator(); ++it) {
    constants[(*it)[1]] = std::stoi((*it)[2]);
  }
  return constants;
}

// A command of row `t` with `n` values (a per-dof command: its joint has n dofs).
Command Sample(const CommandTraits& t, std::size_t n) {
  Command c{.id = 100 + static_cast<CommandId>(t.type), .type = t.type};
  if (t.target == CommandTarget::kJoint) c.target = "pan_joint";
  if (t.target == CommandTarget::kFrame) c.target = "gripper";
  for (std::size_t i = 0; i < n; ++i) c.values.push_back(0.1 * static_cast<double>(i + 1) - 1.0 / 3.0);
  return c;
}

// Every value count a row accepts (per dof: 1 and 2 dofs).
std::vector<std::size_t> Counts(const CommandTraits& t) {
  if (t.min_values == kValuesPerDof) return {1, 2};
  std::vector<std::size_t> counts;
  for (int n = t.min_values; n <= t.max_values; ++n) counts.push_back(static_cast<std::size_t>(n));
  return counts;
}

TEST(CommandTraits, ListsExactlyTheCommandConstantsOfTheWire) {
  const std::map<std::string, int> wire = WireConstants();
  ASSERT_FALSE(wire.empty()) << "no constants read from " << ROBOTALK_LCMTYPES_DIR;
  std::map<std::string, int> table;
  for (const CommandTraits& t : kCommandTraits) table[t.name] = static_cast<int>(t.type);
  EXPECT_EQ(table, wire) << "kCommandTraits (command.h) and command_t.lcm must list the same commands";
}

TEST(CommandTraits, FindsEachRowByItsCodeAndNoOther) {
  for (const CommandTraits& t : kCommandTraits) {
    ASSERT_NE(FindCommandTraits(static_cast<int>(t.type)), nullptr);
    EXPECT_EQ(FindCommandTraits(static_cast<int>(t.type))->name, t.name);
    EXPECT_STREQ(ToString(t.type), t.name);
    EXPECT_EQ(ParseCommandType(t.name), t.type);
    if (t.alias) {
      EXPECT_EQ(ParseCommandType(t.alias), t.type);
    }
    EXPECT_EQ(t.max_values == t.min_values, *t.max_value_names == '\0') << t.name;
  }
  EXPECT_EQ(FindCommandTraits(0), nullptr);
  EXPECT_EQ(FindCommandTraits(static_cast<int>(kCommandTraits.size()) + 1), nullptr);
  EXPECT_EQ(ParseCommandType("setaccel"), std::nullopt);
  // A value that is no type (a C++ cast) has the unknown row: no target, never a motion.
  const auto bogus = static_cast<CommandType>(42);
  EXPECT_STREQ(ToString(bogus), "UNKNOWN_COMMAND");
  EXPECT_EQ(Traits(bogus).kind, CommandKind::kSession);
  EXPECT_FALSE(IsMotionCommand(bogus));
}

TEST(CommandTraits, EveryCommandRoundTripsThroughItsSequenceFileText) {
  for (const CommandTraits& t : kCommandTraits) {
    for (const std::size_t n : Counts(t)) {
      const Command c = Sample(t, n);
      const std::string text = FormatCommandWords(c);
      const Command back = ParseCommandWords(SplitWords(text));
      EXPECT_EQ(back.type, c.type) << text;
      EXPECT_EQ(back.target, c.target) << text;
      EXPECT_EQ(back.values, c.values) << text;
      // And in a sequence file, at an offset.
      const std::vector<SequenceEntry> entries = ParseSequence("0.5 " + text + "\n", "seq.txt");
      ASSERT_EQ(entries.size(), 1u);
      EXPECT_EQ(entries[0].command.values, c.values) << text;
    }
  }
}

TEST(CommandTraits, SequenceTextRefusesAValueCountTheTableDoesNotAllow) {
  for (const CommandTraits& t : kCommandTraits) {
    if (t.min_values == kValuesPerDof) {
      EXPECT_THROW(ParseCommandWords(SplitWords(FormatCommandWords(Sample(t, 0)))), UsageError) << t.name;
      continue;
    }
    const std::string text = FormatCommandWords(Sample(t, static_cast<std::size_t>(t.max_values) + 1));
    try {
      ParseCommandWords(SplitWords(text));
      ADD_FAILURE() << text << " was accepted";
    } catch (const UsageError& e) {
      EXPECT_THAT(e.what(), HasSubstr(std::string(t.name) + " takes ")) << text;
    }
  }
}

TEST(CommandTraits, EveryCommandRoundTripsThroughTheCodec) {
  Request r{.client_id = 7, .sequence = 1};
  for (const CommandTraits& t : kCommandTraits) {
    for (const std::size_t n : Counts(t)) r.commands.push_back(Sample(t, n));
  }
  const Request back = DecodeRequest(EncodeRequest(r));
  EXPECT_TRUE(back.header_error.empty()) << back.header_error;
  EXPECT_TRUE(back.malformed.empty());
  ASSERT_EQ(back.commands.size(), r.commands.size());
  for (std::size_t i = 0; i < r.commands.size(); ++i) {
    EXPECT_EQ(back.commands[i].id, r.commands[i].id);
    EXPECT_EQ(back.commands[i].type, r.commands[i].type);
    EXPECT_EQ(back.commands[i].target, r.commands[i].target);
    EXPECT_EQ(back.commands[i].values, r.commands[i].values);
  }
}

TEST(CommandTraits, TheCodecRefusesACodeOutsideTheTable) {
  for (const int code : {0, static_cast<int>(kCommandTraits.size()) + 1}) {
    Request r{.client_id = 7, .sequence = 1};
    r.commands.push_back(Command{.id = 5, .type = static_cast<CommandType>(code)});
    const Request back = DecodeRequest(EncodeRequest(r));
    EXPECT_TRUE(back.commands.empty());
    ASSERT_EQ(back.malformed.size(), 1u);
    EXPECT_EQ(back.malformed[0].id, 5);
    EXPECT_THAT(back.malformed[0].reason, HasSubstr("unknown command type " + std::to_string(code)));
  }
}

}  // namespace
}  // namespace robotalk
