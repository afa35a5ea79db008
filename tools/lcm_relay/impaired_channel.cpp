#include "impaired_channel.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

namespace robotalk::relay {
namespace {

void CheckProbability(const char* field, double p) {
  if (!(p >= 0.0 && p <= 1.0)) {
    throw std::invalid_argument("Validate(ImpairmentParams): " + std::string(field) + " = " +
                                std::to_string(p) + " is not a probability in [0, 1]");
  }
}

void CheckDuration(const char* field, Duration d) {
  if (d < Duration::zero()) {
    throw std::invalid_argument("Validate(ImpairmentParams): " + std::string(field) + " = " +
                                std::to_string(ToSeconds(d)) + " s is negative");
  }
}

}  // namespace

void Validate(const ImpairmentParams& params) {
  CheckProbability("loss", params.loss);
  CheckProbability("duplicate", params.duplicate);
  CheckProbability("reorder", params.reorder);
  CheckDuration("latency", params.latency);
  CheckDuration("jitter", params.jitter);
  CheckDuration("reorder_delay", params.reorder_delay);
  CheckDuration("congestion_max", params.congestion_max);
  CheckDuration("outage_at", params.outage_at);
  CheckDuration("outage", params.outage);
}

ImpairedChannel::ImpairedChannel(const ImpairmentParams& params, std::uint64_t seed)
    : params_(params), rng_(seed) {
  Validate(params_);
}

double ImpairedChannel::Uniform01() {
  // The top 53 bits as a double in [0, 1): identical on every platform,
  // unlike std::uniform_real_distribution whose algorithm is unspecified.
  return static_cast<double>(rng_() >> 11) * 0x1.0p-53;
}

Duration ImpairedChannel::CopyDelay(bool reordered, double u1, double u2) const {
  const double jitter = static_cast<double>(params_.jitter.count());
  double offset = 0.0;  // nanoseconds
  if (params_.jitter_distribution == JitterDistribution::kUniform) {
    offset = (2.0 * u1 - 1.0) * jitter;
  } else {
    // Box-Muller; 1 - u1 is in (0, 1] so the log is finite. Clamped at 3 sigma
    // so the delay has a hard bound (the clamp holds 0.27 % of the mass).
    const double z = std::sqrt(-2.0 * std::log(1.0 - u1)) * std::cos(2.0 * std::numbers::pi * u2);
    offset = std::clamp(z, -3.0, 3.0) * jitter;
  }
  Duration delay = params_.latency + Duration(static_cast<Duration::rep>(std::llround(offset)));
  delay = std::max(delay, Duration::zero());  // a copy never leaves before it arrived
  if (reordered) delay += params_.reorder_delay;
  return delay;
}

Releases ImpairedChannel::Admit(TimePoint arrival) {
  // Always draw the same numbers in the same order (see the header).
  const double u_loss = Uniform01();
  const double u_dup = Uniform01();
  const double u_service = Uniform01();
  std::array<double, 2> u_reorder{}, u_j1{}, u_j2{};
  for (int i = 0; i < 2; ++i) {
    u_reorder[i] = Uniform01();
    u_j1[i] = Uniform01();
    u_j2[i] = Uniform01();
  }

  ++stats_.arrived;
  Releases r;
  if (u_loss < params_.loss) {
    r.lost = true;
    ++stats_.lost;
    return r;
  }

  // Single-server FIFO link: wait for the previous message, then be served.
  // Without congestion there is no link at all (not even FIFO order).
  if (params_.congestion_max > Duration::zero()) {
    const TimePoint start = std::max(arrival, link_free_);
    const auto service = Duration(static_cast<Duration::rep>(
        std::llround(u_service * static_cast<double>(params_.congestion_max.count()))));
    link_free_ = start + service;
    r.link_exit = link_free_;
  } else {
    r.link_exit = arrival;
  }

  r.duplicated = u_dup < params_.duplicate;
  r.count = r.duplicated ? 2 : 1;
  if (r.duplicated) ++stats_.duplicated;
  for (int i = 0; i < r.count; ++i) {
    r.reordered[i] = u_reorder[i] < params_.reorder;
    if (r.reordered[i]) ++stats_.reordered;
    r.at[i] = r.link_exit + CopyDelay(r.reordered[i], u_j1[i], u_j2[i]);
  }
  stats_.copies += static_cast<std::uint64_t>(r.count);
  if (!first_arrival_) first_arrival_ = arrival;
  if (params_.outage > Duration::zero()) {
    const TimePoint from = *first_arrival_ + params_.outage_at, until = from + params_.outage;
    if (arrival >= from && arrival < until) {
      ++stats_.held;
      for (int i = 0; i < r.count; ++i) r.at[i] = std::max(r.at[i], until);
    }
  }
  return r;
}

}  // namespace robotalk::relay
