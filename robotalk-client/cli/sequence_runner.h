// Runs a timed sequence (or one command) through the public RobotClient API
// and waits for its END, however long its tasks take, while reporting
// progress and watching for Ctrl-C / SIGTERM (interrupt.h). Used by
// `robotalk send` and `robotalk-logplay replay`.
//
// Sequences run through RobotClient::RunSequence (SequenceHooks): unlike its
// default, nothing here times out while the server keeps answering (a 30 s
// GOTO is waited for); a dead server still ends the wait with TimeoutError
// once the client gives up retransmitting. Every wait wakes at once for its
// reply (no polling slices).
//
// On a signal the runner stops what it started: it stops sending frames,
// sends STOP at once, and (delay mode) a STOP at the start time of every
// frame still queued on the server: the protocol cannot cancel a queued
// command, so each one is ended as soon as it begins.
//
// Thread safety: one runner call per client at a time; callbacks run on the
// calling thread.
#pragma once

#include "interrupt.h"
#include "robotalk/robot_client.h"

#include <atomic>
#include <cstddef>
#include <functional>
#include <optional>
#include <stop_token>
#include <string>
#include <thread>
#include <vector>

namespace robotalk::cli {

using RunProgress = SequenceProgress;

struct RunReport {
  /// One per frame, in the order given; nullopt when never answered (interrupted).
  std::vector<std::optional<Reply>> replies;
  int signal = 0;                          ///< the interrupting signal, 0 when none
  std::string interrupt_note;              ///< what was done about it (STOP sent ...)
  std::optional<Duration> playback_delay;  ///< playback: the server's choice
  /// Delay mode: frames whose outcome is unknown (the client gave up, or the
  /// server instance that had them restarted): index and why, every one of them.
  std::vector<std::pair<std::size_t, std::string>> unknown_outcomes;
};

using ReplyCallback = std::function<void(std::size_t index, const Reply& reply)>;
using ProgressCallback = std::function<void(const RunProgress& progress)>;

/// Sends `frames` in `options.mode` through RobotClient::RunSequence and waits
/// for every reply. `on_reply` gets each reply (delay and playback: in the
/// order given; direct: in time order); `on_progress` is called about every
/// 50 ms. `stop` (default: Ctrl-C / SIGTERM) ends the run at once; the runner
/// then sends STOP (and, delay mode, a STOP for each frame still queued) and
/// says so in RunReport::interrupt_note. Throws TimeoutError / ClientError.
RunReport RunFrames(RobotClient& client, std::vector<TimedCommand> frames, const SequenceOptions& options,
                    const ReplyCallback& on_reply, const ProgressCallback& on_progress,
                    std::stop_token stop = Interrupter::StopToken());

/// Waits for one pending reply with no time limit, calling `on_progress`
/// (time since the wait began) about every 50 ms. Returns nullopt when a
/// signal arrived first. Throws TimeoutError when the client gave up.
std::optional<Reply> AwaitReply(PendingReply& pending, const std::function<void(Duration)>& on_progress);

/// Sends STOP now and waits for its reply (the client's timeout); returns a
/// short account: "STOP sent to pioneer: SUCCESS". Never throws. With
/// `succeeded`, says whether the STOP was answered SUCCESS or MODIFIED.
std::string StopNow(RobotClient& client, bool* succeeded = nullptr);

/// While it lives, the first SIGINT/SIGTERM (`interrupt`) sends `client` a
/// STOP at once from a thread of its own, whatever the tool's thread is doing:
/// a write to a stdout or stderr that takes nothing (a full pipe, a terminal
/// stopped with Ctrl-S) waits for ever, and the CLI's heartbeats would keep
/// the motion alive meanwhile. The tool's own StopNow and its lines follow
/// when it gets there (a second STOP changes nothing). If the tool has not
/// finished (destroyed this) kTakeOver after the signal, the process ends
/// with 128 + signal (SignalIsTheEnd: the status of that end): its session then expires (the server's
/// --session-timeout, 2 s) and the watchdog drops the frames it had queued
/// for later, which one STOP does not cancel. Destruction waits for a STOP
/// being sent (the client's timeouts bound it).
class StopOnInterrupt {
 public:
  static constexpr Duration kTakeOver = std::chrono::seconds(2);

  explicit StopOnInterrupt(RobotClient& client, std::stop_token interrupt = Interrupter::StopToken());

  /// From now on a signal is the command's normal end, not a cut (`send
  /// --hold`: held until Ctrl-C, then STOP): the take-over then ends the
  /// process with that end's status, 0 when its STOP was answered SUCCESS or
  /// MODIFIED, else 1, not 128 + signal.
  void SignalIsTheEnd() { signal_ends_ = true; }

 private:
  std::atomic<bool> signal_ends_{false};  // before sender_, which reads it
  std::jthread sender_;
};

/// "5 s", "0.25 s", "1.5 s": seconds without trailing zeros.
std::string FormatSeconds(double seconds);
inline std::string FormatDuration(Duration d) { return FormatSeconds(ToSeconds(d)); }

/// Rewrites every "<number>.<digits> s" in a message to FormatSeconds form
/// ("no reply within 5.000000 s" -> "no reply within 5 s").
std::string TidyDurations(const std::string& message);
/// An error's text as the tools print it: TidyDurations, its control
/// characters as \xNN (EscapeControls), but a line break followed by two
/// blanks kept (an indented continuation line, never one that looks like a
/// line of its own). It may hold a server's text (in open mode anyone's: a
/// hello's refusal, a STOP's reply message), as a reply's message does
/// (PrintReply).
std::string ErrorText(const std::string& message);

/// A one-line progress bar "[#####.....]  12/40  3.2 s / 8 s" of `width` cells.
std::string ProgressBar(const RunProgress& p, int width = 30);

}  // namespace robotalk::cli
