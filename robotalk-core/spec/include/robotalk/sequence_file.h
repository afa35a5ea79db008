// The text forms of commands: command words as the `robotalk` CLI takes them,
// and sequence files (docs/client.md "Sequence files"), one command per line,
//
//   <start seconds> <command> [target] values... [velocity V...] [acceleration A...]
//
// with `#` comments and blank lines, and at most one line
//
//   interpolation step|linear|cubic|quintic
//
// before the first command. <start seconds> is relative to the send time of
// the sequence (>= 0). `velocity` / `acceleration` follow the values of a
// joint_setpoint (one per dof) or frame_setpoint (6: vx vy vz wx wy wz): a
// waypoint's (docs/client.md, "Trajectories"). Pure; no I/O beyond the text
// given. Shared by the CLI, robotalk-logplay and the server's --simulate.
#pragma once

#include "robotalk/command.h"
#include "robotalk/error.h"
#include "robotalk/trajectory.h"

#include <limits>
#include <optional>
#include <string>
#include <vector>

namespace robotalk {

/// A malformed command text or sequence file; the message names the line.
class UsageError : public Error {
 public:
  using Error::Error;
};

/// Builds a command from its CLI words: name (case-insensitive, e.g. "goto",
/// "JOINT_SETPOINT"), then a target for a joint or frame command, then values,
/// then (JOINT_SETPOINT, FRAME_SETPOINT) optionally `velocity` and
/// `acceleration` (or `velocities`, `accelerations`), each followed by its values.
/// Checks the number of values where the protocol fixes it (kCommandTraits:
/// GOTO 3, SETSPEED 2 or 3, FRAME_SETPOINT 7, STOP and PANIC_RESET none,
/// JOINT_* at least 1), of velocities and accelerations (WaypointRateCount:
/// one per position of a JOINT_SETPOINT, 6 for a FRAME_SETPOINT) and that
/// every value is a finite number. Throws UsageError.
Command ParseCommandWords(const std::vector<std::string>& words);
/// The inverse: "joint_setpoint pan 0.5 velocity 0.1", each value as
/// FormatNumber writes it.
std::string FormatCommandWords(const Command& command);

/// The shortest text that reads back (NumberOf) to the same bits: "0.3", not
/// %.17g's "0.29999999999999999"; "0.3333333333333333", not %.10g's
/// "0.3333333333" (another number). Locale-free. The one writer of a number
/// RoboTalk writes to be read again (command words, sequence files, logplay's
/// CSV).
std::string FormatNumber(double value);

/// An interpolation's name, any case ("cubic"); throws UsageError
/// "<what>: 'cubc' is not an interpolation (step, linear, cubic, quintic)".
Interpolation ParseInterpolationWord(const std::string& word, const std::string& what);

/// strtod in the C locale: a decimal point whatever the process's LC_NUMERIC
/// (a program that sets a locale, as Python's locale.setlocale may, reads
/// "0.25" as RoboTalk writes it). The one reader of a number's text
/// (NumberOf; a URDF's <robotalk> triples). Throws Error naming newlocale
/// when the C locale cannot be made (ENOMEM); a later call tries again.
double StrtodC(const char* text, char** end);

/// The number a whole word spells (strtod's syntax in the C locale, blanks
/// before it allowed, as std::stod): nullopt when the word is empty, when anything is
/// left after the number, or when it is out of a double's range (ERANGE:
/// too large, and too small as well: "1e-400" is refused, not read as 0).
/// "inf" and "nan" are numbers here (the callers refuse them). The one rule
/// every number option and text of RoboTalk is read by. Throws Error as
/// StrtodC does when the C locale cannot be made.
std::optional<double> NumberOf(const std::string& word);
/// Parses a finite number (NumberOf); throws UsageError naming `what`:
/// "<what>: 'x' is not a number", "<what>: 'inf' is not finite".
double ParseNumber(const std::string& word, const std::string& what);

/// The values a number option accepts (ParseNumberIn).
struct NumberRange {
  double min = -std::numeric_limits<double>::max();
  double max = std::numeric_limits<double>::max();
  bool above_min = false;  ///< min itself refused: "(0, 60]"
  bool whole = false;      ///< an integer: "3", "3.0" and "3e0", never "2.5"
};
/// A number option's value (the word after `flag`; an environment
/// variable's): a finite number (NumberOf) in `range`. The one reader of a
/// number option of every tool; throws UsageError naming the flag, the word
/// and the range whatever is wrong with it: "--port: 'http' is not a whole
/// number in [0, 65535]", "--rate: '0' is not a number in [1, 240]".
double ParseNumberIn(const std::string& word, const std::string& flag, const NumberRange& range);

/// The most seconds a time given as text may be (a sequence file's start
/// times; the command lines' --timeout, --at, --delay, --listen ...): 1e9 s,
/// 31 years, well inside what a Duration holds (FromSeconds: 9.2e9 s), so
/// that one added to a clock cannot overflow it.
inline constexpr double kMaxTextSeconds = 1e9;
/// Parses a time in seconds (the whole word) in [0, kMaxTextSeconds]; throws
/// UsageError naming `what`: "--timeout 1e12 is out of range (at most 1e+09
/// s)", "start time -1 is negative" (before: a time past FromSeconds' range
/// failed later, naming neither option nor line).
double ParseSeconds(const std::string& word, const std::string& what);

struct SequenceEntry {
  int line = 0;         ///< 1-based line number in the file
  double offset_s = 0;  ///< seconds after the sequence's send time
  Command command;      ///< start_time unset; id 0
};

struct SequenceFile {
  std::vector<SequenceEntry> entries;
  /// The file's `interpolation` line; nullopt when it has none (step).
  std::optional<Interpolation> interpolation;
};

/// Parses a sequence file's text. Throws UsageError "<source>:<line>: what"
/// for the first bad line; an empty sequence is an error too.
SequenceFile ParseSequenceFile(const std::string& text, const std::string& source);
/// Its commands only (the --simulate of a server, robotalk-logplay's check of what it writes).
std::vector<SequenceEntry> ParseSequence(const std::string& text, const std::string& source);

/// Splits on blanks (no quoting).
std::vector<std::string> SplitWords(const std::string& line);

}  // namespace robotalk

namespace robotalk::cli {
// The CLI's names for them (its usage errors are UsageErrors too).
using robotalk::ParseCommandWords;
using robotalk::ParseInterpolationWord;
using robotalk::ParseNumber;
using robotalk::ParseSeconds;
using robotalk::ParseSequence;
using robotalk::ParseSequenceFile;
using robotalk::SequenceEntry;
using robotalk::SplitWords;
using robotalk::UsageError;
}  // namespace robotalk::cli
