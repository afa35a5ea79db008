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
  const double t_nom = std::max(s.remaining, 0.0), t_lo = std::clamp(s.soonest, 0.0, t_nom);
  const double tau_nom = std::exp(omega_ * t_nom);
  const double c = std::cos(s.stance.theta), sn = std::sin(s.stance.theta), side = SideSign(s.swing);
  const double ws = p_.w_step, wo = p_.w_offset;
  const double radius = std::max((s.landing - s.foot).norm(), 0.0);
  const auto at = [&](double t) {
    StepTiming r;
    r.remaining = t;
    const double tau = std::exp(omega_ * t);
    r.dcm_at_landing = s.cop + (s.dcm - s.cop) * tau;
    // For this tau: min ws |u - u_nom|^2 + wo |xi_T - u - b_nom|^2, u in the box.
    const Eigen::Vector2d want = (ws * s.landing + wo * (r.dcm_at_landing - s.offset)) / (ws + wo);
    const Eigen::Vector2d d = want - s.stance.xy();
    const Eigen::Vector2d local(c * d.x() + sn * d.y(), -sn * d.x() + c * d.y());
    const Eigen::Vector2d got(std::clamp(local.x(), -p_.reach_back, p_.reach),
                              side * std::clamp(side * local.y(), p_.min_width, p_.max_width));
    r.landing = s.stance.xy() + Eigen::Vector2d(c * got.x() - sn * got.y(), sn * got.x() + c * got.y());
    if (s.foot_speed > 0) {  // what the swing foot still reaches from where it is
      const double far = std::max(radius, s.foot_speed * t);
      const Eigen::Vector2d to = r.landing - s.foot;
      if (to.norm() > far) r.landing = s.foot + to * (far / to.norm());
    }
    r.fits = (r.landing - want).norm() < 1e-9;
    const Eigen::Vector2d b = r.dcm_at_landing - r.landing;
    r.cost = ws * (r.landing - s.landing).squaredNorm() + wo * (b - s.offset).squaredNorm() +
             p_.w_time * (tau - tau_nom) * (tau - tau_nom);
    return r;
  };
  StepTiming best = at(t_nom);
  const int n = static_cast<int>(std::ceil((t_nom - t_lo) / p_.resolution - 1e-9));
  for (int i = 1; i <= n; ++i) {
    const StepTiming r = at(std::max(t_lo, t_nom - p_.resolution * i));
    if (r.cost < best.cost) best = r;
  }
  return best;
}

}  // namespace robotalk::walking
