// The server's lines ("robotalk-server: ..."): the start-up lines, the
// ServerDaemon's log and audit lines, robotalk-server's command line and its
// errors, all through the process's one writer of stderr
// (LogWriter::Stderr(), robotalk/log_writer.h), as the drivers' lines are: a
// stderr that takes nothing keeps neither the robots from being served nor
// the server from its shutdown, and an error still ends it with its status.
#pragma once

#include "robotalk/log_writer.h"

#include <string>
#include <utility>

namespace robotalk {

/// Never destroyed; Write() from any thread.
LogWriter& ServerLog();

/// One line of robotalk-server's own ("robotalk-server: " + line), errors
/// included: a stderr that takes nothing costs the caller LogWriter::kMaxWait
/// at most, and an error still ends the server with its status. A line is
/// written on one line (a line break in it as \x0a): several lines, one
/// ServerLog().Write(lines).
inline void SayServer(std::string line) { ServerLog().Write(std::move(line)); }

}  // namespace robotalk
