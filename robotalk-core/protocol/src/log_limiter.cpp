#include "robotalk/log_limiter.h"

#include <algorithm>
#include <cstdio>

namespace robotalk {

void LogLimiter::Add(const std::string& line, TimePoint now, std::vector<std::string>& out) {
  Tick(now, out);
  if (auto it = seen_.find(line); it != seen_.end()) {
    ++it->second.count;
    it->second.last = now;
    return;
  }
  if (seen_.size() < options_.max_tracked) {
    seen_.emplace(line, Seen{now, now, 0});
    next_due_ = std::min(next_due_, now + options_.repeat_window);
  }
  if (++lines_ > options_.lines_per_second) {
    ++suppressed_;
    return;
  }
  out.push_back(line);
}

void LogLimiter::Tick(TimePoint now, std::vector<std::string>& out) {
  if (now - second_ >= std::chrono::seconds(1)) {
    if (suppressed_ > 0) {
      out.push_back("(" + std::to_string(suppressed_) + " more log lines suppressed in the last second)");
    }
    second_ = now;
    lines_ = 0;
    suppressed_ = 0;
  }
  if (now >= next_due_) Summarise(now, false, out);
}

void LogLimiter::Flush(TimePoint now, std::vector<std::string>& out) {
  Tick(now, out);
  Summarise(now, true, out);
}

void LogLimiter::Summarise(TimePoint now, bool all, std::vector<std::string>& out) {
  next_due_ = TimePoint::max();
  for (auto it = seen_.begin(); it != seen_.end();) {
    Seen& s = it->second;
    if (!all && now - s.first < options_.repeat_window) {
      next_due_ = std::min(next_due_, s.first + options_.repeat_window);
      ++it;
      continue;
    }
    if (s.count == 0) {  // it stopped coming: forget it
      it = seen_.erase(it);
      continue;
    }
    char span[64];
    std::snprintf(span, sizeof span, "%.3g s", ToSeconds(s.last - s.first));
    out.push_back(it->first + " (repeated " + std::to_string(s.count) + (s.count == 1 ? " time" : " times") +
                  " in " + span + ")");
    s = Seen{now, now, 0};  // still coming: a new window
    next_due_ = std::min(next_due_, now + options_.repeat_window);
    ++it;
  }
}

}  // namespace robotalk
