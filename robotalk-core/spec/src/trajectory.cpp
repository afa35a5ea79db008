#include "robotalk/trajectory.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <limits>
#include <sstream>

namespace robotalk {
namespace {

constexpr int kCoeffs = 6;

std::string Str(double x) {
  std::ostringstream out;
  out << x;
  return out.str();
}

// Throws when `v` is not `size` finite values (an empty optional vector passes).
void CheckVector(const std::string& what, const Eigen::VectorXd& v, int size, bool optional) {
  if (optional && v.size() == 0) return;
  if (v.size() != size) {
    throw Error(what + " has " + std::to_string(v.size()) + " values, the trajectory has " +
                std::to_string(size) + " dofs");
  }
  for (int i = 0; i < size; ++i) {
    if (!std::isfinite(v[i])) throw Error(what + "[" + std::to_string(i) + "] is " + Str(v[i]));
  }
}

void CheckLimitVector(const char* name, const Eigen::VectorXd& v, int dofs, bool positive) {
  if (v.size() == 0) return;
  const std::string what = std::string("Trajectory limits: ") + name;
  if (v.size() != dofs) {
    throw Error(what + " has " + std::to_string(v.size()) + " values, the trajectory has " +
                std::to_string(dofs) + " dofs");
  }
  for (int i = 0; i < dofs; ++i) {
    if (std::isnan(v[i]) || (positive && !(v[i] > 0))) {
      throw Error(what + "[" + std::to_string(i) + "] is " + Str(v[i]) + (positive ? " (must be > 0)" : ""));
    }
  }
}

void CheckLimits(const TrajectoryLimits& l, int dofs) {
  CheckLimitVector("position_min", l.position_min, dofs, false);
  CheckLimitVector("position_max", l.position_max, dofs, false);
  CheckLimitVector("velocity", l.velocity, dofs, true);
  CheckLimitVector("acceleration", l.acceleration, dofs, true);
  if (l.position_min.size() != 0 && l.position_max.size() != 0) {
    for (int i = 0; i < dofs; ++i) {
      if (l.position_min[i] > l.position_max[i]) {
        throw Error("Trajectory limits: position_min[" + std::to_string(i) + "] " + Str(l.position_min[i]) +
                    " is above position_max " + Str(l.position_max[i]));
      }
    }
  }
}

// c[0] + c[1] x + ... (degree 5), and its first and second derivatives.
double Poly(const double* c, double x) {
  return c[0] + x * (c[1] + x * (c[2] + x * (c[3] + x * (c[4] + x * c[5]))));
}
double Deriv1(const double* c, double x) {
  return c[1] + x * (2 * c[2] + x * (3 * c[3] + x * (4 * c[4] + x * 5 * c[5])));
}
double Deriv2(const double* c, double x) {
  return 2 * c[2] + x * (6 * c[3] + x * (12 * c[4] + x * 20 * c[5]));
}
double Deriv3(const double* c, double x) { return 6 * c[3] + x * (24 * c[4] + x * 60 * c[5]); }

// Extremes of f on [lo, hi], f' = df: the ends and every root of df found by
// 64 sub-intervals and bisection (df has degree <= 4, so a pair of roots
// closer than a sub-interval, where f barely moves, is the only miss).
template <typename F, typename DF>
void Extremes(F f, DF df, double lo, double hi, double* min, double* max) {
  auto take = [&](double x) {
    const double y = f(x);
    *min = std::min(*min, y);
    *max = std::max(*max, y);
  };
  take(lo);
  take(hi);
  constexpr int kParts = 64;
  double x0 = lo, d0 = df(lo);
  for (int i = 1; i <= kParts; ++i) {
    const double x1 = lo + (hi - lo) * i / kParts, d1 = df(x1);
    if ((d0 < 0) != (d1 < 0)) {
      double a = x0, b = x1, da = d0;
      for (int it = 0; it < 60; ++it) {
        const double m = 0.5 * (a + b), dm = df(m);
        if ((dm < 0) == (da < 0)) {
          a = m;
          da = dm;
        } else {
          b = m;
        }
      }
      take(0.5 * (a + b));
    }
    x0 = x1;
    d0 = d1;
  }
}

}  // namespace

const char* InterpolationName(Interpolation interpolation) {
  switch (interpolation) {
    case Interpolation::kStep:
      return "step";
    case Interpolation::kLinear:
      return "linear";
    case Interpolation::kCubic:
      return "cubic";
    case Interpolation::kQuintic:
      return "quintic";
  }
  return "?";
}

std::optional<Interpolation> ParseInterpolation(std::string_view name) {
  for (Interpolation i :
       {Interpolation::kStep, Interpolation::kLinear, Interpolation::kCubic, Interpolation::kQuintic}) {
    const std::string_view known = InterpolationName(i);
    if (name.size() == known.size() &&
        std::equal(name.begin(), name.end(), known.begin(),
                   [](char a, char b) { return std::tolower(static_cast<unsigned char>(a)) == b; })) {
      return i;
    }
  }
  return std::nullopt;
}

Trajectory::Trajectory(Interpolation interpolation, TimePoint start_time, const TrajectoryState& start,
                       const Eigen::VectorXd& hold_deceleration)
    : interpolation_(interpolation), hold_deceleration_(hold_deceleration) {
  const int n = static_cast<int>(start.position.size());
  if (n == 0) throw Error("Trajectory: the start state has no position");
  CheckVector("Trajectory: start position", start.position, n, false);
  CheckVector("Trajectory: start velocity", start.velocity, n, true);
  CheckVector("Trajectory: start acceleration", start.acceleration, n, true);
  CheckVector("Trajectory: hold_deceleration", hold_deceleration, n, false);
  for (int i = 0; i < n; ++i) {
    if (!(hold_deceleration[i] > 0)) {
      throw Error("Trajectory: hold_deceleration[" + std::to_string(i) + "] is " + Str(hold_deceleration[i]) +
                  " (must be > 0)");
    }
  }
  times_.push_back(start_time);
  constexpr Eigen::Index kInitialKnots = 8;
  p_ = Eigen::MatrixXd::Zero(n, kInitialKnots);
  v_ = Eigen::MatrixXd::Zero(n, kInitialKnots);
  a_ = Eigen::MatrixXd::Zero(n, kInitialKnots);
  p_.col(0) = start.position;
  if (start.velocity.size()) v_.col(0) = start.velocity;
  if (start.acceleration.size()) a_.col(0) = start.acceleration;
  given_v_.push_back(true);
  given_a_.push_back(true);
  splice_sample_ = MakeSample();
}

void Trajectory::CheckWaypoints(TimePoint after, std::span<const Waypoint> waypoints) const {
  const int n = num_dofs();
  const auto fine = [n](const Eigen::VectorXd& v, bool optional) {
    return (optional && v.size() == 0) || (v.size() == n && v.allFinite());
  };
  TimePoint previous = after;
  for (std::size_t i = 0; i < waypoints.size(); ++i) {
    const Waypoint& w = waypoints[i];
    // The text is built only for a waypoint that is refused (no allocation otherwise).
    if (w.time > previous && fine(w.position, false) && fine(w.velocity, true) &&
        fine(w.acceleration, true)) {
      previous = w.time;
      continue;
    }
    const std::string name = "Trajectory: waypoint " + std::to_string(i);
    if (w.time <= previous) {
      throw Error(
          name + ": time " + Str(ToSeconds(w.time - after)) + " s is not after " +
          (i == 0 ? std::string("the trajectory's time ") + Str(0) + " s"
                  : "waypoint " + std::to_string(i - 1) + "'s " + Str(ToSeconds(previous - after)) + " s") +
          " (times must strictly increase)");
    }
    CheckVector(name + ": position", w.position, n, false);
    CheckVector(name + ": velocity", w.velocity, n, true);
    CheckVector(name + ": acceleration", w.acceleration, n, true);
  }
}

void Trajectory::AddKnot(TimePoint time, const Eigen::VectorXd& position, const Eigen::VectorXd& velocity,
                         const Eigen::VectorXd& acceleration) {
  const auto k = static_cast<Eigen::Index>(times_.size());
  if (k == p_.cols()) {  // the knot storage grows by doubling and never shrinks: no allocation once sized
    for (Eigen::MatrixXd* m : {&p_, &v_, &a_}) m->conservativeResize(Eigen::NoChange, 2 * k);
  }
  times_.push_back(time);
  p_.col(k) = position;
  given_v_.push_back(velocity.size() != 0);
  given_a_.push_back(acceleration.size() != 0);
  if (given_v_.back()) {
    v_.col(k) = velocity;
  } else {
    v_.col(k).setZero();
  }
  if (given_a_.back()) {
    a_.col(k) = acceleration;
  } else {
    a_.col(k).setZero();
  }
}

void Trajectory::AddKnots(std::span<const Waypoint> waypoints, std::size_t first) {
  for (const Waypoint& w : waypoints) AddKnot(w.time, w.position, w.velocity, w.acceleration);
  Resolve(first);
}

void Trajectory::Append(std::span<const Waypoint> waypoints) {
  CheckWaypoints(times_.back(), waypoints);
  AddKnots(waypoints, times_.size());
}

void Trajectory::Splice(TimePoint t, std::span<const Waypoint> waypoints) {
  t = std::max(t, times_.front());
  CheckWaypoints(t, waypoints);
  // Keep every knot at or before t; a knot exactly at t keeps its state, which
  // the segment before it reaches exactly (Hermite ends), so nothing moves.
  const auto keep =
      static_cast<std::size_t>(std::upper_bound(times_.begin(), times_.end(), t) - times_.begin());
  const bool at_knot = times_[keep - 1] == t;
  TrajectorySample& s = splice_sample_;
  if (!at_knot) Sample(t, &s);
  times_.resize(keep);
  given_v_.resize(keep);
  given_a_.resize(keep);
  if (!at_knot) {
    // The sampled state becomes a knot: Hermite interpolation of a polynomial's
    // own end values reproduces it, so the segment before t keeps its shape
    // (except a decelerating hold, replaced by the segment to t's state).
    AddKnot(t, s.position, s.velocity, s.acceleration);
  }
  AddKnots(waypoints, keep);
}

void Trajectory::Forget(TimePoint t) {
  const auto next = std::upper_bound(times_.begin(), times_.end(), t);
  const auto drop = static_cast<std::size_t>(next - times_.begin()) - (next == times_.begin() ? 0 : 1);
  if (drop == 0) return;
  const auto kept = static_cast<Eigen::Index>(times_.size() - drop), first = static_cast<Eigen::Index>(drop);
  times_.erase(times_.begin(), times_.begin() + static_cast<std::ptrdiff_t>(drop));
  given_v_.erase(given_v_.begin(), given_v_.begin() + static_cast<std::ptrdiff_t>(drop));
  given_a_.erase(given_a_.begin(), given_a_.begin() + static_cast<std::ptrdiff_t>(drop));
  for (Eigen::MatrixXd* m : {&p_, &v_, &a_}) {  // in place (columns are contiguous): no allocation
    std::copy(m->data() + first * m->rows(), m->data() + (first + kept) * m->rows(), m->data());
  }
}

void Trajectory::Resolve(std::size_t first) {
  const std::size_t last = times_.size() - 1;
  const int n = num_dofs();
  const bool smooth = interpolation_ == Interpolation::kCubic || interpolation_ == Interpolation::kQuintic;
  for (std::size_t k = first; k <= last && smooth; ++k) {
    if (given_v_[k] || k == last) continue;  // the last one stays zero unless given
    const double h0 = ToSeconds(times_[k] - times_[k - 1]), h1 = ToSeconds(times_[k + 1] - times_[k]);
    const auto c = static_cast<Eigen::Index>(k);
    for (int i = 0; i < n; ++i) {
      const double d0 = (p_(i, c) - p_(i, c - 1)) / h0, d1 = (p_(i, c + 1) - p_(i, c)) / h1;
      // The slope of the parabola through the knot and its neighbours (second
      // order: a smooth motion sampled at its waypoints is followed closely);
      // zero next to a repeated position, so a plateau or a stop stays flat.
      v_(i, c) = d0 == 0 || d1 == 0 ? 0.0 : (h1 * d0 + h0 * d1) / (h0 + h1);
    }
  }
  for (std::size_t k = first; k <= last && interpolation_ == Interpolation::kQuintic; ++k) {
    if (given_a_[k] || k == last) continue;
    const auto c = static_cast<Eigen::Index>(k);
    a_.col(c) = (v_.col(c + 1) - v_.col(c - 1)) / ToSeconds(times_[k + 1] - times_[k - 1]);
  }
}

void Trajectory::Coefficients(std::size_t segment, int dof, double* c) const {
  // Computed when needed rather than kept: 6 per dof per knot would be most
  // of what a held waypoint costs the server (docs/server.md, memory bounds).
  const double h = ToSeconds(times_[segment + 1] - times_[segment]);
  const auto k0 = static_cast<Eigen::Index>(segment), k1 = k0 + 1;
  const auto r = static_cast<Eigen::Index>(dof);
  std::fill(c, c + kCoeffs, 0.0);
  const double p0 = p_(r, k0), p1 = p_(r, k1), v0 = v_(r, k0), v1 = v_(r, k1);
  const double a0 = a_(r, k0), a1 = a_(r, k1), dp = p1 - p0;
  c[0] = p0;
  switch (interpolation_) {
    case Interpolation::kStep:
      break;
    case Interpolation::kLinear:
      c[1] = dp / h;
      break;
    case Interpolation::kCubic:
      c[1] = v0;
      c[2] = (3 * dp / h - 2 * v0 - v1) / h;
      c[3] = (-2 * dp / h + v0 + v1) / (h * h);
      break;
    case Interpolation::kQuintic: {
      const double h2 = h * h, h3 = h2 * h;
      c[1] = v0;
      c[2] = a0 / 2;
      c[3] = (20 * dp - (8 * v1 + 12 * v0) * h - (3 * a0 - a1) * h2) / (2 * h3);
      c[4] = (-30 * dp + (14 * v1 + 16 * v0) * h + (3 * a0 - 2 * a1) * h2) / (2 * h3 * h);
      c[5] = (12 * dp - 6 * (v1 + v0) * h + (a1 - a0) * h2) / (2 * h3 * h2);
      break;
    }
  }
}

TrajectorySample Trajectory::MakeSample() const {
  TrajectorySample s;
  s.position = Eigen::VectorXd::Zero(num_dofs());
  s.velocity = Eigen::VectorXd::Zero(num_dofs());
  s.acceleration = Eigen::VectorXd::Zero(num_dofs());
  return s;
}

void Trajectory::Evaluate(std::size_t segment, double tau, int dof, double* p, double* v, double* a) const {
  double c[kCoeffs];
  Coefficients(segment, dof, c);
  *p = Poly(c, tau);
  *v = Deriv1(c, tau);
  *a = Deriv2(c, tau);
}

void Trajectory::EvaluateHold(double tau, int dof, double* p, double* v, double* a) const {
  const auto last = static_cast<Eigen::Index>(times_.size()) - 1;
  const double p0 = p_(dof, last);
  const bool smooth = interpolation_ == Interpolation::kCubic || interpolation_ == Interpolation::kQuintic;
  const double v0 = smooth ? v_(dof, last) : 0.0;
  if (v0 == 0) {
    *p = p0;
    *v = *a = 0;
    return;
  }
  const double d = std::copysign(hold_deceleration_[dof], v0), stop = v0 / d;
  if (tau >= stop) {
    *p = p0 + v0 * stop / 2;
    *v = *a = 0;
  } else {
    *p = p0 + v0 * tau - d * tau * tau / 2;
    *v = v0 - d * tau;
    *a = -d;
  }
}

void Trajectory::Sample(TimePoint t, TrajectorySample* out) const {
  t = std::max(t, times_.front());
  const auto next = std::upper_bound(times_.begin(), times_.end(), t);
  const bool hold = next == times_.end();
  const auto segment = static_cast<std::size_t>(next - times_.begin()) - 1;
  const double tau = ToSeconds(t - times_[segment]);
  out->holding = hold;
  for (int i = 0; i < num_dofs(); ++i) {
    double p, v, a;
    if (hold) {
      EvaluateHold(tau, i, &p, &v, &a);
    } else {
      Evaluate(segment, tau, i, &p, &v, &a);
    }
    out->position[i] = p;
    out->velocity[i] = v;
    out->acceleration[i] = a;
  }
}

TrajectoryState Trajectory::knot(int k) const { return {p_.col(k), v_.col(k), a_.col(k)}; }

LimitCheck Trajectory::CheckLimits(const TrajectoryLimits& limits, TimePoint from) const {
  const int n = num_dofs();
  robotalk::CheckLimits(limits, n);
  constexpr double kInf = std::numeric_limits<double>::infinity();
  LimitCheck r;
  r.max_velocity = Eigen::VectorXd::Zero(n);
  r.max_acceleration = Eigen::VectorXd::Zero(n);
  r.min_position = Eigen::VectorXd::Constant(n, kInf);
  r.max_position = Eigen::VectorXd::Constant(n, -kInf);
  from = std::max(from, times_.front());
  for (std::size_t k = 0; k + 1 < times_.size(); ++k) {
    if (times_[k + 1] <= from) continue;
    const double lo = std::max(0.0, ToSeconds(from - times_[k])), hi = ToSeconds(times_[k + 1] - times_[k]);
    for (int i = 0; i < n; ++i) {
      double c[kCoeffs];
      Coefficients(k, i, c);
      double vmin = kInf, vmax = -kInf, amin = kInf, amax = -kInf;
      Extremes([&c](double x) { return Poly(c, x); }, [&c](double x) { return Deriv1(c, x); }, lo, hi,
               &r.min_position[i], &r.max_position[i]);
      Extremes([&c](double x) { return Deriv1(c, x); }, [&c](double x) { return Deriv2(c, x); }, lo, hi,
               &vmin, &vmax);
      Extremes([&c](double x) { return Deriv2(c, x); }, [&c](double x) { return Deriv3(c, x); }, lo, hi,
               &amin, &amax);
      r.max_velocity[i] = std::max({r.max_velocity[i], -vmin, vmax});
      r.max_acceleration[i] = std::max({r.max_acceleration[i], -amin, amax});
    }
  }
  // The hold: from the last knot (or `from`) to rest.
  const double hold_from = std::max(0.0, ToSeconds(from - times_.back()));
  for (int i = 0; i < n; ++i) {
    double p0, v0, a0, p1, v1, a1;
    EvaluateHold(hold_from, i, &p0, &v0, &a0);
    EvaluateHold(kInf, i, &p1, &v1, &a1);
    r.min_position[i] = std::min({r.min_position[i], p0, p1});
    r.max_position[i] = std::max({r.max_position[i], p0, p1});
    r.max_velocity[i] = std::max(r.max_velocity[i], std::abs(v0));
    r.max_acceleration[i] = std::max(r.max_acceleration[i], std::abs(a0));
  }
  auto violate = [&r](int i, const std::string& what, double value, const char* relation, double limit) {
    if (!r.violations.empty()) r.violations += "; ";
    r.violations +=
        "dof " + std::to_string(i) + ": " + what + " " + Str(value) + " " + relation + " " + Str(limit);
    r.within = false;
  };
  constexpr double kSlack = 1e-9;  // relative: rounding is not a violation
  for (int i = 0; i < n; ++i) {
    if (limits.position_min.size() &&
        r.min_position[i] < limits.position_min[i] - kSlack * (1 + std::abs(limits.position_min[i])))
      violate(i, "position", r.min_position[i], "is below the limit", limits.position_min[i]);
    if (limits.position_max.size() &&
        r.max_position[i] > limits.position_max[i] + kSlack * (1 + std::abs(limits.position_max[i])))
      violate(i, "position", r.max_position[i], "is above the limit", limits.position_max[i]);
    if (limits.velocity.size() && r.max_velocity[i] > limits.velocity[i] * (1 + kSlack))
      violate(i, "|velocity|", r.max_velocity[i], "exceeds the limit", limits.velocity[i]);
    if (limits.acceleration.size() && r.max_acceleration[i] > limits.acceleration[i] * (1 + kSlack))
      violate(i, "|acceleration|", r.max_acceleration[i], "exceeds the limit", limits.acceleration[i]);
  }
  return r;
}

TimeScaling Trajectory::ScaleToLimits(const TrajectoryLimits& limits, TimePoint from) {
  TimeScaling result;
  const LimitCheck before = CheckLimits(limits, from);
  result.reason = before.violations;
  result.old_end = result.new_end = times_.back() - times_.front();
  from = std::max(from, times_.front());
  const std::size_t segments = times_.size() - 1;
  const int n = num_dofs();
  std::vector<double> original(segments), factor(segments);
  for (std::size_t k = 0; k < segments; ++k) original[k] = ToSeconds(times_[k + 1] - times_[k]);
  // Stretch each offending segment by what it needs (velocity / limit, or the
  // square root of acceleration / limit); a knot between stretched segments
  // scales its velocity by 1/f and acceleration by 1/f² (f the larger
  // stretch), an exact time-scaling when neighbours agree. Repeat: a knot's
  // change moves its other segment too, and knots that may not change (knot 0,
  // a knot at or before `from`) keep theirs.
  for (int iteration = 0; iteration < 40; ++iteration) {
    std::fill(factor.begin(), factor.end(), 1.0);
    bool stretched = false;
    for (std::size_t k = 0; k < segments; ++k) {
      if (times_[k] < from) continue;
      const double h = ToSeconds(times_[k + 1] - times_[k]);
      for (int i = 0; i < n; ++i) {
        double c[kCoeffs];
        Coefficients(k, i, c);
        double vmin = 0, vmax = 0, amin = 0, amax = 0;
        Extremes([&c](double x) { return Deriv1(c, x); }, [&c](double x) { return Deriv2(c, x); }, 0, h,
                 &vmin, &vmax);
        Extremes([&c](double x) { return Deriv2(c, x); }, [&c](double x) { return Deriv3(c, x); }, 0, h,
                 &amin, &amax);
        // A fixed start knot's own velocity (acceleration, quintic) cannot be
        // scaled: stretch only towards it, never forever.
        const auto c0 = static_cast<Eigen::Index>(k);
        const bool fixed = k == 0 || times_[k] <= from;
        const double vfix = fixed ? std::abs(v_(i, c0)) : 0.0;
        const double afix = fixed && interpolation_ == Interpolation::kQuintic ? std::abs(a_(i, c0)) : 0.0;
        if (limits.velocity.size()) {
          factor[k] = std::max(factor[k], std::max(-vmin, vmax) / std::max(limits.velocity[i], vfix));
        }
        if (limits.acceleration.size()) {
          factor[k] =
              std::max(factor[k], std::sqrt(std::max(-amin, amax) / std::max(limits.acceleration[i], afix)));
        }
      }
      if (factor[k] > 1 + 1e-9) {
        factor[k] *= 1 + 1e-6;  // land inside, not on, the limit
        stretched = true;
      } else {
        factor[k] = 1;
      }
    }
    if (!stretched) break;
    result.changed = true;
    std::vector<TimePoint> times = times_;
    for (std::size_t k = 0; k < segments; ++k) {
      times[k + 1] = times[k] + FromSeconds(ToSeconds(times_[k + 1] - times_[k]) * factor[k]);
    }
    for (std::size_t j = 1; j <= segments; ++j) {
      if (times_[j] <= from) continue;
      const double f = std::max(factor[j - 1], j < segments ? factor[j] : 1.0);
      const auto c = static_cast<Eigen::Index>(j);
      v_.col(c) /= f;
      a_.col(c) /= f * f;
    }
    times_ = std::move(times);
  }
  double largest = 1;
  for (std::size_t k = 0; k < segments; ++k) {
    largest = std::max(largest, ToSeconds(times_[k + 1] - times_[k]) / original[k]);
  }
  result.largest_factor = largest;
  result.new_end = times_.back() - times_.front();
  result.after = CheckLimits(limits, from);
  return result;
}

}  // namespace robotalk
