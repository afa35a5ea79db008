// RoboTalk's one clock abstraction. Every time inside a process is a
// TimePoint / Duration (std::chrono); only LCM messages carry int64
// microseconds, converted at the edge by ToWireMicros / FromWireMicros, which
// check the range (a wire value is untrusted input; overflowing it is UB).
//
// Thread safety: Now() may be called from any thread on every implementation.
#pragma once

#include "robotalk/error.h"

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <optional>
#include <string>

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

/// Another clock moved by a fixed offset: a client's clock that disagrees
/// with the server's, or a server clock ahead of the steady clock. `base` must
/// outlive it.
class OffsetClock final : public Clock {
 public:
  OffsetClock(const Clock& base, Duration offset) : base_(base), offset_(offset) {}
  TimePoint Now() const override { return base_.Now() + offset_; }

 private:
  const Clock& base_;
  Duration offset_;
};

/// The largest |microseconds| a TimePoint / Duration (int64 nanoseconds) holds:
/// about ±292 years. Wire values beyond it cannot be represented.
inline constexpr std::int64_t kMaxWireMicros = INT64_MAX / 1000;

/// Wire microseconds -> Duration; nullopt when |us| > kMaxWireMicros (the
/// nanosecond count would overflow). Never undefined behaviour.
inline std::optional<Duration> TryDurationFromWireMicros(std::int64_t us) {
  if (us > kMaxWireMicros || us < -kMaxWireMicros) return std::nullopt;
  return Duration(us * 1000);
}

/// Wire microseconds -> Duration. Throws ProtocolError naming `field` and the
/// value when out of range ("command 7: start_time_us 18446744073709552 us is
/// out of range (|t| <= 9223372036854775 us)").
inline Duration DurationFromWireMicros(std::int64_t us, const std::string& field = "time") {
  if (auto d = TryDurationFromWireMicros(us)) return *d;
  throw ProtocolError(field + " " + std::to_string(us) +
                      " us is out of range (|t| <= " + std::to_string(kMaxWireMicros) + " us)");
}

/// Wire microseconds (LCM int64 fields) -> TimePoint. Throws ProtocolError
/// naming `field` and the value when out of range.
inline TimePoint FromWireMicros(std::int64_t us, const std::string& field = "time") {
  return TimePoint(DurationFromWireMicros(us, field));
}

/// TimePoint / Duration -> wire microseconds, truncated toward zero. Cannot
/// overflow (it divides).
inline std::int64_t ToWireMicros(TimePoint t) {
  return std::chrono::duration_cast<std::chrono::microseconds>(t.time_since_epoch()).count();
}
inline std::int64_t ToWireMicros(Duration d) {
  return std::chrono::duration_cast<std::chrono::microseconds>(d).count();
}

/// a - b, saturated at Duration's range instead of overflowing: a start time
/// from the wire may lie up to ±292 years away, and TimePoint::min() /
/// max() stand for "at once" / "never".
inline Duration SaturatingSub(TimePoint a, TimePoint b) {
  Duration::rep d = 0;
  if (__builtin_sub_overflow(a.time_since_epoch().count(), b.time_since_epoch().count(), &d))
    return a > b ? Duration::max() : Duration::min();
  return Duration(d);
}

/// a - b, or nullopt where it would overflow (for times from the wire that
/// must be refused rather than saturated: a clock sample, a delay).
inline std::optional<Duration> CheckedSub(TimePoint a, TimePoint b) {
  Duration::rep d = 0;
  if (__builtin_sub_overflow(a.time_since_epoch().count(), b.time_since_epoch().count(), &d))
    return std::nullopt;
  return Duration(d);
}

/// Seconds as a double, for printing and for maths on rates.
inline double ToSeconds(Duration d) { return std::chrono::duration<double>(d).count(); }
/// The largest |seconds| FromSeconds() accepts: a Duration (int64
/// nanoseconds) holds about ±292 years.
inline constexpr double kMaxSeconds = 9.2e9;

/// Seconds -> Duration, rounded to the nanosecond. Throws robotalk::Error for
/// NaN and infinities ("FromSeconds: nan s is not a finite time") and for
/// magnitudes beyond kMaxSeconds, naming the limit ("FromSeconds: 1e+12 s is
/// out of range: a time holds at most +-9.2e+09 s (292 years)"); a cast
/// would be UB.
inline Duration FromSeconds(double s) {
  if (!(s > -kMaxSeconds && s < kMaxSeconds)) {
    char text[160];
    if (std::isfinite(s)) {  // finite: name the limit
      std::snprintf(text, sizeof text,
                    "FromSeconds: %g s is out of range: a time holds at most +-%g s (292 years)", s,
                    kMaxSeconds);
    } else {
      std::snprintf(text, sizeof text, "FromSeconds: %g s is not a finite time", s);
    }
    throw Error(text);
  }
  return std::chrono::duration_cast<Duration>(std::chrono::duration<double>(s));
}

}  // namespace robotalk
