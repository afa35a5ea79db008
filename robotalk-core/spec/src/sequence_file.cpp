#include "robotalk/sequence_file.h"

#include "robotalk/error.h"

#include <atomic>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <sstream>

#include <locale.h>
#include <stdlib.h>  // strtod_l

namespace robotalk {

std::vector<std::string> SplitWords(const std::string& line) {
  std::istringstream in(line);
  std::vector<std::string> words;
  for (std::string w; in >> w;) words.push_back(w);
  return words;
}

// The C locale, made once by newlocale, which can fail (ENOMEM): then no
// number is read (an Error naming it; a null locale_t given to strtod_l is
// undefined behaviour, a crash in glibc), and the next call tries again.
double StrtodC(const char* text, char** end) {
  static std::atomic<locale_t> made{static_cast<locale_t>(nullptr)};
  locale_t c = made.load(std::memory_order_acquire);
  if (!c) {
    const int saved = errno;
    locale_t fresh = newlocale(LC_NUMERIC_MASK, "C", static_cast<locale_t>(nullptr));
    if (!fresh) {
      const std::string why = std::strerror(errno);
      errno = saved;
      throw Error("cannot read a number: the C locale could not be made (newlocale: " + why + ")");
    }
    errno = saved;
    locale_t expected = static_cast<locale_t>(nullptr);
    if (made.compare_exchange_strong(expected, fresh, std::memory_order_acq_rel)) {
      c = fresh;
    } else {
      freelocale(fresh);  // another thread made it first
      c = expected;
    }
  }
  return strtod_l(text, end, c);
}

std::optional<double> NumberOf(const std::string& word) {
  if (word.empty()) return std::nullopt;
  const int saved = errno;  // as std::stod: the caller's errno survives
  errno = 0;
  char* end = nullptr;
  const double v = StrtodC(word.c_str(), &end);
  const bool whole = end == word.c_str() + word.size() && errno != ERANGE;
  errno = saved;
  if (!whole) return std::nullopt;
  return v;
}

double ParseNumber(const std::string& word, const std::string& what) {
  const std::optional<double> v = NumberOf(word);
  if (!v) throw UsageError(what + ": '" + word + "' is not a number");
  if (!std::isfinite(*v)) throw UsageError(what + ": '" + word + "' is not finite");
  return *v;
}

double ParseNumberIn(const std::string& word, const std::string& flag, const NumberRange& range) {
  const std::optional<double> v = NumberOf(word);
  if (v && std::isfinite(*v) && (range.above_min ? *v > range.min : *v >= range.min) && *v <= range.max &&
      (!range.whole || *v == std::floor(*v)))
    return *v;
  // A whole number's bounds to the digit (%g rounds 2^53 - 1 up to 9.0072e+15).
  const auto bound = [&range](double b) {
    char text[40];
    std::snprintf(text, sizeof text, range.whole && std::fabs(b) <= 0x1p53 ? "%.0f" : "%g", b);
    return std::string(text);
  };
  throw UsageError(flag + ": '" + word + "' is not a " + (range.whole ? "whole " : "") + "number in " +
                   (range.above_min ? "(" : "[") + bound(range.min) + ", " + bound(range.max) + "]");
}

double ParseSeconds(const std::string& word, const std::string& what) {
  const double s = ParseNumber(word, what);
  if (s < 0) throw UsageError(what + " " + word + " is negative");
  if (s > kMaxTextSeconds) {
    char limit[32];
    std::snprintf(limit, sizeof limit, "%g", kMaxTextSeconds);
    throw UsageError(what + " " + word + " is out of range (at most " + limit + " s)");
  }
  return s;
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

std::string Lower(std::string word) {
  for (char& ch : word) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
  return word;
}

// A command's word in a sequence file: its name in lower case.
std::string Word(CommandType t) { return Lower(ToString(t)); }

// "step, linear, cubic, quintic".
std::string InterpolationWords() {
  std::string words;
  for (Interpolation i :
       {Interpolation::kStep, Interpolation::kLinear, Interpolation::kCubic, Interpolation::kQuintic})
    words += (words.empty() ? "" : ", ") + std::string(InterpolationName(i));
  return words;
}

// The words that start a waypoint's velocities or accelerations.
struct RateWord {
  const char* word;
  bool acceleration;
};
constexpr RateWord kRateWords[] = {
    {"velocity", false}, {"velocities", false}, {"acceleration", true}, {"accelerations", true}};
const RateWord* FindRateWord(const std::string& word) {
  for (const RateWord& r : kRateWords) {
    if (word == r.word) return &r;
  }
  return nullptr;
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
  const std::string name = ToString(*type);
  const bool waypoint = WaypointRateCount(*type, 1) > 0;
  std::vector<double>* into = &c.values;
  std::string noun = name + " value ";
  bool rates = false;  // a velocity or acceleration word came
  for (; i < words.size(); ++i) {
    if (const RateWord* rate = FindRateWord(words[i])) {
      if (!waypoint) {
        throw UsageError(name + " takes no " + words[i] +
                         " (only a joint_setpoint or frame_setpoint waypoint does)");
      }
      if (!rates) CheckCount(*type, c.values.size());
      rates = true;
      into = rate->acceleration ? &c.accelerations : &c.velocities;
      if (!into->empty()) throw UsageError(name + ": " + words[i] + " given twice");
      noun = name + " " + std::string(rate->acceleration ? "acceleration " : "velocity ");
      if (i + 1 == words.size() || FindRateWord(words[i + 1])) {
        throw UsageError(name + ": " + words[i] + " needs its values");
      }
      continue;
    }
    try {
      into->push_back(ParseNumber(words[i], noun + std::to_string(into->size() + 1)));
    } catch (const UsageError& e) {
      // Past the positions of a waypoint, a word may be a misspelt keyword.
      if (!waypoint) throw;
      throw UsageError(std::string(e.what()) + " (a " + Word(*type) +
                       " ends with its values, then optionally velocity V... and acceleration A...)");
    }
  }
  if (!rates) CheckCount(*type, c.values.size());
  const std::size_t expected = WaypointRateCount(*type, c.values.size());
  for (const auto& [values, word] :
       {std::pair{&c.velocities, "velocity"}, {&c.accelerations, "acceleration"}}) {
    if (values->empty() || values->size() == expected) continue;
    throw UsageError(name + " " + word + " takes " +
                     (*type == CommandType::kFrameSetPoint
                          ? std::string("6 values (linear x y z, then angular x y z, in the world)")
                          : "one value per position (" + std::to_string(expected) + ")") +
                     ", got " + std::to_string(values->size()));
  }
  return c;
}

std::string FormatNumber(double value) {
  char number[32];  // the longest shortest form, "-2.2250738585072014e-308", is 24
  const std::to_chars_result r = std::to_chars(number, number + sizeof number, value);
  return std::string(number, r.ptr);
}

std::string FormatCommandWords(const Command& c) {
  std::string text = Word(c.type);
  if (!c.target.empty()) text += " " + c.target;
  const auto append = [&text](const std::vector<double>& values) {
    for (const double v : values) text += ' ' + FormatNumber(v);
  };
  append(c.values);
  if (!c.velocities.empty()) text += " velocity";
  append(c.velocities);
  if (!c.accelerations.empty()) text += " acceleration";
  append(c.accelerations);
  return text;
}

Interpolation ParseInterpolationWord(const std::string& word, const std::string& what) {
  if (auto interpolation = ParseInterpolation(word)) return *interpolation;
  throw UsageError(what + ": '" + word + "' is not an interpolation (" + InterpolationWords() + ")");
}

SequenceFile ParseSequenceFile(const std::string& text, const std::string& source) {
  SequenceFile file;
  int interpolation_line = 0;
  std::istringstream in(text);
  std::string line;
  for (int number = 1; std::getline(in, line); ++number) {
    if (auto hash = line.find('#'); hash != std::string::npos) line.erase(hash);
    const auto words = SplitWords(line);
    if (words.empty()) continue;
    const std::string where = source + ":" + std::to_string(number) + ": ";
    try {
      if (ParseInterpolation(words[0]) || Lower(words[0]) == "interpolation") {
        if (Lower(words[0]) != "interpolation") {
          throw UsageError("'" + words[0] + "' is an interpolation: write 'interpolation " + words[0] + "'");
        }
        if (interpolation_line) {
          throw UsageError("interpolation given twice (first on line " + std::to_string(interpolation_line) +
                           ")");
        }
        if (!file.entries.empty()) throw UsageError("the interpolation line goes before the first command");
        if (words.size() != 2)
          throw UsageError("interpolation takes one word (" + InterpolationWords() + ")");
        file.interpolation = ParseInterpolationWord(words[1], "interpolation");
        interpolation_line = number;
        continue;
      }
      SequenceEntry e;
      e.line = number;
      e.offset_s = ParseSeconds(words[0], "start time");
      if (words.size() < 2) throw UsageError("missing command after the start time");
      e.command = ParseCommandWords({words.begin() + 1, words.end()});
      file.entries.push_back(std::move(e));
    } catch (const UsageError& err) {
      throw UsageError(where + err.what());
    }
  }
  if (file.entries.empty()) throw UsageError(source + ": no commands");
  return file;
}

std::vector<SequenceEntry> ParseSequence(const std::string& text, const std::string& source) {
  return ParseSequenceFile(text, source).entries;
}

}  // namespace robotalk
