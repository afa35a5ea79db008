// DCM stabilizer: see dcm_stabilizer.h.
#include "walking/dcm_stabilizer.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace robotalk::walking {
namespace {

double Cross(const Eigen::Vector2d& a, const Eigen::Vector2d& b) { return a.x() * b.y() - a.y() * b.x(); }

// The closest point of segment [a, b] to p.
Eigen::Vector2d OnSegment(const Eigen::Vector2d& p, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  const Eigen::Vector2d ab = b - a;
  const double len2 = ab.squaredNorm();
  const double s = len2 > 0 ? std::clamp((p - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
  return a + s * ab;
}

}  // namespace

Eigen::Vector2d ClampToPolygon(const Eigen::Vector2d& p, std::span<const Eigen::Vector2d> poly,
                               double margin) {
  const size_t n = poly.size();
  if (n == 0) return p;
  if (n == 1) return poly[0];
  // Shrink: move each edge inward by margin (a convex polygon stays convex;
  // for a polygon thinner than 2 margin the centroid is the answer).
  Eigen::Vector2d centroid = Eigen::Vector2d::Zero();
  for (const Eigen::Vector2d& v : poly) centroid += v;
  centroid /= static_cast<double>(n);
  bool inside = true;
  for (size_t i = 0; i < n; ++i) {
    const Eigen::Vector2d a = poly[i], b = poly[(i + 1) % n];
    const double len = (b - a).norm();
    if (len < 1e-12) continue;
    if (Cross(b - a, p - a) / len < margin) inside = false;
  }
  if (inside) return p;
  // Outside the shrunk polygon: the closest point of its boundary. The
  // shrunk polygon's corners are where neighbouring shifted edges meet.
  std::array<Eigen::Vector2d, 32> shrunk;
  size_t m = 0;
  for (size_t i = 0; i < n && m < shrunk.size(); ++i) {
    const Eigen::Vector2d a0 = poly[(i + n - 1) % n], a1 = poly[i], b1 = poly[(i + 1) % n];
    const Eigen::Vector2d u = (a1 - a0).normalized(), v = (b1 - a1).normalized();
    const Eigen::Vector2d nu(-u.y(), u.x()), nv(-v.y(), v.x());  // inward normals (counter-clockwise)
    const Eigen::Vector2d pa = a0 + margin * nu, pb = a1 + margin * nv;
    const double den = Cross(u, v);
    shrunk[m++] = std::abs(den) < 1e-12 ? Eigen::Vector2d(a1 + margin * nv)
                                        : Eigen::Vector2d(pa + Cross(pb - pa, v) / den * u);
  }
  for (size_t i = 0; i < m; ++i) {  // degenerate (too thin): the centroid
    const Eigen::Vector2d a = shrunk[i], b = shrunk[(i + 1) % m];
    const Eigen::Vector2d e = poly[(i + 1) % n] - poly[i];
    if (e.dot(b - a) < 0) return centroid;
  }
  Eigen::Vector2d best = shrunk[0];
  double best_d = std::numeric_limits<double>::infinity();
  for (size_t i = 0; i < m; ++i) {
    const Eigen::Vector2d q = OnSegment(p, shrunk[i], shrunk[(i + 1) % m]);
    const double d = (q - p).squaredNorm();
    if (d < best_d) {
      best_d = d;
      best = q;
    }
  }
  return best;
}

DcmStabilizer::DcmStabilizer(double com_height, double gravity, DcmGains gains) : gains_(gains) {
  if (!(com_height > 0) || !(gravity > 0) || !(gains.k >= 0) || !(gains.margin >= 0)) {
    throw std::invalid_argument("DcmStabilizer: com_height and gravity must be > 0, k and margin >= 0");
  }
  omega_ = std::sqrt(gravity / com_height);
}

DcmStabilizer::Output DcmStabilizer::Update(const Eigen::Vector2d& com, const Eigen::Vector2d& com_vel,
                                            const Eigen::Vector2d& com_ref,
                                            const Eigen::Vector2d& com_vel_ref,
                                            const Eigen::Vector2d& zmp_ref,
                                            std::span<const Eigen::Vector2d> support,
                                            double time_to_touchdown) const {
  Output o;
  o.dcm = com + com_vel / omega_;
  o.dcm_ref = com_ref + com_vel_ref / omega_;
  o.zmp_wanted = zmp_ref + (1 + gains_.k / omega_) * (o.dcm - o.dcm_ref);
  o.zmp = ClampToPolygon(o.zmp_wanted, support, gains_.margin);
  o.saturated = (o.zmp - o.zmp_wanted).norm() > 1e-9;
  if (o.saturated && time_to_touchdown > 0) {
    const double grow = std::exp(omega_ * time_to_touchdown);
    const Eigen::Vector2d end = o.zmp + (o.dcm - o.zmp) * grow;
    const Eigen::Vector2d end_ref = zmp_ref + (o.dcm_ref - zmp_ref) * grow;
    const Eigen::Vector2d d = end - end_ref;
    if (d.norm() >= gains_.step_min) o.step_offset = d;
  }
  return o;
}

ComOffset::ComOffset(double omega, ComOffsetGains gains) : omega_(omega), gains_(gains) {
  if (!(omega > 0) || !(gains.max_offset >= 0) || !(gains.max_speed >= 0)) {
    throw std::invalid_argument("ComOffset: omega must be > 0, max_offset and max_speed >= 0");
  }
}

void ComOffset::Reset() {
  offset_.setZero();
  velocity_.setZero();
}

const Eigen::Vector2d& ComOffset::Update(const DcmStabilizer::Output& o, const Eigen::Vector2d& com,
                                         const Eigen::Vector2d& com_ref, const Eigen::Vector2d& zmp_ref,
                                         const Eigen::Vector2d* cop, double dt) {
  const double w2 = omega_ * omega_;
  // The CoM acceleration that puts the ZMP at the command, less the plan's own.
  Eigen::Vector2d a = w2 * ((com - o.zmp) - (com_ref - zmp_ref));
  if (cop) a -= gains_.zmp_gain * (o.zmp - *cop);
  velocity_ += a * dt;
  for (int i = 0; i < 2; ++i) {
    velocity_[i] = std::clamp(velocity_[i], -gains_.max_speed, gains_.max_speed);
    const double next = std::clamp(offset_[i] + velocity_[i] * dt, -gains_.max_offset, gains_.max_offset);
    if (next != offset_[i] + velocity_[i] * dt) velocity_[i] = 0;  // at the bound: stop there
    offset_[i] = next;
  }
  return offset_;
}

const Eigen::Vector2d& ComOffset::Relax(double dt, double tau) {
  if (!(tau > 0) || !(dt >= 0))
    throw std::invalid_argument("ComOffset::Relax: tau must be > 0 s and dt >= 0 s");
  velocity_ = (-offset_ / tau).cwiseMax(-gains_.max_speed).cwiseMin(gains_.max_speed);
  offset_ += velocity_ * dt;
  return offset_;
}

}  // namespace robotalk::walking
