// Push recovery: see push_recovery.h.
#include "walking/push_recovery.h"

#include "walking/dcm_stabilizer.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

namespace robotalk::walking {

Eigen::Vector2d CaptureShift(const Eigen::Vector2d& e0, double omega, double T, double D,
                             const Eigen::Vector2d& u) {
  const double wd = omega * D, ed = std::exp(wd);
  const double f = wd > 1e-9 ? (ed - 1 - wd) / wd : 0.0;
  const Eigen::Vector2d et = u + (e0 - u) * std::exp(omega * T);
  return (et * ed - u * (ed - 1 - f)) / (1 + f);
}

Eigen::Vector2d Relocate(const Pose2& from, const Pose2& to, const Eigen::Vector2d& p, bool vector) {
  const double a = from.theta, c = std::cos(a), s = std::sin(a);
  const Eigen::Vector2d d = vector ? p : Eigen::Vector2d(p - from.xy());
  const Eigen::Vector2d local(c * d.x() + s * d.y(), -s * d.x() + c * d.y());
  const double b = to.theta, cb = std::cos(b), sb = std::sin(b);
  const Eigen::Vector2d r(cb * local.x() - sb * local.y(), sb * local.x() + cb * local.y());
  return vector ? r : Eigen::Vector2d(to.xy() + r);
}

// WalkPattern's part of the recovery, here beside its maths (walk_pattern.h
// declares it).

// The DCM of the reference's stable solution from now: xi = w int_0^inf
// e^{-w t} p_ref(now + t) dt (the preview's CoM is the one that follows the
// reference without diverging; its DCM is this, up to the preview's horizon).
Eigen::Vector2d WalkPattern::NominalDcm() const {
  const double omega = std::sqrt(gravity_ / g_.com_height), dt = 5 * tick_s_;
  Eigen::Vector2d xi = Eigen::Vector2d::Zero();
  double t = 0;
  for (; t < 4.0; t += dt) {  // midpoint rule; e^{-4 w} < 1e-6
    xi += (std::exp(-omega * t) - std::exp(-omega * (t + dt))) *
          ZmpAt(tick_ + std::llround((t + dt / 2) / tick_s_));
  }
  return xi + std::exp(-omega * t) * ZmpAt(tick_ + std::llround(t / tick_s_));
}

// From the saved schedule: step k lands at `land` (in the air) or lifts
// after `lift` ticks of shifting onto its stance foot (not started; -1: as
// planned), the stance ZMP held `u` from the reference until then, the
// steps from k on shifted by `shift[i - k]`, the later ones at fast timing.
void WalkPattern::Rebuild(size_t k, std::int64_t land, std::int64_t lift, const Eigen::Vector2d& u,
                          const std::vector<Eigen::Vector2d>& shift, const RecoveryParams& rp) {
  const auto ticks = [&](double s) { return static_cast<std::int64_t>(std::llround(s / tick_s_)); };
  const bool in_air = steps_[k].start <= tick_;
  const Eigen::Vector2d p_now = ZmpAt(tick_);
  const int j = PhaseAt(tick_);
  const bool in_phase = j >= 0 && j < static_cast<int>(phases_.size());
  std::vector<Footstep> later;
  std::vector<Pose2> centres;
  for (size_t i = in_air ? k + 1 : k; i < steps_.size(); ++i) {
    Footstep f = steps_[i].step;
    Pose2 ce = steps_[i].centre;
    const Eigen::Vector2d& by = shift[std::min(i - k, shift.size() - 1)];
    f.pose.x += by.x();
    f.pose.y += by.y();
    ce.x += by.x();
    ce.y += by.y();
    later.push_back(f);
    centres.push_back(ce);
  }
  const auto truncate_now = [&] {  // the phase holding now ends now
    phases_.resize(static_cast<size_t>(j) + 1);
    Phase& ph = phases_.back();
    ph.end = tick_;
    ph.to = p_now;
    if (ph.end <= ph.start && phases_.size() > 1) phases_.pop_back();
  };
  std::int64_t cut = in_air ? land : steps_[k].start;
  if (in_air) {
    Scheduled& st = steps_[k];
    const Eigen::Vector2d& dk = shift[0];
    const double s0 = SwingProgress(st);
    const double m = std::clamp((s0 - 0.1) / 0.8, 0.0, 1.0), b = 0.5 * (1 - std::cos(std::numbers::pi * m));
    st.from.x -= b / (1 - b) * dk.x();  // the foot where it is now, then to the new landing
    st.from.y -= b / (1 - b) * dk.y();
    st.step.pose.x += dk.x();
    st.step.pose.y += dk.y();
    st.planned = st.step.pose;
    st.centre.x += dk.x();
    st.centre.y += dk.y();
    if (land != st.land) {
      st.s_retimed = s0;
      st.retimed = tick_;
      st.land = land;
    }
    if (in_phase) {  // the single support: the ankles' ZMP from now to the landing
      const int next = phases_[static_cast<size_t>(j)].next;
      truncate_now();
      const std::int64_t ramp = std::min(land - tick_, ticks(rp.ankle_ramp));
      if (ramp > 0) AddPhase(ramp, p_now + u, Kind::kSingle, next);
      if (land - tick_ - ramp > 0) AddPhase(land - tick_ - ramp, p_now + u, Kind::kSingle, next);
    }
  } else if (lift >= 0) {
    const Eigen::Vector2d to = ZmpPoint(steps_[k].stance);
    const int side = static_cast<int>(steps_[k].step.side);
    while (!steps_.empty() && steps_.back().start >= tick_) steps_.pop_back();
    truncate_now();
    if (lift > 0) AddPhase(lift, to + u, Kind::kShift, side);
    cut = phases_.back().end;
  }
  if (!later.empty()) {
    AppendAt(cut, later, centres, rp.fast_steps, ticks(rp.fast_single), ticks(rp.fast_double),
             lift >= 0 ? u : Eigen::Vector2d::Zero());
  } else {
    Cut(cut);
    const Scheduled& st = steps_[k];
    AddPhase(end_ticks_, 0.5 * (ZmpPoint(st.stance) + ZmpPoint(st.step.pose)), Kind::kEnd, -1);
  }
}

bool WalkPattern::Regenerate(const Eigen::Vector2d& com, const Eigen::Vector2d& com_vel,
                             const RecoveryParams& rp) {
  Prune();
  const double omega = std::sqrt(gravity_ / g_.com_height);
  const auto ticks = [&](double s) { return static_cast<std::int64_t>(std::llround(s / tick_s_)); };
  const std::int64_t late = ticks(rp.late);
  size_t k = 0;                                     // the first step whose landing may move
  const auto too_late = [&](const Scheduled& st) {  // in the air, about to land
    if (st.start > tick_) return false;
    const double m = std::clamp((SwingProgress(st) - 0.1) / 0.8, 0.0, 1.0);
    return st.land - tick_ < late || 0.5 * (1 - std::cos(std::numbers::pi * m)) > 0.9;
  };
  while (k < steps_.size() && (steps_[k].land <= tick_ || too_late(steps_[k]))) ++k;
  if (k == steps_.size() || !steps_[k].swing) return false;
  if (!rp.in_double_support && steps_[k].start > tick_) return false;
  const bool in_air = steps_[k].start <= tick_;
  const Eigen::Vector2d xi = com + com_vel / omega;
  const Eigen::Vector2d p_now = ZmpAt(tick_);
  // Ankles (single support): the stance foot's ZMP toward the error, at
  // most by it (the DCM error then holds still). Timing (double support):
  // the shift onto the stance foot ends within fast_double, then a fast
  // step; (single support) the foot lands sooner while beyond reach.
  Eigen::Vector2d u = Eigen::Vector2d::Zero();
  std::int64_t land = steps_[k].land, lift = -1;
  const int j = PhaseAt(tick_);
  const Eigen::Vector2d e = xi - (this->com() + com_velocity() / omega);
  if (in_air) {
    u = ClampToPolygon(p_now + e, Corners(steps_[k].stance, g_), rp.ankle_margin) - p_now;
  } else if (rp.early_lift && j >= 0 && j < static_cast<int>(phases_.size()) &&
             phases_[static_cast<size_t>(j)].kind == Kind::kShift &&
             phases_[static_cast<size_t>(j)].end == steps_[k].start) {
    lift = std::min(steps_[k].start - tick_, ticks(rp.fast_double));
    const Eigen::Vector2d to = ZmpPoint(steps_[k].stance);
    u = ClampToPolygon(to + e, Corners(steps_[k].stance, g_), rp.ankle_margin) - to;
  }
  const std::int64_t soonest = in_air ? std::max(tick_ + late, steps_[k].start + ticks(rp.min_swing)) : land;
  // The error against the plan's own DCM (its preview state); a change of
  // timing below moves the reference's DCM by what NominalDcm says.
  const Eigen::Vector2d nominal = NominalDcm();
  const std::vector<Phase> phases = phases_;
  const std::vector<Scheduled> steps = steps_;
  const double wd = omega * rp.fast_double;
  const double g_ramp =
      wd > 1e-9 ? (1 - std::exp(-wd)) / wd : 1.0;  // a shift's effect on the DCM, per e^{-wT}
  std::vector<Eigen::Vector2d> shift;
  bool fits = false;
  for (;; land = std::max(soonest, land - ticks(0.025))) {
    phases_ = phases;
    steps_ = steps;
    Rebuild(k, land, lift, u, {Eigen::Vector2d::Zero()}, rp);
    // The landings' shifts that make the reference's DCM the measured one:
    // sum_i delta_i e^{-w T_i} g = e0 (T_i: step i's landing), step by step
    // within reach of the landing before.
    Eigen::Vector2d rest = (e - (NominalDcm() - nominal)) / g_ramp, total = Eigen::Vector2d::Zero();
    shift.clear();
    Pose2 on = steps_[k].stance;
    fits = true;
    for (size_t i = k; i < steps_.size() && i < k + 4; ++i) {
      const double grow = std::exp(omega * static_cast<double>(steps_[i].land - tick_) * tick_s_);
      const Eigen::Vector2d want = total + rest * grow;
      const Pose2& plan = steps_[i].step.pose;
      const double c = std::cos(on.theta), s = std::sin(on.theta), side = SideSign(steps_[i].step.side);
      const Eigen::Vector2d w = plan.xy() + want - on.xy();
      const Eigen::Vector2d local(c * w.x() + s * w.y(), -s * w.x() + c * w.y());
      const Eigen::Vector2d got(std::clamp(local.x(), -rp.reach_back, rp.reach),
                                side * std::clamp(side * local.y(), rp.min_width, rp.max_width));
      Eigen::Vector2d now =
          on.xy() + Eigen::Vector2d(c * got.x() - s * got.y(), s * got.x() + c * got.y()) - plan.xy();
      if (i == k && in_air) {  // the swing foot's speed
        const double most = rp.swing_speed * static_cast<double>(land - tick_) * tick_s_;
        if ((now - total).norm() > most) now = total + (now - total) * (most / (now - total).norm());
      }
      if (i == k) fits = (now - want).norm() < 1e-6;
      rest -= (now - total) / grow;
      total = now;
      shift.push_back(total);
      on = plan;
      on.x += total.x();
      on.y += total.y();
    }
    if (fits || land <= soonest) break;
  }
  phases_ = phases;
  steps_ = steps;
  Rebuild(k, land, lift, u, shift, rp);
  SetComState(com, com_vel);
  return true;
}

PushRecovery::PushRecovery(double omega, double tick, RecoveryParams params)
    : omega_(omega), tick_(tick), p_(params) {
  if (!(omega > 0) || !(tick > 0) || !(p_.threshold >= 0) || !(p_.reach > 0)) {
    throw std::invalid_argument("PushRecovery: omega, tick and reach must be > 0, threshold >= 0");
  }
  if (!(p_.stop_impulse >= 0) || (p_.stop_impulse > 0 && !(p_.stop_hold > 0))) {
    throw std::invalid_argument("PushRecovery: stop_impulse must be >= 0 (0: off) and stop_hold > 0");
  }
}

bool PushRecovery::Update(WalkPattern& pattern, const Eigen::Vector2d& com, const Eigen::Vector2d& com_vel) {
  since_ += tick_;
  error_ = (com + com_vel / omega_) - (pattern.com() + pattern.com_velocity() / omega_);
  // Per axis: an axis within the threshold keeps the plan's state (the
  // measured one's noise, amplified by e^{w T}, would move the feet).
  const Eigen::Array2d over = (error_.array().abs() > p_.threshold).cast<double>();
  if (!over.any() || since_ < p_.interval) return false;
  const Eigen::Vector2d c = over * com.array() + (1 - over) * pattern.com().array();
  const Eigen::Vector2d v = over * com_vel.array() + (1 - over) * pattern.com_velocity().array();
  if (!pattern.Regenerate(c, v, p_)) return false;
  since_ = 0;
  ++count_;
  return true;
}

PushRecovery::Walk PushRecovery::Watch(WalkPattern& pattern, const Eigen::Vector2d& impulse) {
  if (p_.stop_impulse > 0 && impulse.norm() > p_.stop_impulse) {
    if (hold_ <= 0 && !pattern.standing()) {
      pattern.StopSoon();
      ++stops_;
      hold_ = p_.stop_hold;
    } else if (hold_ > 0) {
      hold_ = p_.stop_hold;
    }
  }
  if (hold_ <= 0) return Walk::kOn;
  hold_ -= tick_;
  return hold_ > 0 ? Walk::kHold : Walk::kResume;
}

}  // namespace robotalk::walking
