// Capturability of the walking humanoid: see capturability.h.
#include "walking/capturability.h"

#include "walking/walk_pattern.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace robotalk::walking {
namespace {

// One axis of the stance foot's frame: the sole's CoP range around its
// ankle and where the next landing may be, both from the stance ankle.
struct Axis {
  double sole_lo, sole_hi, step_lo, step_hi;
};

Axis AxisX(const CaptureLimits& l) { return {-l.back, l.front, -l.reach_back, l.reach}; }
Axis AxisY(const CaptureLimits& l, Side swing) {
  return swing == Side::kLeft ? Axis{-l.half_width, l.half_width, l.min_width, l.max_width}
                              : Axis{-l.half_width, l.half_width, -l.max_width, -l.min_width};
}

// The region on one axis, one step before `next` (the landed foot's region,
// from its ankle): a swing of at least the time giving e1 = e^{-w T}, a
// landing within [step_lo, step_hi], a double support of e^{-w d} = ed.
// Each end comes from the landing farthest its way (the ends do not
// decrease with the landing); the sole is always in it (no step needed).
Interval StepBack(const Axis& a, const Interval& next, double e1, double ed) {
  const double box_lo = std::min(0.0, a.step_lo) + a.sole_lo;  // the double support's CoP range
  const double box_hi = std::max(0.0, a.step_hi) + a.sole_hi;
  const double landed_lo = std::min(box_lo, box_lo + (a.step_lo + next.lo - box_lo) * ed);
  const double landed_hi = std::max(box_hi, box_hi + (a.step_hi + next.hi - box_hi) * ed);
  return {std::min(a.sole_lo, a.sole_lo + (landed_lo - a.sole_lo) * e1),
          std::max(a.sole_hi, a.sole_hi + (landed_hi - a.sole_hi) * e1)};
}

Interval Shift(const Interval& i, double by) { return {i.lo + by, i.hi + by}; }

// With a swing speed: the first landing's times scanned beyond the soonest.
constexpr double kFirstLandingScan = 1.0, kFirstLandingStep = 0.005;  // s

// How far from p along dir the box holds (p inside); 0 when p is outside.
double ExitAlong(const CaptureBox& b, const Eigen::Vector2d& p, const Eigen::Vector2d& dir) {
  if (!b.Contains(p)) return 0;
  double t = std::numeric_limits<double>::infinity();
  const Interval* axes[2] = {&b.x, &b.y};
  for (int i = 0; i < 2; ++i) {
    if (dir[i] > 0) t = std::min(t, (axes[i]->hi - p[i]) / dir[i]);
    if (dir[i] < 0) t = std::min(t, (axes[i]->lo - p[i]) / dir[i]);
  }
  return t;
}

}  // namespace

namespace {

// SingleSupportRegion, the first landing's range (from the stance ankle)
// narrowed to `first_reach` when given (the swing foot's speed).
CaptureBox Region(const CaptureLimits& l, Side swing, double first, int steps,
                  const CaptureBox* first_reach) {
  const double e_swing = std::exp(-l.omega * l.min_swing), ed = std::exp(-l.omega * l.double_support);
  // regions[s]: the region with the foot on side s in the air, just lifted,
  // k steps to go; built up from the sole (k = 0).
  CaptureBox regions[2];
  for (Side s : {Side::kLeft, Side::kRight}) {
    regions[static_cast<int>(s)] = {{-l.back, l.front}, {-l.half_width, l.half_width}};
  }
  for (int k = 1; k <= steps; ++k) {
    const bool last = k == steps;
    const double e1 = last ? std::exp(-l.omega * std::max(first, 0.0)) : e_swing;
    CaptureBox next[2];
    for (Side s : {Side::kLeft, Side::kRight}) {
      // The foot on side s lands; then the other one swings from its region.
      const CaptureBox& after = regions[static_cast<int>(Other(s))];
      Axis ax = AxisX(l), ay = AxisY(l, s);
      if (last && first_reach && s == swing) {
        ax.step_lo = std::max(ax.step_lo, first_reach->x.lo);
        ax.step_hi = std::min(ax.step_hi, first_reach->x.hi);
        ay.step_lo = std::max(ay.step_lo, first_reach->y.lo);
        ay.step_hi = std::min(ay.step_hi, first_reach->y.hi);
      }
      next[static_cast<int>(s)] = {StepBack(ax, after.x, e1, ed), StepBack(ay, after.y, e1, ed)};
    }
    regions[0] = next[0];
    regions[1] = next[1];
  }
  return regions[static_cast<int>(swing)];
}

// The largest of `exit(region)` over the first landing's times from `first`
// (its swing `swing_time` s long from where the foot is, `foot` from the
// stance ankle) when the swing speed bounds it; else the soonest only.
template <typename Exit>
double OverFirstLandings(const CaptureLimits& l, Side swing, double first, double swing_time, int steps,
                         const Eigen::Vector2d& foot, const Exit& exit) {
  if (!(l.swing_speed > 0) || steps <= 0) return exit(Region(l, swing, first, steps, nullptr));
  double best = 0;
  for (double extra = 0; extra <= kFirstLandingScan + 1e-9; extra += kFirstLandingStep) {
    const double r = l.swing_speed * (swing_time + extra);
    const CaptureBox reach{{foot.x() - r, foot.x() + r}, {foot.y() - r, foot.y() + r}};
    const Axis ax = AxisX(l), ay = AxisY(l, swing);
    if (reach.x.hi < ax.step_lo || reach.x.lo > ax.step_hi || reach.y.hi < ay.step_lo ||
        reach.y.lo > ay.step_hi) {
      continue;  // no landing in reach yet
    }
    best = std::max(best, exit(Region(l, swing, first + extra, steps, &reach)));
  }
  return best;
}

}  // namespace

CaptureBox SingleSupportRegion(const CaptureLimits& l, Side swing, double first, int steps) {
  return Region(l, swing, first, steps, nullptr);
}

double CapturableShift(const CaptureLimits& l, const CaptureSituation& s, const Eigen::Vector2d& dir,
                       int steps) {
  // Into the feet's frame (their common yaw), from the world origin.
  const double th = s.feet[s.double_support ? 0 : static_cast<int>(Other(s.swing))].theta;
  Eigen::Matrix2d to_local;
  to_local << std::cos(th), std::sin(th), -std::sin(th), std::cos(th);
  const Eigen::Vector2d p = to_local * s.dcm, d = to_local * dir;
  Eigen::Vector2d feet[2] = {to_local * s.feet[0].xy(), to_local * s.feet[1].xy()};
  if (!s.double_support) {
    const Eigen::Vector2d& at = feet[static_cast<int>(Other(s.swing))];
    return OverFirstLandings(l, s.swing, s.soonest, s.soonest, steps, feet[static_cast<int>(s.swing)] - at,
                             [&](const CaptureBox& r) {
                               return ExitAlong({Shift(r.x, at.x()), Shift(r.y, at.y())}, p, d);
                             });
  }
  // Double support: the box of both soles, or either foot lifts (no sooner
  // than s.soonest) and swings from its region.
  const CaptureBox both{
      {std::min(feet[0].x(), feet[1].x()) - l.back, std::max(feet[0].x(), feet[1].x()) + l.front},
      {std::min(feet[0].y(), feet[1].y()) - l.half_width, std::max(feet[0].y(), feet[1].y()) + l.half_width}};
  double best = ExitAlong(both, p, d);
  if (steps <= 0) return best;
  const double er = std::exp(-l.omega * std::max(s.soonest, 0.0));
  for (Side lift : {Side::kLeft, Side::kRight}) {
    const Eigen::Vector2d& at = feet[static_cast<int>(Other(lift))];
    const auto exit = [&](const CaptureBox& r) {
      const Interval* target[2] = {&r.x, &r.y};
      const Interval* box[2] = {&both.x, &both.y};
      Interval got[2];
      for (int i = 0; i < 2; ++i) {  // held in the box for s.soonest, then into the region
        const Interval t = Shift(*target[i], at[i]);
        got[i] = {std::min(box[i]->lo, box[i]->lo + (t.lo - box[i]->lo) * er),
                  std::max(box[i]->hi, box[i]->hi + (t.hi - box[i]->hi) * er)};
      }
      return ExitAlong({got[0], got[1]}, p, d);
    };
    best = std::max(best, OverFirstLandings(l, lift, l.min_swing, l.min_swing, steps,
                                            feet[static_cast<int>(lift)] - at, exit));
  }
  return best;
}

CaptureSituation SituationOf(const WalkPattern& w, double since_landing, const CaptureLimits& l) {
  CaptureSituation s;
  s.double_support = w.double_support();
  s.feet[0] = w.foot(Side::kLeft);
  s.feet[1] = w.foot(Side::kRight);
  s.dcm = w.com() + w.com_velocity() / l.omega;
  if (s.double_support) {
    s.soonest = std::max(0.0, l.double_support - since_landing);
  } else {
    s.swing = w.swing_step()->side;
    s.soonest = std::max(0.0, l.min_swing - (w.gait().single_support - w.time_to_landing()));
  }
  return s;
}

double DcmShiftPerImpulse(double mass, double omega, double duration) {
  const double wd = omega * std::max(duration, 0.0);
  const double spread = wd < 1e-9 ? 1.0 : (1 - std::exp(-wd)) / wd;
  return spread / (mass * omega);
}

}  // namespace robotalk::walking
