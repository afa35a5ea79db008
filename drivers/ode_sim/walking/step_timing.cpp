// Step timing adaptation with step location: see step_timing.h.
#include "walking/step_timing.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace robotalk::walking {

StepTimingAdapter::StepTimingAdapter(double omega, StepTimingParams params) : omega_(omega), p_(params) {
  if (!(omega > 0) || !(p_.w_step > 0) || !(p_.w_offset > 0) || !(p_.w_time >= 0) || !(p_.reach > 0) ||
      !(p_.reach_back >= 0) || !(p_.min_width > 0) || !(p_.max_width >= p_.min_width) ||
      !(p_.resolution > 0)) {
    throw std::invalid_argument(
        "StepTimingAdapter: omega, w_step, w_offset, reach, min_width and resolution must be > 0, w_time and "
        "reach_back >= 0, max_width >= min_width");
  }
}

StepTiming StepTimingAdapter::Solve(const StepSituation& s) const {
  // Not yet adapted: the plan's landing and time (the reproducer's base).
  StepTiming r;
  r.remaining = std::max(s.remaining, 0.0);
  r.landing = s.landing;
  r.dcm_at_landing = s.cop + (s.dcm - s.cop) * std::exp(omega_ * r.remaining);
  r.fits = (r.dcm_at_landing - r.landing - s.offset).norm() < 1e-9;
  return r;
}

}  // namespace robotalk::walking
