#include "clock_sync.h"

namespace robotalk::client {

bool ClockSync::AddSample(TimePoint t1, TimePoint t2, TimePoint t3, TimePoint t4) {
  const Duration round_trip = (t4 - t1) - (t3 - t2);
  if (t4 < t1 || t3 < t2 || round_trip < Duration::zero()) return false;
  ++num_samples_;
  // The sample with the smallest round trip bounds the offset most tightly:
  // its error is at most half its round trip, whatever the path asymmetry.
  if (!best_round_trip_ || round_trip < *best_round_trip_) {
    best_round_trip_ = round_trip;
    offset_ = ((t2 - t1) + (t3 - t4)) / 2;
  }
  return true;
}

}  // namespace robotalk::client
