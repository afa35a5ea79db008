// A log's limiter, shared by the server (issue 19: a driver failing in
// Update logged 231 fault lines in 12 s) and robotalk-ros2 (review8: a flood
// of refused cmd_vel logged a line each). Two rules, applied to every line
// offered:
//   - per line: a line seen again within `repeat_window` of its first
//     printing is counted, not printed; when the window ends one summary
//     says how often it came ("<line> (repeated 230 times in 10 s)") and, if
//     it still comes, the next window starts. A line that stopped coming is
//     forgotten, so it prints in full when it comes back.
//   - per second: at most `lines_per_second` lines are printed; the rest
//     are counted and summarised ("(12 more log lines suppressed in the last
//     second)").
// Summaries are never suppressed. At most `max_tracked` distinct lines are
// remembered (bounded memory); beyond that lines are only rate-limited.
//
// Pure: times come from the caller (a ManualClock in tests).
// Thread safety: none (the server: the ServerDaemon thread; robotalk-ros2
// holds a mutex around it).
#pragma once

#include "robotalk/clock.h"

#include <cstdint>
#include <map>
#include <string>
#include <vector>

namespace robotalk {

struct LogLimiterOptions {
  int lines_per_second = 20;
  Duration repeat_window = std::chrono::seconds(10);
  std::size_t max_tracked = 256;
};

class LogLimiter {
 public:
  explicit LogLimiter(LogLimiterOptions options = {}) : options_(options) {}

  /// Offers `line` at `now`; appends to `out` what is to be printed now (the
  /// line, summaries that fell due, or nothing).
  void Add(const std::string& line, TimePoint now, std::vector<std::string>& out);
  /// Appends the summaries due at `now` (call it every iteration).
  void Tick(TimePoint now, std::vector<std::string>& out);
  /// Appends every pending summary (at shutdown).
  void Flush(TimePoint now, std::vector<std::string>& out);

 private:
  struct Seen {
    TimePoint first{};        // when the current window started
    TimePoint last{};         // the latest repeat
    std::uint64_t count = 0;  // repeats in this window
  };
  void Summarise(TimePoint now, bool all, std::vector<std::string>& out);

  const LogLimiterOptions options_;
  std::map<std::string, Seen> seen_;
  TimePoint next_due_ = TimePoint::max();  // the earliest window end among seen_
  TimePoint second_{};                     // the per-second window
  int lines_ = 0;
  std::uint64_t suppressed_ = 0;
};

}  // namespace robotalk
