#include "playback_estimator.h"

#include <algorithm>
#include <cmath>

namespace robotalk {

PlaybackEstimator::PlaybackEstimator(std::size_t total_frames, Duration duration, PlaybackEstimatorOptions options)
    : total_(std::max<std::size_t>(total_frames, 1)), duration_(duration), options_(options) {
  const auto by_fraction = static_cast<std::size_t>(std::ceil(options_.fraction * static_cast<double>(total_)));
  needed_ = std::min(total_, std::max(options_.min_frames, by_fraction));
  frames_.reserve(needed_);
}

void PlaybackEstimator::Add(Duration offset, TimePoint arrival) { frames_.push_back({offset, arrival}); }

Duration PlaybackEstimator::mean_command_interval() const {
  if (frames_.size() < 2) return Duration(0);
  auto [lo, hi] = std::minmax_element(frames_.begin(), frames_.end(),
                                      [](const Frame& a, const Frame& b) { return a.offset < b.offset; });
  return (hi->offset - lo->offset) / static_cast<Duration::rep>(frames_.size() - 1);
}

Duration PlaybackEstimator::mean_arrival_interval() const {
  if (frames_.size() < 2) return Duration(0);
  auto [lo, hi] = std::minmax_element(frames_.begin(), frames_.end(),
                                      [](const Frame& a, const Frame& b) { return a.arrival < b.arrival; });
  return (hi->arrival - lo->arrival) / static_cast<Duration::rep>(frames_.size() - 1);
}

Duration PlaybackEstimator::arrival_interval_bound() const {
  // Few frames give a noisy mean: take its upper confidence bound (mean +
  // z · s / sqrt(n)), since running dry is worse than starting a little later.
  if (frames_.size() < 3) return mean_arrival_interval();
  std::vector<TimePoint> arrivals;
  arrivals.reserve(frames_.size());
  for (const Frame& f : frames_) arrivals.push_back(f.arrival);
  std::sort(arrivals.begin(), arrivals.end());
  const double n = static_cast<double>(arrivals.size() - 1);
  const double mean = ToSeconds(arrivals.back() - arrivals.front()) / n;
  double variance = 0;
  for (std::size_t i = 1; i < arrivals.size(); ++i) {
    const double gap = ToSeconds(arrivals[i] - arrivals[i - 1]);
    variance += (gap - mean) * (gap - mean);
  }
  variance /= n - 1;
  return FromSeconds(mean + options_.confidence_z * std::sqrt(variance / n));
}

TimePoint PlaybackEstimator::StartTime() const {
  // Each frame seen must be there before it plays: start >= a_i - o_i ("lag").
  const Frame* first = &frames_.front();
  for (const Frame& f : frames_) {
    if (f.offset < first->offset) first = &f;
  }
  const TimePoint first_lag = first->arrival - first->offset;
  // If the channel is slower than the sequence, the lag grows by (T_a - T_c)
  // per frame: project it to the last of the declared frames.
  const Duration command_interval = mean_command_interval();
  const Duration growth = std::max(Duration(0), arrival_interval_bound() - command_interval);
  const auto line = [&](const Frame& f) {
    const double index = command_interval.count() > 0 ? ToSeconds(f.offset - first->offset) / ToSeconds(command_interval) : 0.0;
    return first_lag + FromSeconds(ToSeconds(growth) * index);
  };
  // Jitter: how far any frame lagged behind that line.
  Duration jitter{0};
  TimePoint lag = first_lag;
  for (const Frame& f : frames_) {
    lag = std::max(lag, f.arrival - f.offset);
    jitter = std::max(jitter, (f.arrival - f.offset) - line(f));
  }
  const TimePoint projected = first_lag + growth * static_cast<Duration::rep>(total_ - 1);
  return std::max(lag, projected + jitter) + options_.margin;
}
}  // namespace robotalk
