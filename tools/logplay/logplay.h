// The pieces of robotalk-logplay (docs/logplay.md): reading an LCM log with
// LCM's own log API, turning a recovered timeline into sequence-file lines or
// client frames, and the four subcommands. Errors: LogError (bad log or
// selection), robotalk::cli::UsageError (bad options), client errors on replay.
#pragma once

#include "robotalk/lcm_log.h"
#include "robotalk/robot_client.h"
#include "session_log.h"

#include <iosfwd>
#include <limits>
#include <map>
#include <string>
#include <vector>

namespace robotalk::logplay {

/// Reads every intact event of an LCM log (LcmLogReader) into a SessionLog;
/// a damaged stretch of the file is one of its rejected entries, naming the
/// byte. Throws LogError when the file cannot be opened.
SessionLog ReadLog(const std::string& path);
/// The checked reader of every robotalk-logplay command (robotalk/lcm_log.h);
/// LogError when the file cannot be opened.
LcmLogReader OpenLog(const std::string& path);

/// The log's rejected entries (SessionLog::rejected(): each names the event,
/// its channel and what was wrong), one line each after `prefix`; nothing
/// when every entry was used.
void PrintRejected(const SessionLog& log, const std::string& prefix, std::ostream& out);

/// How recorded commands become frames again.
struct FrameOptions {
  std::map<std::string, std::string> rename;  ///< --map old=new: joint / frame names
  double from_s = 0;                          ///< --window A:B, on the recorded offsets
  double to_s = std::numeric_limits<double>::infinity();
  double speed = 1.0;  ///< --speed: offsets are divided by it (a waypoint's velocities times it,
                       ///< accelerations times its square)
};

/// The selected frames, renamed, windowed (re-based to the window's start)
/// and scaled, each with its package's interpolation (step for a frame sent
/// without a start time). Throws LogError when the window holds nothing.
std::vector<TimedCommand> ToFrames(const Timeline& timeline, const FrameOptions& options);

/// A sequence file `robotalk send --file` plays: a comment header, the
/// set-points' interpolation line (none for step; a frame whose
/// interpolation is nullopt takes the file's), then one "<offset>
/// FormatCommandWords" line per frame. Throws LogError naming the frame for a
/// target that is not one word of the file, and for set-points of two
/// interpolations.
std::string FormatSequence(const std::vector<TimedCommand>& frames, const std::string& header);

/// `info`: channels, span, servers, robots, clients and their command streams.
void PrintInfo(const SessionLog& log, const std::string& path, std::ostream& out);

/// "; interpolation cubic 40, step 2": how many of `each` travelled in
/// packages of each interpolation; "" when all are step (info, replay).
std::string DescribeInterpolations(const std::vector<Interpolation>& each);

/// "direct", "delay", "playback".
const char* ModeName(RequestMode mode);

/// "old=new" -> {old, new}; throws UsageError.
std::pair<std::string, std::string> ParseRename(const std::string& text);
/// "A:B" (either side may be empty) -> {A, B}; throws UsageError.
std::pair<double, double> ParseWindow(const std::string& text);

struct ReplayOptions {
  std::string robot;  ///< the live robot to drive
  Selection selection;
  FrameOptions frames;
  SequenceOptions sequence;  ///< mode, delay
  std::string url;
  double timeout_s = 5;
  bool progress = false;  ///< draw a progress bar on stderr
};

/// `replay`: sends the selected commands through RobotClient and waits for
/// every reply; prints a summary of signals. Returns the exit status (0 all
/// SUCCESS/MODIFIED, 1 otherwise, 128+signal when interrupted).
int Replay(const SessionLog& log, const ReplayOptions& options, std::ostream& out);

struct RecordOptions {
  std::string output;           ///< the LCM log to write (lcm-logger's format)
  std::string url;              ///< RoboTalk URL; "" = $LCM_DEFAULT_URL or LCM's default
  std::string channels = ".*";  ///< LCM channel regex (whole name) of what is kept
  Duration duration{0};         ///< 0: until SIGINT/SIGTERM (cli::Interrupter, deferred)
};

struct RecordResult {
  std::uint64_t events = 0;
  std::uint64_t bytes = 0;
  int signal = 0;  ///< the signal that stopped it, or 0
  /// Events dispatched too late to be written in receipt order (ReceiptOrder::late).
  std::uint64_t late = 0;
  /// Events (and bytes) written before their 0.25 s sort was over because
  /// the sort held more than its bound (ReceiptOrder::early): none dropped.
  std::uint64_t early = 0, early_bytes = 0;
};

/// `record`: every channel of every lane of `options.url` (the split
/// layout's 66 ports, or the one URL of the single layout) into one LCM log,
/// each event stamped with LCM's receive time and written in receipt order
/// (held up to 0.25 s to sort the lanes), until the duration is over or a
/// signal arrives; prints one line to `progress` when it starts.
/// Throws LogError (cannot write) or TransportError (bad URL).
RecordResult Record(const RecordOptions& options, std::ostream& progress);

}  // namespace robotalk::logplay
