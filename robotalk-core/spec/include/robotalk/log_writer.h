// LogWriter: log lines reach a file descriptor (stderr) on a thread of their
// own, so a stderr that takes nothing (a full pipe nobody reads, a terminal
// stopped with Ctrl-S, a stalled log collector) never stops the thread that
// logs: the ServerDaemon takes panics, runs the watchdogs and answers on.
//
// Write() queues the lines and waits until they are written, as a direct
// write did, but never longer than kMaxWait after the line being written
// when it was called began: while the descriptor takes lines the order of
// lines and replies is as before (an audit line on stderr before its reply
// leaves, soak.md); one that takes nothing costs a caller kMaxWait at most,
// once per spell, and nothing after. Lines then wait in a queue of at most
// kMaxQueuedBytes; beyond it they are dropped, and the first write after
// says how many ("N log lines lost: ..."), as it does for lines whose write
// failed (a full disk, a pipe without a reader: EPIPE, never SIGPIPE).
// Each line is written on one line (EscapeControls: a line break in a text
// of anyone's never forges a log line, an escape never reaches a terminal). A
// non-blocking descriptor's EAGAIN is no failure: the writer thread waits
// for it to take more (poll), as a blocking write waits.
// Flush(), and the destruction of a writer, say a count not yet said in a
// line of its own, within the same bound.
//
// One writer per descriptor: LogWriter::Stderr() is the process's writer of
// stderr, which every line RoboTalk's serving programs write to stderr goes
// through (the server's, its drivers', ODE's and Cyclone DDS's messages,
// robotalk-web's and robotalk-ros2's; not LCM's own, nor --help's);
// a LogWriter made from another shares its thread and queue and adds a
// prefix of its own. A program's last words (an error before it exits) are
// written the same way: a stderr that takes nothing loses them after
// kMaxWait, and the program still exits with its status.
//
// Thread safety: Write() and Flush() from any thread. fork(): the child gets
// a writer thread of its own for every writer, its queue empty (the parent's
// lines are the parent's to write; pthread_atfork holds each writer's lock
// around the fork). The writer's state
// outlives the object: a destructor that cannot write what waits within
// kMaxWait leaves the writer thread blocked, and returns.
#pragma once

#include "robotalk/clock.h"

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

namespace robotalk {

/// Writes all of `text` to `fd`, through EINTR and, on a non-blocking
/// descriptor, waiting for room (poll); false when the descriptor fails
/// (closed, EPIPE, no space). For a thread of its own (it may wait for ever).
bool WriteFully(int fd, std::string_view text);

/// Runs `run` on a detached thread that blocks every signal: a descriptor
/// whose reader went away answers it EPIPE, never SIGPIPE, and it takes no
/// signal a program waits for (SIGINT, SIGTERM), though it may start before
/// the program blocks them.
void DetachWithSignalsBlocked(std::function<void()> run);

/// Opens /dev/null on each of descriptors 0, 1 and 2 that is closed (a
/// program started with `>&- 2>&-`): else the next files the program opens
/// take them, and its output and log lines (LogWriter::Stderr() writes to
/// descriptor 2) go into those (robotalk-server's went into its panic
/// latch's lock file). A program's main calls it first, before it opens
/// anything or starts a thread. Each that cannot be opened stays closed.
void OpenStandardDescriptors();

/// `text` on one line with no terminal control: each C0 control character,
/// DEL and C1 control encoded in UTF-8 (0xc2 0x80..0x9f) written as \xNN;
/// every other byte kept (UTF-8 text; a lone byte 0x80..0x9f too, which a
/// terminal set to 8-bit controls would read as one). For texts of anyone's written to a
/// terminal or a log (LogWriter's lines, the CLI's replies).
/// `ascii_only`: every byte outside printable ASCII written as \xNN (a text
/// that must also be valid UTF-8, e.g. for Python: robotalk-logplay's).
std::string EscapeControls(std::string_view text, bool ascii_only = false);

/// `text`'s lines, without their line breaks (an empty line kept, none after
/// a last "\n"): a multi-line text for LogWriter::Write, which writes a line
/// break inside a line as \x0a.
std::vector<std::string> SplitLines(std::string_view text);

class LogWriter {
 public:
  static constexpr Duration kMaxWait = std::chrono::milliseconds(200);
  static constexpr std::size_t kMaxQueuedBytes = std::size_t{4} << 20;

  /// A writer of its own (a thread and a queue): each line is written as
  /// `prefix` + line + "\n" to `fd` (not owned).
  explicit LogWriter(std::string prefix, int fd = 2);
  /// A writer through `shared`'s thread and queue (the same descriptor),
  /// each line written as `prefix` + line + "\n".
  LogWriter(std::string prefix, const LogWriter& shared);
  /// The process's writer of stderr (fd 2), made at first use and never
  /// destroyed. Its own lines have no prefix; its "N log lines lost" line
  /// begins with the program's name ("robotalk-server: ").
  static LogWriter& Stderr();
  /// Flush(); the last LogWriter of a thread and queue ends the thread once
  /// the queue is written.
  ~LogWriter();
  LogWriter(const LogWriter&) = delete;
  LogWriter& operator=(const LogWriter&) = delete;

  /// Queues `lines` (moved out; `lines` is left empty) and waits until they
  /// are written, or until the write in progress has run kMaxWait. Returns
  /// true when they were written.
  bool Write(std::vector<std::string>& lines);
  /// The same for one line.
  bool Write(std::string line);
  /// Waits, as Write() does, until what is queued is written and the lines
  /// lost but not yet said are said ("N log lines lost: ...") in a line of
  /// their own. Returns true when nothing waits and nothing is left unsaid.
  bool Flush();
  /// Lines dropped so far because the queue was full.
  std::uint64_t dropped() const;

 private:
  struct State;
  std::string prefix_;
  std::shared_ptr<State> state_;
};

}  // namespace robotalk
