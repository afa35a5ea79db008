// Ctrl-C and SIGTERM for the command-line tools, as a flag that their wait
// loops check: a tool that started a motion must send STOP for it before it
// exits (docs/client.md, "Ctrl-C"), which a plain signal handler cannot do
// (RobotClient is not async-signal-safe).
//
// Install() blocks SIGINT and SIGTERM in the calling thread and starts one
// thread that sigwait()s for them; every thread started afterwards (LCM's,
// RobotClient's ReadDaemon) inherits the mask, so only that thread receives
// them. Until a tool calls Defer(true) (it is about to start something it
// must stop), a signal ends the process at once with status 128 + signal;
// afterwards the first signal is recorded for the wait loops, and a second
// one ends the process at once (the user insists).
//
// Thread safety: every function may be called from any thread.
#pragma once

#include "robotalk/clock.h"

#include <stop_token>

namespace robotalk::cli {

class Interrupter {
 public:
  /// Call first in main(), before any other thread exists. Idempotent.
  static void Install();
  /// true: record signals for the wait loops instead of exiting at once.
  static void Defer(bool defer);
  /// The first SIGINT/SIGTERM received, or 0. Without Install(), always 0.
  static int Signal();
  /// Waits at most `d`, returning early when a signal arrives; returns Signal().
  static int WaitFor(Duration d);
  /// Requested when the first signal is recorded: waits that take a
  /// std::stop_token (PendingReply::WaitFor, SequenceHooks::stop) end at once.
  static std::stop_token StopToken();
  /// "SIGINT", "SIGTERM".
  static const char* Name(int signal);
  /// The conventional exit status after `signal`: 128 + signal.
  static int ExitStatus(int signal) { return 128 + signal; }
};

}  // namespace robotalk::cli
