// Foot damping control: see foot_damping.h.
#include "walking/foot_damping.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace robotalk::walking {
namespace {

// The centre of a foot's sole rectangle, in the foot's frame.
Eigen::Vector2d SoleCentre(const SoleRect& s) { return {0.5 * (s.front - s.back), 0}; }

// p (foot frame) clamped into the sole rectangle shrunk by margin (never past its centre).
Eigen::Vector2d IntoSole(const Eigen::Vector2d& p, const SoleRect& s, double margin) {
  const Eigen::Vector2d c = SoleCentre(s);
  const double hx = std::max(0.0, 0.5 * (s.front + s.back) - margin),
               hy = std::max(0.0, s.half_width - margin);
  return {std::clamp(p.x(), c.x() - hx, c.x() + hx), std::clamp(p.y(), -hy, hy)};
}

Eigen::Vector2d ToFoot(const Pose2& f, const Eigen::Vector2d& p) {
  const double c = std::cos(f.theta), s = std::sin(f.theta);
  const Eigen::Vector2d d = p - f.xy();
  return {c * d.x() + s * d.y(), -s * d.x() + c * d.y()};
}

}  // namespace

FootTargets DistributeZmp(const Eigen::Vector2d& zmp, const std::array<Pose2, 2>& feet,
                          const std::array<bool, 2>& on_ground, const SoleRect& sole, double margin) {
  FootTargets t;
  const Eigen::Vector2d centre = SoleCentre(sole);
  t.cop = {centre, centre};
  if (on_ground[0] != on_ground[1]) {
    const size_t i = on_ground[0] ? 0 : 1;
    t.share[i] = 1;
    t.cop[i] = IntoSole(ToFoot(feet[i], zmp), sole, margin);
    return t;
  }
  if (!on_ground[0]) return t;
  const Eigen::Vector2d a = feet[0].Apply(centre.x(), 0), b = feet[1].Apply(centre.x(), 0);
  const Eigen::Vector2d ab = b - a;
  const double len2 = ab.squaredNorm();
  const double alpha = len2 > 0 ? std::clamp((zmp - a).dot(ab) / len2, 0.0, 1.0) : 0.5;
  t.share = {1 - alpha, alpha};
  const Eigen::Vector2d rest = zmp - (a + alpha * ab);  // the ZMP's offset from the line between the soles
  for (size_t i = 0; i < 2; ++i) {
    const Pose2 yaw{0, 0, feet[i].theta};
    t.cop[i] = IntoSole(centre + ToFoot(yaw, rest), sole, margin);
  }
  return t;
}

double AdmittanceFor(double stiffness, double length) {
  if (!(std::isfinite(stiffness) && stiffness > 0) || !(std::isfinite(length) && length > 0))
    throw std::invalid_argument("AdmittanceFor: stiffness and length must be > 0");
  const double scale =
      kTunedSoleStiffness * kTunedSoleLength * kTunedSoleLength / (stiffness * length * length);
  return std::abs(scale - 1) < 1e-3 ? kTunedAdmittance : kTunedAdmittance * scale;
}

FootDamping::FootDamping(double weight, double dt, FootDampingGains gains)
    : weight_(weight), dt_(dt), gains_(gains) {
  const auto positive = [](double v) { return std::isfinite(v) && v > 0; };
  if (!positive(weight)) throw std::invalid_argument("FootDamping: weight must be > 0 N");
  if (!positive(dt)) throw std::invalid_argument("FootDamping: dt must be > 0 s");
  if (!positive(gains.admittance) || !positive(gains.leak) || !positive(gains.air_return) ||
      !positive(gains.max_angle) || !positive(gains.max_rate) || !(gains.contact_force >= 0) ||
      !positive(gains.loaded) || gains.loaded > 1) {
    throw std::invalid_argument(
        "FootDamping: admittance, leak, air_return, max_angle, max_rate must be > 0, contact_force >= 0 and "
        "loaded in (0, 1]");
  }
}

size_t FootDamping::Index(int foot) {
  if (foot != 0 && foot != 1)
    throw std::invalid_argument("FootDamping: foot " + std::to_string(foot) + " is not 0 or 1");
  return static_cast<size_t>(foot);
}

void FootDamping::Reset() {
  for (size_t i = 0; i < 2; ++i) {
    offset_[i].setZero();
    landing_[i] = false;
    in_contact_[i] = false;
  }
}

const Eigen::Vector2d& FootDamping::Update(int foot, const Eigen::Vector2d& desired_cop,
                                           const FootWrench& measured) {
  const size_t i = Index(foot);
  Eigen::Vector2d& off = offset_[i];
  Eigen::Vector2d rate;
  const bool contact = std::isfinite(measured.force) && measured.force >= gains_.contact_force &&
                       measured.cop.allFinite() && desired_cop.allFinite();
  if (!contact) {
    rate = -off / gains_.air_return;
    landing_[i] = false;
  } else {
    if (!in_contact_[i]) landing_[i] = true;
    if (measured.force >= gains_.loaded * weight_) landing_[i] = false;
    // rad/s per m of CoP error: A f_z, at least a full load's while landing.
    const double gain =
        gains_.admittance * (landing_[i] ? std::max(measured.force, weight_) : measured.force);
    const Eigen::Vector2d e = measured.cop - desired_cop;
    rate = Eigen::Vector2d(gain * e.y(), -gain * e.x()) - off / gains_.leak;
  }
  in_contact_[i] = contact;
  const double r = gains_.max_rate;
  off += dt_ * rate.cwiseMax(-r).cwiseMin(r);
  off = off.cwiseMax(-gains_.max_angle).cwiseMin(gains_.max_angle);
  return off;
}

const Eigen::Vector2d& FootDamping::Relax(int foot) {
  const size_t i = Index(foot);
  const double r = gains_.max_rate;
  offset_[i] += dt_ * (-offset_[i] / gains_.leak).cwiseMax(-r).cwiseMin(r);
  landing_[i] = false;
  in_contact_[i] = true;  // a foot on the ground when the loop comes back is not landing
  return offset_[i];
}

ForceDifferenceGains ForceDifferenceFor(double stiffness, double rate) {
  if (!(std::isfinite(stiffness) && stiffness > 0) || !(std::isfinite(rate) && rate > 0))
    throw std::invalid_argument("ForceDifferenceFor: stiffness and rate must be > 0");
  ForceDifferenceGains g;
  // h moves each foot by h/2: the difference of forces changes by stiffness * h.
  g.admittance = rate / stiffness;
  return g;
}

ForceDifference::ForceDifference(double dt, ForceDifferenceGains gains) : dt_(dt), gains_(gains) {
  const auto positive = [](double v) { return std::isfinite(v) && v > 0; };
  if (!positive(dt)) throw std::invalid_argument("ForceDifference: dt must be > 0 s");
  if (!positive(gains.admittance) || !positive(gains.leak) || !positive(gains.air_return) ||
      !positive(gains.max_height) || !positive(gains.max_rate)) {
    throw std::invalid_argument(
        "ForceDifference: admittance, leak, air_return, max_height and max_rate must be > 0");
  }
}

double ForceDifference::Move(double rate) {
  h_ += dt_ * std::clamp(rate, -gains_.max_rate, gains_.max_rate);
  h_ = std::clamp(h_, -gains_.max_height, gains_.max_height);
  return h_;
}

double ForceDifference::Update(const std::array<double, 2>& share, const std::array<double, 2>& force,
                               bool double_support) {
  const bool valid = std::isfinite(share[0]) && std::isfinite(share[1]) && std::isfinite(force[0]) &&
                     std::isfinite(force[1]);
  if (!double_support || !valid) return Move(-h_ / gains_.air_return);
  const double total = force[0] + force[1];
  const double error = (force[0] - force[1]) - (share[0] - share[1]) * total;
  return Move(gains_.admittance * error - h_ / gains_.leak);
}

double ForceDifference::Relax() { return Move(-h_ / gains_.leak); }

}  // namespace robotalk::walking
