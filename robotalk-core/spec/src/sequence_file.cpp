#include "robotalk/sequence_file.h"

#include <cmath>
#include <sstream>

namespace robotalk {

std::vector<std::string> SplitWords(const std::string& line) {
  std::istringstream in(line);
  std::vector<std::string> words;
  for (std::string w; in >> w;) words.push_back(w);
  return words;
}

double ParseNumber(const std::string& word, const std::string& what) {
  std::size_t used = 0;
  double v = 0;
  try {
    v = std::stod(word, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used != word.size() || word.empty()) throw UsageError(what + ": '" + word + "' is not a number");
  if (!std::isfinite(v)) throw UsageError(what + ": '" + word + "' is not finite");
  return v;
}

namespace {

bool NeedsTarget(CommandType t) {
  return t == CommandType::kJointSetPoint || t == CommandType::kJointSpeed || t == CommandType::kJointForce ||
         t == CommandType::kFrameSetPoint;
}

void CheckCount(CommandType t, std::size_t n) {
  const std::string name = ToString(t);
  auto fail = [&](const std::string& expected) {
    throw UsageError(name + " takes " + expected + ", got " + std::to_string(n));
  };
  switch (t) {
    case CommandType::kGoto:
      if (n != 3) fail("3 values (x y theta)");
      break;
    case CommandType::kSetSpeed:
      if (n != 2 && n != 3) fail("2 values (v omega) or 3 (vx vy omega)");
      break;
    case CommandType::kFrameSetPoint:
      if (n != 7) fail("7 values (x y z qw qx qy qz)");
      break;
    case CommandType::kStop:
    case CommandType::kPanicReset:
      if (n != 0) fail("no values");
      break;
    case CommandType::kJointSetPoint:
    case CommandType::kJointSpeed:
    case CommandType::kJointForce:
      if (n == 0) fail("one value per dof of the joint");
      break;
  }
}

}  // namespace

Command ParseCommandWords(const std::vector<std::string>& words) {
  if (words.empty()) throw UsageError("missing command name");
  const auto type = ParseCommandType(words[0]);
  if (!type) {
    throw UsageError("unknown command '" + words[0] +
                     "' (joint_setpoint, joint_speed, joint_force, frame_setpoint, goto, setspeed, stop, "
                     "panic_reset)");
  }
  Command c;
  c.type = *type;
  std::size_t i = 1;
  if (NeedsTarget(*type)) {
    if (words.size() < 2) throw UsageError(std::string(ToString(*type)) + " needs a target name");
    c.target = words[1];
    i = 2;
  }
  for (; i < words.size(); ++i) {
    c.values.push_back(ParseNumber(
        words[i], std::string(ToString(*type)) + " value " + std::to_string(c.values.size() + 1)));
  }
  CheckCount(*type, c.values.size());
  return c;
}

std::vector<SequenceEntry> ParseSequence(const std::string& text, const std::string& source) {
  std::vector<SequenceEntry> entries;
  std::istringstream in(text);
  std::string line;
  for (int number = 1; std::getline(in, line); ++number) {
    if (auto hash = line.find('#'); hash != std::string::npos) line.erase(hash);
    const auto words = SplitWords(line);
    if (words.empty()) continue;
    const std::string where = source + ":" + std::to_string(number) + ": ";
    try {
      SequenceEntry e;
      e.line = number;
      e.offset_s = ParseNumber(words[0], "start time");
      if (e.offset_s < 0) throw UsageError("start time " + words[0] + " is negative");
      if (words.size() < 2) throw UsageError("missing command after the start time");
      e.command = ParseCommandWords({words.begin() + 1, words.end()});
      entries.push_back(std::move(e));
    } catch (const UsageError& err) {
      throw UsageError(where + err.what());
    }
  }
  if (entries.empty()) throw UsageError(source + ": no commands");
  return entries;
}

}  // namespace robotalk
