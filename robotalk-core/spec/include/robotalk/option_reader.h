// The loop over a command line that every tool's main had: its words in
// order, an option's value, -h/--help, --version, and an unknown option named
// the same way by every tool. Pure (no I/O); what -h and --version print and
// the exit status stay the caller's. Not thread-safe: one reader, one thread.
//
//   OptionReader r(argc, argv);
//   while (r.Next()) {
//     if (r.IsHelp()) { ...usage, exit 0 }
//     else if (r.Is("--port")) port = ParseNumberIn(r.Value(), r.word(), {...});
//     else r.Unknown();
//   }
#pragma once

#include "robotalk/sequence_file.h"  // UsageError

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

namespace robotalk {

/// Throws UsageError "unknown option '<option>' (see --help)": the one text
/// for an option no tool knows (OptionReader::Unknown; "--opt=value" forms).
[[noreturn]] void ThrowUnknownOption(const std::string& option);

class OptionReader {
 public:
  /// The words after the program's name.
  explicit OptionReader(std::vector<std::string> args);
  /// argv[1] .. argv[argc - 1].
  OptionReader(int argc, const char* const* argv);

  /// Moves to the next word; false after the last.
  bool Next();
  /// The current word: the option whose value Value() takes.
  /// REQUIRES: Next() returned true.
  const std::string& word() const { return args_[at_]; }
  bool Is(std::string_view option) const { return word() == option; }
  /// -h or --help.
  bool IsHelp() const { return Is("-h") || Is("--help"); }
  /// --version.
  bool IsVersion() const { return Is("--version"); }

  /// The word after the current option, taken (the next Next() skips it).
  /// Throws UsageError "<option> needs a value" when it was the last word.
  const std::string& Value();
  /// Throws UsageError "unknown option '<word>' (see --help)" (ThrowUnknownOption).
  [[noreturn]] void Unknown() const;

 private:
  std::vector<std::string> args_;
  std::size_t at_ = 0;    // the current word
  std::size_t next_ = 0;  // the word Next() or Value() reads next
};

}  // namespace robotalk
