#include "robotalk/option_reader.h"

#include <utility>

namespace robotalk {

OptionReader::OptionReader(std::vector<std::string> args) : args_(std::move(args)) {}

OptionReader::OptionReader(int argc, const char* const* argv)
    : args_(argc > 1 ? std::vector<std::string>(argv + 1, argv + argc) : std::vector<std::string>()) {}

bool OptionReader::Next() {
  if (next_ >= args_.size()) return false;
  at_ = next_++;
  return true;
}

const std::string& OptionReader::Value() {
  if (next_ >= args_.size()) throw UsageError(word() + " needs a value");
  return args_[next_++];
}

void ThrowUnknownOption(const std::string& option) {
  throw UsageError("unknown option '" + option + "' (see --help)");
}

void OptionReader::Unknown() const { ThrowUnknownOption(word()); }

}  // namespace robotalk
