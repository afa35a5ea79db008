// robotalk-web's lines ("robotalk-web: ..."): its start-up warnings and
// errors and the WebSocket closes, through the process's one writer of
// stderr (robotalk/log_writer.h): a stderr that takes nothing (a full pipe, a
// terminal stopped with Ctrl-S) holds a caller LogWriter::kMaxWait at most,
// and one whose reader went away loses the line (EPIPE), never the bridge.
#pragma once

#include "robotalk/log_writer.h"

namespace robotalk::web {

/// Never destroyed; Write() from any thread.
inline LogWriter& WebLog() {
  static LogWriter* const log = new LogWriter("robotalk-web: ", LogWriter::Stderr());
  return *log;
}

}  // namespace robotalk::web
