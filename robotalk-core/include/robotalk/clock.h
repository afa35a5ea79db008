// RoboTalk's one clock abstraction. Every time inside a process is a
// TimePoint / Duration (std::chrono); only LCM messages carry int64
// microseconds, converted at the edge by ToWireMicros / FromWireMicros.
//
// Thread safety: Now() may be called from any thread on every implementation.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>

namespace robotalk {

using Duration = std::chrono::nanoseconds;
/// A point on the server's (or client's) monotonic timeline.
using TimePoint = std::chrono::time_point<std::chrono::steady_clock, Duration>;

class Clock {
 public:
  virtual ~Clock() = default;
  virtual TimePoint Now() const = 0;
};

/// The real monotonic clock (std::chrono::steady_clock).
class SteadyClock final : public Clock {
 public:
  TimePoint Now() const override {
    return std::chrono::time_point_cast<Duration>(std::chrono::steady_clock::now());
  }
};

/// A clock that moves only when told to: for tests and simulated time.
class ManualClock final : public Clock {
 public:
  explicit ManualClock(TimePoint start = TimePoint(std::chrono::seconds(1000)))
      : now_(start.time_since_epoch().count()) {}
  TimePoint Now() const override { return TimePoint(Duration(now_.load())); }
  void Set(TimePoint t) { now_.store(t.time_since_epoch().count()); }
  void Advance(Duration d) { now_.fetch_add(d.count()); }

 private:
  std::atomic<Duration::rep> now_;
};

/// Microseconds on the wire (LCM int64 fields) <-> TimePoint.
inline std::int64_t ToWireMicros(TimePoint t) {
  return std::chrono::duration_cast<std::chrono::microseconds>(t.time_since_epoch()).count();
}
inline TimePoint FromWireMicros(std::int64_t us) {
  return TimePoint(std::chrono::duration_cast<Duration>(std::chrono::microseconds(us)));
}
inline std::int64_t ToWireMicros(Duration d) {
  return std::chrono::duration_cast<std::chrono::microseconds>(d).count();
}

/// Seconds as a double, for printing and for maths on rates.
inline double ToSeconds(Duration d) { return std::chrono::duration<double>(d).count(); }
inline Duration FromSeconds(double s) {
  return std::chrono::duration_cast<Duration>(std::chrono::duration<double>(s));
}

}  // namespace robotalk
