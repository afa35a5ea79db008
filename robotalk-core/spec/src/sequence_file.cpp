#include "robotalk/sequence_file.h"

#include <cctype>
#include <cmath>
#include <cstdio>
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
  const CommandTarget target = Traits(t).target;
  return target == CommandTarget::kJoint || target == CommandTarget::kFrame;
}

void CheckCount(CommandType t, std::size_t n) {
  const CommandTraits& traits = Traits(t);
  const bool per_dof = traits.min_values == kValuesPerDof;
  // The joint's dofs are not known here: at least one value.
  if (per_dof ? n > 0 : ValueCountFits(traits, n, 0)) return;
  const std::string expected = per_dof                  ? "one value per dof of the joint"
                               : traits.max_values == 0 ? "no values"
                                                        : ValueCountText(traits);
  throw UsageError(std::string(traits.name) + " takes " + expected + ", got " + std::to_string(n));
}

// A command's word in a sequence file: its name in lower case.
std::string Word(CommandType t) {
  std::string word = ToString(t);
  for (char& ch : word) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
  return word;
}

// "joint_setpoint, joint_speed, ...": the words a command may start with.
std::string CommandWords() {
  std::string words;
  for (const CommandTraits& t : kCommandTraits) words += (words.empty() ? "" : ", ") + Word(t.type);
  return words;
}

}  // namespace

Command ParseCommandWords(const std::vector<std::string>& words) {
  if (words.empty()) throw UsageError("missing command name");
  const auto type = ParseCommandType(words[0]);
  if (!type) {
    throw UsageError("unknown command '" + words[0] + "' (" + CommandWords() + ")");
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

std::string FormatCommandWords(const Command& c) {
  std::string text = Word(c.type);
  if (!c.target.empty()) text += " " + c.target;
  for (const double v : c.values) {
    char number[32];
    std::snprintf(number, sizeof number, " %.17g", v);
    text += number;
  }
  return text;
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
