// OutputLines: lines written to a descriptor (the CLI's stdout) by a thread
// of their own. A stdout that takes nothing (a full pipe whose reader stalls,
// a pager stopped) never holds the thread that sends a sequence's frames at
// their times, and so never the session that keeps the last frame's motion
// alive (before: `robotalk send --file` waited in a reply line's write while
// its heartbeats kept a SETSPEED driving). The caller ends the session first,
// then waits for the output with Finish() (a signal ends the tool meanwhile).
//
// Add() never blocks: at most kMaxQueuedBytes wait; beyond, texts are dropped
// and counted (Finish() returns the count). A descriptor that fails (EPIPE: its
// reader exited) loses what waits. The thread blocks every signal (EPIPE, never
// SIGPIPE) and is detached: an OutputLines destroyed before its thread has
// written everything leaves it to end with the process.
//
// Thread safety: Add() and Finish() from any thread. TtyProgress (below):
// one thread.
#pragma once

#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <memory>
#include <mutex>
#include <string>

namespace robotalk::cli {

class OutputLines {
 public:
  static constexpr std::size_t kMaxQueuedBytes = std::size_t{4} << 20;

  explicit OutputLines(int fd);
  ~OutputLines();
  OutputLines(const OutputLines&) = delete;
  OutputLines& operator=(const OutputLines&) = delete;

  /// Queues `text` (one or more whole lines, each ending in '\n').
  void Add(std::string text);
  /// Nothing waits to be written (a progress line on the same terminal may
  /// be drawn without tearing a reply line).
  bool idle() const;
  /// Waits, with no limit, until every queued text is written or the
  /// descriptor failed; returns the texts dropped or lost so far.
  std::uint64_t Finish();

 private:
  struct State {
    mutable std::mutex mu;
    std::condition_variable work, idle;
    std::deque<std::string> queue;
    std::size_t queued_bytes = 0;
    std::uint64_t lost = 0;
    bool writing = false, failed = false, stop = false;
    int fd = -1;
    void Run();
  };
  std::shared_ptr<State> state_;
};

/// The progress line on a terminal (stderr when it is one), written through a
/// description of its own opened non-blocking: a terminal that takes nothing
/// (stopped with Ctrl-S, a pty nobody reads) loses progress lines, never the
/// thread that sends frames or the STOP on Ctrl-C (before: it waited in the
/// write, and its heartbeats kept the session and so the motion alive).
class TtyProgress {
 public:
  TtyProgress();
  ~TtyProgress();
  TtyProgress(const TtyProgress&) = delete;
  TtyProgress& operator=(const TtyProgress&) = delete;

  /// Whether stderr is a terminal (the line is drawn).
  bool on() const { return fd_ >= 0; }
  /// Writes what the terminal takes now, nothing more (a torn line at worst).
  void Show(const std::string& text) const;
  void Clear() const { Show("\r\033[K"); }

 private:
  int fd_ = -1;
};

}  // namespace robotalk::cli
