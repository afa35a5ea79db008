#include "clock_sync.h"

#include <algorithm>
#include <chrono>

namespace robotalk::client {
namespace {

// a + b on nanosecond counts; nullopt where int64 would overflow.
std::optional<Duration> CheckedAdd(Duration a, Duration b) {
  Duration::rep d = 0;
  if (__builtin_add_overflow(a.count(), b.count(), &d)) return std::nullopt;
  return Duration(d);
}

}  // namespace

bool ClockSync::AddSample(TimePoint t1, TimePoint t2, TimePoint t3, TimePoint t4) {
  // t2 and t3 are whatever the reply said: a forged or corrupt one may put
  // them at the ends of the range, so every difference is checked and a
  // sample whose arithmetic would overflow is absurd, like a negative one.
  const std::optional<Duration> client = CheckedSub(t4, t1), server = CheckedSub(t3, t2);
  if (!client || !server || *client < Duration::zero() || *server < Duration::zero() || *server > *client)
    return false;
  const Duration round_trip = *client - *server;  // 0 <= server <= client: no overflow
  const std::optional<Duration> out = CheckedSub(t2, t1), back = CheckedSub(t3, t4);
  const std::optional<Duration> sum = out && back ? CheckedAdd(*out, *back) : std::nullopt;
  // The offset must also map the client's clock to a server time that exists.
  if (!sum || !CheckedAdd(t4.time_since_epoch(), *sum / 2)) return false;
  ++num_samples_;
  // The sample with the smallest round trip bounds the offset most tightly
  // (its error is at most half its round trip, whatever the path
  // asymmetry), as of when it was taken; since then the clocks may have
  // drifted apart by up to the allowance times its age.
  const Sample fresh{.received = t4, .round_trip = round_trip, .offset = *sum / 2};
  const auto bound = [&](const Sample& x) {
    const double age_s = std::max(0.0, std::chrono::duration<double>(t4 - x.received).count());
    return std::chrono::duration<double>(x.round_trip).count() / 2 + kDriftAllowance * age_s;
  };
  if (!best_ || bound(fresh) < bound(*best_)) {
    best_ = fresh;
    offset_ = fresh.offset;
  }
  return true;
}

}  // namespace robotalk::client
