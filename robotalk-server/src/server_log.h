// The server's lines ("robotalk-server: ..."): the start-up lines, the
// ServerDaemon's log and audit lines, robotalk-server's command line and its
// errors, all through the process's one writer of stderr
// (LogWriter::Stderr(), robotalk/log_writer.h), as the drivers' lines are: a
// stderr that takes nothing keeps neither the robots from being served nor
// the server from its shutdown, and an error still ends it with its status.
#pragma once

#include "robotalk/log_writer.h"

namespace robotalk {

/// Never destroyed; Write() from any thread.
LogWriter& ServerLog();

}  // namespace robotalk
