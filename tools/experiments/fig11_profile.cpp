#include "fig11_profile.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <string>

namespace robotalk::experiments {

namespace {
constexpr double kPi = std::numbers::pi;
constexpr double kTwoPi = 2 * std::numbers::pi;

void CheckPositive(const char* name, double v) {
  if (!std::isfinite(v) || v <= 0)
    throw std::invalid_argument(std::string("Fig11Params: ") + name + " must be > 0");
}

// a mod 2π in [0, 2π).
double Mod2Pi(double a) {
  a = std::fmod(a, kTwoPi);
  return a < 0 ? a + kTwoPi : a;
}
}  // namespace

double WrapAngle(double a) {
  a = Mod2Pi(a + kPi);
  return a - kPi;
}

Fig11Profile MakeFig11Profile(const Fig11Params& params) {
  CheckPositive("length", params.length);
  CheckPositive("duration", params.duration);
  CheckPositive("frame_period", params.frame_period);
  Fig11Profile p;
  p.params = params;
  p.frames_per_small =
      std::max(1, static_cast<int>(std::lround(params.duration / (8 * params.frame_period))));
  const int n = p.frames_per_small;
  p.radius = params.length / (8 * kPi);
  const double t_small = n * params.frame_period;
  p.speed = kPi * p.radius / t_small;
  p.duration = 8 * t_small;
  const double w_small = p.speed / p.radius;  // = π / t_small
  const double w_large = p.speed / (4 * p.radius);
  // left, right, left, right (small), then right (large): see the header.
  const double turns[5] = {w_small, -w_small, w_small, -w_small, -w_large};
  const int counts[5] = {n, n, n, n, 4 * n};
  int k = 0;
  for (int seg = 0; seg < 5; ++seg) {
    for (int i = 0; i < counts[seg]; ++i, ++k) {
      p.frames.push_back({k * params.frame_period, p.speed, turns[seg]});
    }
  }
  p.frames.push_back({k * params.frame_period, 0.0, 0.0});
  return p;
}

Pose2 Arc::At(double t) const {
  t = std::clamp(t, 0.0, dt);
  const double c = std::cos(start.theta), s = std::sin(start.theta);
  if (std::abs(omega) < 1e-12) return {start.x + v * t * c, start.y + v * t * s, start.theta};
  const double th = start.theta + omega * t;
  const double r = v / omega;  // signed radius
  return {start.x + r * (std::sin(th) - s), start.y - r * (std::cos(th) - c), WrapAngle(th)};
}

double Arc::Distance(double x, double y) const {
  const Pose2 a = start, b = End();
  const double to_ends = std::min(std::hypot(x - a.x, y - a.y), std::hypot(x - b.x, y - b.y));
  if (v == 0 || dt <= 0) return to_ends;
  if (std::abs(omega) < 1e-12) {  // straight segment
    const double ux = std::cos(a.theta), uy = std::sin(a.theta), len = v * dt;
    const double along = (x - a.x) * ux + (y - a.y) * uy;
    const double sgn_len = len;  // v may be negative: the segment runs from 0 to len along u
    const double lo = std::min(0.0, sgn_len), hi = std::max(0.0, sgn_len);
    if (along < lo || along > hi) return to_ends;
    return std::abs(-(x - a.x) * uy + (y - a.y) * ux);
  }
  const double r = v / omega;
  const double cx = a.x - r * std::sin(a.theta), cy = a.y + r * std::cos(a.theta);
  // Angle of the start point around the centre, and of the query point.
  const double alpha0 = std::atan2(a.y - cy, a.x - cx);
  const double beta = std::atan2(y - cy, x - cx);
  const double sweep = std::abs(omega * dt);
  // The point moves around the centre in the direction of sign(ω)·sign(v)...
  // concretely: angle advances by ω·t whatever the sign of v.
  const double delta = omega > 0 ? Mod2Pi(beta - alpha0) : Mod2Pi(alpha0 - beta);
  if (sweep >= kTwoPi || delta <= sweep) {
    return std::abs(std::hypot(x - cx, y - cy) - std::abs(r));
  }
  return to_ends;
}

IdealPath::IdealPath(const Fig11Profile& profile, const Pose2& start) : start_(start) {
  Pose2 pose = start;
  for (std::size_t i = 0; i + 1 < profile.frames.size(); ++i) {
    const SpeedFrame& f = profile.frames[i];
    const double dt = profile.frames[i + 1].offset - f.offset;
    Arc arc{pose, f.v, f.omega, dt};
    arcs_.push_back(arc);
    pose = arc.End();
  }
}

Pose2 IdealPath::End() const { return arcs_.empty() ? start_ : arcs_.back().End(); }

Pose2 IdealPath::At(double t) const {
  if (arcs_.empty() || t <= 0) return start_;
  double t0 = 0;
  for (const Arc& a : arcs_) {
    if (t <= t0 + a.dt) return a.At(t - t0);
    t0 += a.dt;
  }
  return End();
}

double IdealPath::Distance(double x, double y) const {
  double best = std::hypot(x - start_.x, y - start_.y);
  for (const Arc& a : arcs_) best = std::min(best, a.Distance(x, y));
  return best;
}

Deviation MeasureDeviation(const IdealPath& path, const std::vector<Pose2>& samples) {
  Deviation d;
  double sum = 0;
  for (const Pose2& s : samples) {
    const double e = path.Distance(s.x, s.y);
    sum += e;
    d.max = std::max(d.max, e);
    ++d.samples;
  }
  d.mean = d.samples ? sum / static_cast<double>(d.samples) : 0.0;
  return d;
}

}  // namespace robotalk::experiments
