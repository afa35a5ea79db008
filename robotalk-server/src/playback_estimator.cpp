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

double PlaybackEstimator::lag_growth_bound() const {
  // Each frame's lag behind its own offset, l_i = a_i - o_i, as a line in the
  // offset: l(o) = l0 + b·o. A channel that keeps up has b ≈ 0; a slower one
  // b = T_a/T_c - 1 > 0. Bursts (several frames at one offset, one package)
  // do not disturb it, unlike a mean of arrival gaps. The slope is taken at
  // the upper bound of its confidence interval: a few frames give a noisy
  // slope, and running dry costs more than starting a little later.
  const double n = static_cast<double>(frames_.size());
  if (frames_.size() < 2) return 0.0;
  double mean_o = 0, mean_l = 0;
  for (const Frame& f : frames_) {
    mean_o += ToSeconds(f.offset) / n;
    mean_l += ToSeconds(f.arrival.time_since_epoch() - f.offset) / n;
  }
  double sxx = 0, sxy = 0;
  for (const Frame& f : frames_) {
    const double dx = ToSeconds(f.offset) - mean_o;
    sxx += dx * dx;
    sxy += dx * (ToSeconds(f.arrival.time_since_epoch() - f.offset) - mean_l);
  }
  if (sxx <= 0) return 0.0;  // every frame at one offset: no rate to see yet
  const double slope = sxy / sxx;
  double standard_error = 0;
  if (frames_.size() > 2) {
    double residuals = 0;
    for (const Frame& f : frames_) {
      const double r = ToSeconds(f.arrival.time_since_epoch() - f.offset) - mean_l - slope * (ToSeconds(f.offset) - mean_o);
      residuals += r * r;
    }
    standard_error = std::sqrt(residuals / (n - 2) / sxx);
  }
  return std::max(0.0, slope + options_.confidence_z * standard_error);
}

TimePoint PlaybackEstimator::StartTime() const {
  // Frames seen must be there before they play: start >= a_i - o_i.
  TimePoint lag = TimePoint::min();
  Duration last_offset = Duration::min();
  for (const Frame& f : frames_) {
    lag = std::max(lag, f.arrival - f.offset);
    last_offset = std::max(last_offset, f.offset);
  }
  // Frames still to come lag more if the channel is slower than the sequence:
  // project the worst lag so far along the growth bound to the last frame.
  const double growth = lag_growth_bound();
  const TimePoint projected = lag + FromSeconds(growth * ToSeconds(duration_ - std::min(duration_, last_offset)));
  return projected + options_.margin;
}

}  // namespace robotalk
