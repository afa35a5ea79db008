// Push recovery: see push_recovery.h.
#include "walking/push_recovery.h"

#include "walking/dcm_stabilizer.h"
#include "walking/step_timing.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <span>
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
  std::int64_t cut = in_air ? land : steps_[k].start;
  if (in_air) {
    Scheduled& st = steps_[k];
    MoveLanding(st, shift[0], land);
    st.centre.x += shift[0].x();
    st.centre.y += shift[0].y();
    if (in_phase) {  // the single support: the ankles' ZMP from now to the landing
      const int next = phases_[static_cast<size_t>(j)].next;
      TruncateNow(j, p_now);
      const std::int64_t ramp = std::min(land - tick_, ticks(rp.ankle_ramp));
      if (ramp > 0) AddPhase(ramp, p_now + u, Kind::kSingle, next);
      if (land - tick_ - ramp > 0) AddPhase(land - tick_ - ramp, p_now + u, Kind::kSingle, next);
    }
  } else if (lift >= 0) {
    const Eigen::Vector2d to = ZmpPoint(steps_[k].stance);
    const int side = static_cast<int>(steps_[k].step.side);
    while (!steps_.empty() && steps_.back().start >= tick_) steps_.pop_back();
    TruncateNow(j, p_now);
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

bool WalkPattern::TooLate(const Scheduled& st, std::int64_t late) const {
  if (st.start > tick_) return false;
  const double m = std::clamp((SwingProgress(st) - 0.1) / 0.8, 0.0, 1.0);
  return st.land - tick_ < late || 0.5 * (1 - std::cos(std::numbers::pi * m)) > 0.9;
}

void WalkPattern::TruncateNow(int j, const Eigen::Vector2d& p_now) {
  phases_.resize(static_cast<size_t>(j) + 1);
  Phase& ph = phases_.back();
  ph.end = tick_;
  ph.to = p_now;
  if (ph.end <= ph.start && phases_.size() > 1) phases_.pop_back();
}

void WalkPattern::MoveLanding(Scheduled& st, const Eigen::Vector2d& by, std::int64_t land) {
  if (st.start <= tick_) {
    const double s0 = SwingProgress(st);
    const double m = std::clamp((s0 - 0.1) / 0.8, 0.0, 1.0), b = 0.5 * (1 - std::cos(std::numbers::pi * m));
    st.from.x -= b / (1 - b) * by.x();  // the foot where it is now, then to the new landing
    st.from.y -= b / (1 - b) * by.y();
    if (land != st.land) {
      st.s_retimed = s0;
      st.retimed = tick_;
      st.land = land;
    }
  }
  st.step.pose.x += by.x();
  st.step.pose.y += by.y();
  st.planned = st.step.pose;
}

bool WalkPattern::Regenerate(const Eigen::Vector2d& com, const Eigen::Vector2d& com_vel,
                             const RecoveryParams& rp, bool stopping) {
  Prune();
  const double omega = std::sqrt(gravity_ / g_.com_height);
  const auto ticks = [&](double s) { return static_cast<std::int64_t>(std::llround(s / tick_s_)); };
  const std::int64_t late = ticks(rp.late);
  size_t k = 0;  // the first step whose landing may move
  while (k < steps_.size() && (steps_[k].land <= tick_ || TooLate(steps_[k], late))) ++k;
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
    // The shift's target (it may hold an earlier regeneration's ankles) moves
    // to this one's over at least 0.4 ankle_ramp (20 ms; the full ramp lost 4
    // more ODE pushes of 384): moved in full in the ticks left before the
    // lift, the reference jumped up to 10 cm in a tick (push_recovery_test,
    // "TwoPushes"). Between two points inside the sole, so inside it.
    const Eigen::Vector2d target = phases_[static_cast<size_t>(j)].to;
    const double part = std::min(1.0, static_cast<double>(lift) / static_cast<double>(std::max<std::int64_t>(
                                                                      1, ticks(0.4 * rp.ankle_ramp))));
    u = target + part * (to + u - target) - to;
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
  if (stopping &&
      rp.stop_feet == RecoveryParams::StopFeet::kKeep) {  // the stop lands where and when it was to
    Rebuild(k, land, lift, u, {Eigen::Vector2d::Zero()}, rp);
    SetComState(com, com_vel);
    return true;
  }
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
        const double left = static_cast<double>(land - tick_) * tick_s_, most = rp.swing_speed * left;
        if ((now - total).norm() > most) now = total + (now - total) * (most / (now - total).norm());
        if (rp.swing_reach > 0) {  // the landing within what the foot can reach from where it is
          // The foot moves horizontally until 0.9 of its swing (UpdateFeet), its
          // progress linear to 1 at the landing from now.
          const double s0 = SwingProgress(steps_[i]), moving = s0 < 0.9 ? left * (0.9 - s0) / (1 - s0) : 0.0;
          const Eigen::Vector2d at = foot_[static_cast<int>(steps_[i].step.side)].xy();
          const Eigen::Vector2d to = plan.xy() + now - at;
          const double far = std::max((plan.xy() - at).norm(), rp.swing_reach * moving);
          if (to.norm() > far) now = at + to * (far / to.norm()) - plan.xy();
        }
      }
      if (rp.lift_reach > 0 && !(i == k && in_air) && steps_[i].swing) {
        // A step not yet in the air: within what its swing reaches from where
        // its foot stands before it (the foot's earlier landing, moved with
        // this regeneration's shift when it is one of its steps), then back
        // inside the reach box (the legs' limits first).
        Eigen::Vector2d from = steps_[i].from.xy();
        if (i >= k + 2) from += shift[i - 2 - k];
        const double moving =
            0.8 * static_cast<double>(steps_[i].land - steps_[i].start) * tick_s_;  // (0.1 to 0.9)
        const double far = std::max((plan.xy() - steps_[i].from.xy()).norm(), rp.lift_reach * moving);
        const Eigen::Vector2d to = plan.xy() + now - from;
        if (to.norm() > far) {
          const Eigen::Vector2d v = from + to * (far / to.norm()) - on.xy();
          const Eigen::Vector2d l(c * v.x() + s * v.y(), -s * v.x() + c * v.y());
          const Eigen::Vector2d b(std::clamp(l.x(), -rp.reach_back, rp.reach),
                                  side * std::clamp(side * l.y(), rp.min_width, rp.max_width));
          now = on.xy() + Eigen::Vector2d(c * b.x() - s * b.y(), s * b.x() + c * b.y()) - plan.xy();
        }
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

bool WalkPattern::AdaptStep(const Eigen::Vector2d& com, const Eigen::Vector2d& com_vel,
                            const StepTimingAdapter& adapter, const RecoveryParams& rp, bool only_sooner) {
  Prune();
  const auto ticks = [&](double s) { return static_cast<std::int64_t>(std::llround(s / tick_s_)); };
  size_t k = 0;  // the step in the air
  while (k < steps_.size() && steps_[k].land <= tick_) ++k;
  if (k == steps_.size() || !steps_[k].swing || steps_[k].start > tick_ ||
      TooLate(steps_[k], ticks(rp.late))) {
    return false;
  }
  const double omega = std::sqrt(gravity_ / g_.com_height);
  const Scheduled& st = steps_[k];
  const Eigen::Vector2d xi = com + com_vel / omega, xi_plan = this->com() + com_velocity() / omega;
  const Eigen::Vector2d p_now = ZmpAt(tick_);
  // The ankles as the regeneration's: the stance ZMP toward the error, inside the sole.
  const Eigen::Vector2d u =
      ClampToPolygon(p_now + xi - xi_plan, Corners(st.stance, g_), rp.ankle_margin) - p_now;
  StepSituation s;
  s.dcm = xi;
  s.cop = p_now + u;
  s.stance = st.stance;
  s.swing = st.step.side;
  s.landing = st.step.pose.xy();
  s.offset = DcmAt(st.land, xi_plan) - s.landing;  // the plan's own DCM at its landing
  s.remaining = static_cast<double>(st.land - tick_) * tick_s_;
  const std::int64_t soonest = std::max(tick_ + ticks(rp.late), st.start + ticks(rp.min_swing));
  s.soonest = static_cast<double>(std::max<std::int64_t>(0, soonest - tick_)) * tick_s_;
  s.foot = foot_[static_cast<int>(st.step.side)].xy();
  s.foot_speed = rp.swing_reach;
  const StepTiming r = adapter.Solve(s);
  if (only_sooner && r.remaining > s.remaining - rp.timing_sooner) return false;
  const std::int64_t land = std::clamp(tick_ + ticks(r.remaining), std::min(soonest, st.land), st.land);
  Rebuild(k, land, -1, u, {r.landing - s.landing}, rp);
  SetComState(com, com_vel);
  return true;
}

Eigen::Vector2d WalkPattern::DcmAt(std::int64_t at, const Eigen::Vector2d& xi0) const {
  // xi(T) = e^{wT} (xi0 - w int_0^T e^{-wt} p(now + t) dt), midpoint rule over 5 ticks.
  const double omega = std::sqrt(gravity_ / g_.com_height);
  Eigen::Vector2d pulled = Eigen::Vector2d::Zero();
  for (std::int64_t i = 0; i < at - tick_; i += 5) {
    const std::int64_t n = std::min<std::int64_t>(5, at - tick_ - i);
    const double t0 = static_cast<double>(i) * tick_s_, t1 = static_cast<double>(i + n) * tick_s_;
    pulled += (std::exp(-omega * t0) - std::exp(-omega * t1)) * ZmpAt(tick_ + i + n / 2);
  }
  return std::exp(omega * static_cast<double>(at - tick_) * tick_s_) * (xi0 - pulled);
}

bool WalkPattern::CaptureStop(const Eigen::Vector2d& com, const Eigen::Vector2d& com_vel,
                              const RecoveryParams& rp) {
  Prune();
  const auto ticks = [&](double s) { return static_cast<std::int64_t>(std::llround(s / tick_s_)); };
  size_t k = 0;  // the first step whose landing may move
  while (k < steps_.size() && TooLate(steps_[k], ticks(rp.late))) ++k;
  if (k == steps_.size() || !steps_[k].swing || steps_[k].tidy) return false;
  // It becomes the stop's last step; where it cannot catch the DCM (reach,
  // swing speed), it lands as it would and the other foot, brought
  // alongside it after (as StopSoon has it), catches the DCM.
  const std::vector<Scheduled> steps = steps_;
  const std::vector<Phase> phases = phases_;
  if (CaptureWith(k, com, com_vel, rp)) return true;
  steps_ = steps;
  phases_ = phases;
  steps_.resize(k + 1);
  Scheduled along;  // the other foot brought alongside step k's landing, as StopSoon has it
  const Scheduled& st = steps_[k];
  along.step = {Other(st.step.side), st.step.pose};
  const Eigen::Vector2d at = st.step.pose.Apply(0, -SideSign(st.step.side) * g_.foot_separation);
  along.step.pose.x = at.x();
  along.step.pose.y = at.y();
  along.planned = along.step.pose;
  along.uncaptured = along.step.pose;
  along.captured = true;
  along.from = st.stance;
  along.stance = st.step.pose;
  along.centre = st.centre;
  while (phases_.size() > 1 && phases_.back().start >= st.land) phases_.pop_back();
  AddPhase(ds_ticks_, ZmpPoint(st.step.pose), Kind::kShift, static_cast<int>(along.step.side));
  along.start = phases_.back().end;
  along.land = along.start + ss_ticks_;
  AddPhase(ss_ticks_, ZmpPoint(st.step.pose), Kind::kSingle, -1);
  steps_.push_back(along);
  CaptureWith(k + 1, com, com_vel, rp);
  return true;
}

bool WalkPattern::CaptureWith(size_t k, const Eigen::Vector2d& com, const Eigen::Vector2d& com_vel,
                              const RecoveryParams& rp) {
  const auto ticks = [&](double s) { return static_cast<std::int64_t>(std::llround(s / tick_s_)); };
  steps_.resize(k + 1);
  Scheduled& st = steps_[k];
  if (!st.captured) st.uncaptured = st.step.pose;
  st.captured = true;
  const bool in_air = st.start <= tick_;
  const int j = PhaseAt(tick_);
  const double omega = std::sqrt(gravity_ / g_.com_height);
  const Eigen::Vector2d xi0 = com + com_vel / omega, p_now = ZmpAt(tick_);
  const Pose2 stance = st.stance;
  const double side = SideSign(st.step.side), c = std::cos(stance.theta), s = std::sin(stance.theta);
  const auto to_local = [&](const Eigen::Vector2d& p) {
    const Eigen::Vector2d d = p - stance.xy();
    return Eigen::Vector2d(c * d.x() + s * d.y(), -s * d.x() + c * d.y());
  };
  // The ankles: in the air, the stance ZMP at the sole's point nearest the DCM.
  const Eigen::Vector2d ankle = ClampToPolygon(xi0, Corners(stance, g_), rp.ankle_margin);
  // After the landing the ZMP ramps from p_land to q over d1, holds it h,
  // ramps to the middle m over de: the reference's DCM at the landing is
  // p_land + (q - p_land) g1 + (m - q) e ge (xi = p(0) + int e^{-wt} p'(t) dt).
  const double d1 = static_cast<double>(ticks(rp.capture_shift)) * tick_s_;
  const double de = static_cast<double>(end_ticks_) * tick_s_;
  const double g1 = (1 - std::exp(-omega * d1)) / (omega * d1),
               ge = (1 - std::exp(-omega * de)) / (omega * de);
  const double e = std::exp(-omega * (d1 + static_cast<double>(ticks(rp.capture_hold)) * tick_s_));
  const std::vector<Phase> saved = phases_;
  const auto until_landing = [&](std::int64_t land) {  // the reference from now to the landing
    phases_ = saved;
    if (in_air) {
      const int next = phases_[static_cast<size_t>(j)].next;
      TruncateNow(j, p_now);
      const std::int64_t ramp = std::min(land - tick_, ticks(rp.ankle_ramp));
      if (ramp > 0) AddPhase(ramp, ankle, Kind::kSingle, next);
      if (land - tick_ - ramp > 0) AddPhase(land - tick_ - ramp, ankle, Kind::kSingle, next);
    } else {
      while (phases_.size() > 1 && phases_.back().start >= land) phases_.pop_back();
    }
  };
  const std::int64_t soonest =
      in_air ? std::max(tick_ + ticks(rp.late), st.start + ticks(rp.min_swing)) : st.land;
  std::int64_t land = st.land;
  Pose2 foot;
  Eigen::Vector2d q, m;
  bool fits = true;
  for (;; land = std::max(soonest, land - ticks(0.025))) {
    until_landing(land);
    const Eigen::Vector2d xi_land = DcmAt(land, xi0), p_land = phases_.back().to;
    // The landing as planned before the capture (the stop's: alongside),
    // moved only as far as q needs to be inside the soles' hull, within
    // reach and width of the stance foot, and (in the air) swing speed.
    const Eigen::Vector2d n0 = to_local(st.uncaptured.xy());
    Eigen::Vector2d f(n0.x(), side * n0.y());
    for (int it = 0; it < 4; ++it) {
      foot = {stance.Apply(f.x(), side * f.y()).x(), stance.Apply(f.x(), side * f.y()).y(), stance.theta};
      m = 0.5 * (ZmpPoint(stance) + ZmpPoint(foot));
      q = (xi_land - p_land * (1 - g1) - m * e * ge) / (g1 - e * ge);
      std::array<Eigen::Vector2d, 16> h;
      const Eigen::Vector2d out =
          q - ClampToPolygon(q, std::span(h.data(), static_cast<size_t>(HullOfSoles(stance, foot, g_, h))),
                             rp.capture_margin);
      // (sideways only outward: a foot moved inward narrows the support)
      const Eigen::Vector2d d(c * out.x() + s * out.y(), std::max(0.0, side * (-s * out.x() + c * out.y())));
      const Eigen::Vector2d want = f + d;
      f = {std::clamp(want.x(), -rp.reach_back, rp.reach), std::clamp(want.y(), rp.min_width, rp.max_width)};
      fits = (f - want).norm() < 1e-9;
    }
    foot = {stance.Apply(f.x(), side * f.y()).x(), stance.Apply(f.x(), side * f.y()).y(), stance.theta};
    const double most = rp.swing_speed * static_cast<double>(land - tick_) * tick_s_;
    fits = fits && (!in_air || (foot.xy() - st.step.pose.xy()).norm() <= most);
    if (fits || land <= soonest) break;
  }
  Eigen::Vector2d by = foot.xy() - st.step.pose.xy();
  if (in_air) {  // the swing foot's speed
    const double most = rp.swing_speed * static_cast<double>(land - tick_) * tick_s_;
    if (by.norm() > most) by *= most / by.norm();
  }
  MoveLanding(st, by, land);
  st.step.pose.theta = stance.theta;
  st.planned = st.step.pose;
  const Pose2 mid{0.5 * (stance.x + st.step.pose.x), 0.5 * (stance.y + st.step.pose.y), stance.theta};
  const Eigen::Vector2d centre = mid.Apply(-g_.ankle_x, 0);
  st.centre = {centre.x(), centre.y(), stance.theta};
  // Moved off alongside: after the hold the weight goes onto the moved foot
  // (as a start's first shift) and the other foot steps alongside it, so
  // that the walk resumes from its usual stance; else to the middle.
  const Eigen::Vector2d beside = st.step.pose.Apply(0, -side * g_.foot_separation);
  const bool tidy = rp.capture_tidy && (beside - stance.xy()).norm() > rp.capture_tidy_beyond;
  const Eigen::Vector2d after =
      tidy ? ZmpPoint(st.step.pose) : Eigen::Vector2d(0.5 * (ZmpPoint(stance) + ZmpPoint(st.step.pose)));
  q = (DcmAt(land, xi0) - phases_.back().to * (1 - g1) - after * e * ge) / (g1 - e * ge);
  std::array<Eigen::Vector2d, 16> hull;
  const int n = HullOfSoles(stance, st.step.pose, g_, hull);
  q = ClampToPolygon(q, std::span(hull.data(), static_cast<size_t>(n)), rp.capture_margin);
  AddPhase(ticks(rp.capture_shift), q, Kind::kShift, -1);
  AddPhase(ticks(rp.capture_hold), q, Kind::kHold, -1);
  if (tidy) {
    Scheduled t;
    t.tidy = true;
    t.step = {Other(st.step.side), {beside.x(), beside.y(), st.step.pose.theta}};
    t.planned = t.step.pose;
    t.from = stance;
    t.stance = st.step.pose;
    const Eigen::Vector2d c2 =
        Pose2{0.5 * (beside.x() + st.step.pose.x), 0.5 * (beside.y() + st.step.pose.y), st.step.pose.theta}
            .Apply(-g_.ankle_x, 0);
    t.centre = {c2.x(), c2.y(), st.step.pose.theta};
    AddPhase(end_ticks_, after, Kind::kShift, static_cast<int>(t.step.side));
    t.start = phases_.back().end;
    t.land = t.start + ss_ticks_;
    AddPhase(ss_ticks_, after, Kind::kSingle, -1);
    steps_.push_back(t);
    AddPhase(end_ticks_, 0.5 * (ZmpPoint(t.step.pose) + after), Kind::kEnd, -1);
  } else {
    AddPhase(end_ticks_, after, Kind::kEnd, -1);
  }
  if (rp.capture_reanchor) SetComState(com, com_vel);
  return fits;
}

PushRecovery::PushRecovery(double omega, double tick, RecoveryParams params)
    : omega_(omega), tick_(tick), p_(params) {
  if (!(omega > 0) || !(tick > 0) || !(p_.threshold >= 0) || !(p_.reach > 0)) {
    throw std::invalid_argument("PushRecovery: omega, tick and reach must be > 0, threshold >= 0");
  }
  if (!(p_.swing_reach >= 0)) throw std::invalid_argument("PushRecovery: swing_reach must be >= 0 (0: off)");
  if (!(p_.lift_reach >= 0)) throw std::invalid_argument("PushRecovery: lift_reach must be >= 0 (0: off)");
  if (!(p_.stop_impulse >= 0) || (p_.stop_impulse > 0 && !(p_.stop_hold > 0))) {
    throw std::invalid_argument("PushRecovery: stop_impulse must be >= 0 (0: off) and stop_hold > 0");
  }
  if (p_.step_timing != RecoveryParams::TimingMode::kOff) {
    StepTimingParams t = p_.timing;
    t.reach = p_.reach;
    t.reach_back = p_.reach_back;
    t.min_width = p_.min_width;
    t.max_width = p_.max_width;
    timing_.emplace(omega, t);
  }
  if (!(p_.stop_wait >= 0) || !(p_.wait_share >= 0 && p_.wait_share <= 1) || !(p_.wait_margin >= 0)) {
    throw std::invalid_argument("PushRecovery: stop_wait and wait_margin must be >= 0, wait_share in [0, 1]");
  }
  if (!(p_.capture_margin >= 0) || !(p_.capture_shift > 0) || !(p_.capture_hold >= 0) ||
      !(p_.capture_tidy_beyond >= 0)) {
    throw std::invalid_argument(
        "PushRecovery: capture_margin, capture_hold and capture_tidy_beyond must be >= 0 and capture_shift > "
        "0");
  }
}

bool PushRecovery::Update(WalkPattern& pattern, const Eigen::Vector2d& com, const Eigen::Vector2d& com_vel) {
  since_ += tick_;
  error_ = (com + com_vel / omega_) - (pattern.com() + pattern.com_velocity() / omega_);
  if (timing_ && since_ >= p_.interval) {
    // Step timing: from the push's reading until a step it re-planned lands
    // (read in double support: the next step to lift; kPush, kAlways: only
    // a step the adapter lands sooner than planned, else the regeneration
    // below as ever), and
    // whenever the DCM error passes the threshold with a foot in the air
    // (kThreshold, kAlways: in place of the regeneration).
    using Mode = RecoveryParams::TimingMode;
    const bool over = (error_.array().abs() > p_.threshold).any() && p_.step_timing != Mode::kPush;
    pushed_ = pushed_ && p_.step_timing != Mode::kThreshold;
    if (pushed_ || over) {
      if (pattern.AdaptStep(com, com_vel, *timing_, p_, !over)) {
        since_ = 0;
        ++timed_;
        adapted_ = true;
        return true;
      }
      // No foot in the air (or too late): the regeneration below as ever.
      if (adapted_ || pattern.standing()) pushed_ = adapted_ = false;
    }
  }
  if (capturing_) {  // the capture stop re-plans until its last step lands; no regeneration meanwhile
    if (since_ < p_.interval) return false;
    capturing_ = pattern.CaptureStop(com, com_vel, p_);
    if (!capturing_) return false;
    since_ = 0;
    ++captures_;
    return true;
  }
  // Per axis: an axis within the threshold keeps the plan's state (the
  // measured one's noise, amplified by e^{w T}, would move the feet).
  const Eigen::Array2d over = (error_.array().abs() > p_.threshold).cast<double>();
  if (!over.any() || since_ < p_.interval) return false;
  if (hold_ > 0 && p_.stop_feet == RecoveryParams::StopFeet::kStill) return false;
  const Eigen::Vector2d c = over * com.array() + (1 - over) * pattern.com().array();
  const Eigen::Vector2d v = over * com_vel.array() + (1 - over) * pattern.com_velocity().array();
  if (!pattern.Regenerate(c, v, p_, hold_ > 0)) return false;
  since_ = 0;
  ++count_;
  return true;
}

bool LiftReady(const Pose2& stance, const GaitParams& g, const Eigen::Vector2d& dcm, double force,
               double weight, const RecoveryParams& p) {
  return force >= p.wait_share * weight && InFoot(stance, g, dcm, p.wait_margin);
}

bool LandReady(double force, double weight, const RecoveryParams& p) {
  return force >= p.touch_share * weight;
}

bool PushRecovery::GateLift(WalkPattern& pattern, bool ready, const Eigen::Vector2d& com,
                            const Eigen::Vector2d& com_vel) {
  const bool lift = pattern.lifting_next() != nullptr;
  if (p_.stop_wait <= 0) return false;
  if (hold_ <= 0 || (!lift && pattern.landing_next() == nullptr)) {
    waiting_ = 0;  // a wait the hold's end or a re-plan cut short: the next event waits afresh
    return false;
  }
  if (!ready && waiting_ < p_.stop_wait - 0.5 * tick_) {
    if (lift) {
      pattern.DelayLift(1);
    } else {
      pattern.DelayShift(1);
    }
    waiting_ += tick_;
    waited_total_ += tick_;
    return false;
  }
  const bool waited = waiting_ > 0;
  waiting_ = 0;
  if (!waited || !p_.wait_reanchor) return false;
  pattern.Reanchor(com, com_vel);
  return true;
}

PushRecovery::Walk PushRecovery::Watch(WalkPattern& pattern, const Eigen::Vector2d& impulse) {
  if (p_.stop_impulse > 0 && impulse.norm() > p_.stop_impulse) {
    if (hold_ <= 0 && !pattern.standing()) {
      pattern.StopSoon();
      pushed_ = timing_.has_value();
      adapted_ = false;
      if (pushed_) since_ = 1e9;  // the step timing's first re-plan at the next Update
      ++stops_;
      hold_ = p_.stop_hold;
      capturing_ = p_.capture_stop;
      if (capturing_) since_ = 1e9;  // the capture's first re-plan at the next Update
    } else if (hold_ > 0) {
      hold_ = p_.stop_hold;
    }
  }
  if (hold_ <= 0) return Walk::kOn;
  hold_ -= tick_;
  return hold_ > 0 ? Walk::kHold : Walk::kResume;
}

}  // namespace robotalk::walking
