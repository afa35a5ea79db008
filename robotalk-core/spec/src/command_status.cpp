#include "robotalk/command_status.h"

namespace robotalk {

std::string CommandStatusText(CommandStatusKind kind, CommandId about) {
  switch (kind) {
    case CommandStatusKind::kNotEnded:
      return "command " + std::to_string(about) + " has not ended";
    case CommandStatusKind::kNotReceived:
      return "command " + std::to_string(about) +
             " was never received in this session (or is older than its reply cache)";
    case CommandStatusKind::kEnded:
      break;
  }
  return "";
}

CommandStatusKind CommandStatusOf(const Reply& answer, CommandId about) {
  if (answer.signal == Signal::kBusy &&
      answer.message == CommandStatusText(CommandStatusKind::kNotEnded, about))
    return CommandStatusKind::kNotEnded;
  if (answer.signal == Signal::kNa &&
      answer.message == CommandStatusText(CommandStatusKind::kNotReceived, about))
    return CommandStatusKind::kNotReceived;
  return CommandStatusKind::kEnded;
}

}  // namespace robotalk
