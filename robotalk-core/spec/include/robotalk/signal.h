// The seven return signals of a RoboTalk command (paper §III-C).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

namespace robotalk {

enum class Signal : std::int8_t {
  kSuccess = 0,      ///< done as asked
  kModified = 1,     ///< done, but the driver had to change it (clamped, holonomic dropped)
  kNa = 2,           ///< this robot does not support that command
  kBusy = 3,         ///< an earlier request that cannot be interrupted is still running
  kInterrupted = 4,  ///< a legitimate action was stopped before it finished
  kError = 5,        ///< the request was wrong (unknown joint, malformed arguments, ...)
  kPanic = 6,        ///< the robot is in panic; nothing executes until PANIC_RESET
};

/// "SUCCESS", "MODIFIED", "NA", "BUSY", "INTERRUPTED", "ERROR", "PANIC".
std::string_view ToString(Signal s);
/// The signal with that wire value, or nullopt.
std::optional<Signal> SignalFromWire(std::int8_t value);
/// SUCCESS and MODIFIED mean the command was carried out.
inline bool Succeeded(Signal s) { return s == Signal::kSuccess || s == Signal::kModified; }

/// Why a request is not executed, as every check in RoboTalk reports it: the
/// signal it is answered with (ERROR for a malformed request, NA for one this
/// robot does not support) and a message naming what was wrong.
struct Refusal {
  Signal signal = Signal::kError;
  std::string message;
  bool operator==(const Refusal&) const = default;
};

}  // namespace robotalk
