// What COMMAND_STATUS's answer about a command says became of it
// (docs/protocol.md). On the wire (protocol 4) a command that still waits or
// runs answers BUSY and one the session never received (or whose reply left
// the cache) NA, each with the server's fixed text, while a command that
// *ended* BUSY or NA (refused behind a GOTO, ...) keeps its own reply: the
// text is what tells them apart. The server writes it with CommandStatusText
// and every reader asks CommandStatusOf, so the two never drift. Pure.
#pragma once

#include "robotalk/command.h"

#include <string>

namespace robotalk {

enum class CommandStatusKind {
  kEnded,        ///< the answer is the command's own final reply, whatever its signal
  kNotEnded,     ///< BUSY "command N has not ended": it waits or runs
  kNotReceived,  ///< NA "command N was never received in this session ...": not this session's
};

/// What `answer`, COMMAND_STATUS's answer about command `about`, says.
CommandStatusKind CommandStatusOf(const Reply& answer, CommandId about);

/// The server's message for kNotEnded or kNotReceived about command `about`
/// ("" for kEnded: the command's own reply is sent).
std::string CommandStatusText(CommandStatusKind kind, CommandId about);

}  // namespace robotalk
