#include "robotalk/signal.h"

namespace robotalk {

std::string_view ToString(Signal s) {
  switch (s) {
    case Signal::kSuccess:
      return "SUCCESS";
    case Signal::kModified:
      return "MODIFIED";
    case Signal::kNa:
      return "NA";
    case Signal::kBusy:
      return "BUSY";
    case Signal::kInterrupted:
      return "INTERRUPTED";
    case Signal::kError:
      return "ERROR";
    case Signal::kPanic:
      return "PANIC";
  }
  return "UNKNOWN";
}

std::optional<Signal> SignalFromWire(std::int8_t value) {
  if (value < 0 || value > static_cast<std::int8_t>(Signal::kPanic)) return std::nullopt;
  return static_cast<Signal>(value);
}

}  // namespace robotalk
