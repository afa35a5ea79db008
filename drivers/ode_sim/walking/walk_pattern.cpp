// The walking pattern: see walk_pattern.h.
#include "walking/walk_pattern.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

namespace robotalk::walking {
namespace {

Pose2 Lerp(const Pose2& a, const Pose2& b, double s) {
  return {a.x + s * (b.x - a.x), a.y + s * (b.y - a.y), Wrap(a.theta + s * Wrap(b.theta - a.theta))};
}

double Cross(const Eigen::Vector2d& o, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  return (a.x() - o.x()) * (b.y() - o.y()) - (a.y() - o.y()) * (b.x() - o.x());
}

// R of the preview's cost (Qe = 1): 1e-5 tracks a 0.8 s weight shift seen
// 1 s ahead within 6 mm; Kajita's 1e-6 swings the ZMP harder for little gain.
constexpr double kJerkWeight = 1e-5;

bool SamePose(const Pose2& a, const Pose2& b) {
  return std::hypot(a.x - b.x, a.y - b.y) < 1e-6 && std::abs(Wrap(a.theta - b.theta)) < 1e-6;
}

}  // namespace

std::array<Eigen::Vector2d, 4> Corners(const Pose2& f, const GaitParams& g) {
  return {f.Apply(g.foot_front, g.foot_half_width), f.Apply(-g.foot_back, g.foot_half_width),
          f.Apply(-g.foot_back, -g.foot_half_width), f.Apply(g.foot_front, -g.foot_half_width)};
}

bool InFoot(const Pose2& foot, const GaitParams& g, const Eigen::Vector2d& p, double margin) {
  const double c = std::cos(foot.theta), s = std::sin(foot.theta);
  const double lx = c * (p.x() - foot.x) + s * (p.y() - foot.y),
               ly = -s * (p.x() - foot.x) + c * (p.y() - foot.y);
  return lx <= g.foot_front - margin && lx >= -g.foot_back + margin &&
         std::abs(ly) <= g.foot_half_width - margin;
}

WalkPattern::WalkPattern(const GaitParams& g, double tick, int preview_every, double gravity, double horizon)
    : g_(g),
      tick_s_(tick),
      every_(preview_every),
      gravity_(gravity),
      ss_ticks_(std::llround(g.single_support / tick)),
      ds_ticks_(std::llround(g.double_support / tick)),
      start_ticks_(std::llround(g.start_shift / tick)),
      end_ticks_(std::llround(g.end_shift / tick)),
      lead_ticks_(std::llround(g.start_lead / tick)),
      px_(tick * preview_every, g.com_height, gravity, horizon, 1.0, kJerkWeight),
      py_(tick * preview_every, g.com_height, gravity, horizon, 1.0, kJerkWeight) {
  future_x_.resize(static_cast<size_t>(px_.horizon_samples()));
  future_y_.resize(future_x_.size());
  steps_.reserve(512);
  phases_.reserve(1024);
  Reset({}, Eigen::Vector2d::Zero());
}

void WalkPattern::Reset(const Pose2& centre, const Eigen::Vector2d& com) {
  steps_.clear();
  rest_[0] = foot_[0] = FootAt(centre, Side::kLeft, g_);
  rest_[1] = foot_[1] = FootAt(centre, Side::kRight, g_);
  rest_centre_ = centre;
  height_[0] = height_[1] = 0;
  const Eigen::Vector2d mid = 0.5 * (ZmpPoint(rest_[0]) + ZmpPoint(rest_[1]));
  phases_.clear();
  phases_.push_back(
      Phase{.start = tick_, .end = tick_, .from = mid, .to = mid, .kind = Kind::kHold, .next = -1});
  px_.Reset(com.x());
  py_.Reset(com.y());
  cx_ = px_.state();
  cy_ = py_.state();
  sample_x_ = cx_;
  sample_y_ = cy_;
  ux_ = uy_ = 0;
}

Eigen::Vector2d WalkPattern::ZmpPoint(const Pose2& foot) const { return foot.Apply(g_.zmp_x, 0); }

int WalkPattern::PhaseAt(std::int64_t tick) const {
  if (tick < phases_.front().start) return -1;
  const auto it = std::upper_bound(phases_.begin(), phases_.end(), tick,
                                   [](std::int64_t t, const Phase& p) { return t < p.end; });
  return static_cast<int>(it - phases_.begin());
}

Eigen::Vector2d WalkPattern::ZmpAt(std::int64_t tick) const {
  const int k = PhaseAt(tick);
  if (k < 0) return phases_.front().from;
  if (k >= static_cast<int>(phases_.size())) return phases_.back().to;
  const Phase& p = phases_[static_cast<size_t>(k)];
  const double s = static_cast<double>(tick - p.start) / static_cast<double>(p.end - p.start);
  return p.from + s * (p.to - p.from);
}

// The first tick from t where the schedule may be cut without changing the
// reference before it: a phase boundary, or any tick of a standing hold. In
// single support that is after the landing and the shift onto the landed foot.
std::int64_t WalkPattern::CutTick(std::int64_t t) const {
  const int k = PhaseAt(t);
  if (k < 0 || k >= static_cast<int>(phases_.size())) return t;
  const Phase& p = phases_[static_cast<size_t>(k)];
  if (t == p.start || p.kind == Kind::kHold) return t;
  if (p.kind == Kind::kSingle && k + 1 < static_cast<int>(phases_.size()) &&
      phases_[static_cast<size_t>(k) + 1].kind == Kind::kShift) {
    return phases_[static_cast<size_t>(k) + 1].end;
  }
  return p.end;
}

std::int64_t WalkPattern::AppendTick() const {
  if (!steps_.empty() && steps_.back().land >= tick_ + lead_ticks_) return steps_.back().land;
  return CutTick(tick_ + lead_ticks_);
}

WalkPattern::Splice WalkPattern::SpliceAt(std::int64_t t) const {
  Splice sp;
  sp.centre = rest_centre_;
  for (const Scheduled& s : steps_) {
    if (s.start < t) sp.centre = s.centre;
  }
  const int k = PhaseAt(t - 1);
  if (k >= 0 && k < static_cast<int>(phases_.size()) && phases_[static_cast<size_t>(k)].end == t &&
      phases_[static_cast<size_t>(k)].next >= 0) {
    sp.next = static_cast<Side>(phases_[static_cast<size_t>(k)].next);
    sp.side_free = false;
  }
  return sp;
}

void WalkPattern::Prune() {
  size_t n = 0;
  while (n < steps_.size() && steps_[n].land <= tick_) {
    rest_[static_cast<int>(steps_[n].step.side)] = steps_[n].step.pose;
    rest_centre_ = steps_[n].centre;
    ++n;
  }
  steps_.erase(steps_.begin(), steps_.begin() + static_cast<std::ptrdiff_t>(n));
  size_t m = 0;
  while (m + 1 < phases_.size() && phases_[m].end <= tick_) ++m;
  phases_.erase(phases_.begin(), phases_.begin() + static_cast<std::ptrdiff_t>(m));
}

void WalkPattern::Cut(std::int64_t t) {
  Prune();
  const Eigen::Vector2d at = ZmpAt(t);
  while (!steps_.empty() && steps_.back().start >= t) steps_.pop_back();
  while (phases_.size() > 1 && phases_.back().start >= t) phases_.pop_back();
  Phase& last = phases_.back();
  if (last.end > t) {  // inside a hold (CutTick cuts nothing else inside)
    last.end = std::max(t, last.start);
    last.to = at;
  } else if (last.end < t) {
    AddPhase(t - last.end, last.to, Kind::kHold, -1);
  }
}

void WalkPattern::AddPhase(std::int64_t ticks, const Eigen::Vector2d& to, Kind kind, int next) {
  const Phase& last = phases_.back();
  phases_.push_back(Phase{
      .start = last.end, .end = last.end + ticks, .from = last.to, .to = to, .kind = kind, .next = next});
}

WalkPattern::Splice WalkPattern::DropUnstarted() {
  const std::int64_t t = CutTick(tick_ + lead_ticks_);
  const Splice sp = SpliceAt(t);
  Cut(t);
  return sp;
}

WalkPattern::Splice WalkPattern::AppendPoint() const { return SpliceAt(AppendTick()); }

void WalkPattern::Append(const std::vector<Footstep>& steps, const std::vector<Pose2>& centres) {
  if (steps.empty()) return;
  AppendAt(AppendTick(), steps, centres);
}

void WalkPattern::AppendAt(std::int64_t t, const std::vector<Footstep>& steps,
                           const std::vector<Pose2>& centres, int fast, std::int64_t ss, std::int64_t ds,
                           const Eigen::Vector2d& first_offset) {
  Cut(t);
  const bool from_stance = phases_.back().kind == Kind::kSingle;  // the weight on a foot, about to shift
  Pose2 last[2] = {rest_[0], rest_[1]};
  for (const Scheduled& s : steps_) last[static_cast<int>(s.step.side)] = s.step.pose;
  Eigen::Vector2d z = phases_.back().to;
  for (size_t i = 0; i < steps.size(); ++i) {
    Scheduled s;
    s.step = steps[i];
    s.planned = s.step.pose;
    s.centre = centres[i];
    const int sw = static_cast<int>(s.step.side);
    s.from = last[sw];
    s.stance = last[1 - sw];
    const Eigen::Vector2d p = ZmpPoint(s.stance) + (i == 0 ? first_offset : Eigen::Vector2d::Zero());
    const bool quick = static_cast<int>(i) < fast;
    if ((p - z).norm() > 1e-9) {
      AddPhase(i > 0 || from_stance ? (quick ? ds : ds_ticks_) : start_ticks_, p, Kind::kShift, sw);
    }
    s.start = phases_.back().end;
    s.land = s.start + (quick ? ss : ss_ticks_);
    AddPhase(s.land - s.start, p, Kind::kSingle, 1 - sw);
    steps_.push_back(s);
    last[sw] = s.step.pose;
    z = p;
  }
  const Scheduled& l = steps_.back();
  AddPhase(end_ticks_, 0.5 * (ZmpPoint(l.stance) + ZmpPoint(l.step.pose)), Kind::kEnd, -1);
}

// The step in the air lands; the next one (whose single support the preview
// already sees) becomes the step that brings its foot alongside, or, with the
// feet already side by side, a stand on its stance foot without a swing; then
// the shift back to the middle. The reference is unchanged until that step's
// end: at least single_support ahead (whatever the phase, a stop never
// changes what the preview already counts on sooner).
Pose2 WalkPattern::StopSoon() {
  Prune();
  size_t n = 0;
  while (n < steps_.size() && steps_[n].start <= tick_) ++n;
  if (n == steps_.size()) return final_centre();  // nothing ahead: the schedule already ends
  const Pose2 centre = n > 0 ? steps_[n - 1].centre : rest_centre_;
  Scheduled& st = steps_[n];
  const Pose2 along = FootAt(centre, st.step.side, g_);
  st.step.pose = st.planned = along;
  st.centre = centre;
  st.swing = !SamePose(st.from, along);
  const std::int64_t land = st.land;
  const Eigen::Vector2d mid = 0.5 * (ZmpPoint(st.stance) + ZmpPoint(along));
  Cut(land);
  AddPhase(end_ticks_, mid, Kind::kEnd, -1);
  return centre;
}

const Footstep* WalkPattern::lifting_next() const {
  for (const Scheduled& s : steps_) {
    if (s.start == tick_ + 1) return s.swing ? &s.step : nullptr;
  }
  return nullptr;
}

const Footstep* WalkPattern::landing_next() const {
  for (const Scheduled& s : steps_) {
    if (s.land == tick_ + 1) return s.swing ? &s.step : nullptr;
  }
  return nullptr;
}

bool WalkPattern::DelayLift(std::int64_t ticks) {
  return ticks > 0 && lifting_next() != nullptr && DelayFrom(tick_ + 1, ticks);
}

bool WalkPattern::DelayShift(std::int64_t ticks) {
  return ticks > 0 && landing_next() != nullptr && DelayFrom(tick_ + 1, ticks);
}

// Everything from the boundary `at` on (the phases from it, the steps that
// lift from it) `ticks` later; the reference holds its value at `at`
// meanwhile: the phase ending there lasts longer when it holds still (a
// single support, an earlier wait; a foot landing at `at` lands as late, its
// swing's last thousandths stretched), else a phase that holds still and whose
// next swing is the same (SpliceAt: the side is forced) comes in between.
bool WalkPattern::DelayFrom(std::int64_t at, std::int64_t ticks) {
  size_t j = 0;  // the first phase from `at` on
  while (j < phases_.size() && phases_[j].start < at) ++j;
  if (j == 0 || phases_[j - 1].end != at) return false;  // (no boundary there)
  for (size_t i = j; i < phases_.size(); ++i) {
    phases_[i].start += ticks;
    phases_[i].end += ticks;
  }
  for (Scheduled& s : steps_) {
    if (s.land == at) s.land += ticks;  // DelayShift: the foot ends its swing as late (at its landing)
    if (s.start < at) continue;
    s.start += ticks;
    s.land += ticks;
  }
  Phase& before = phases_[j - 1];
  if ((before.to - before.from).norm() < 1e-12) {
    before.end += ticks;
  } else {
    const Phase wait{.start = at,
                     .end = at + ticks,
                     .from = before.to,
                     .to = before.to,
                     .kind = before.kind,
                     .next = before.next};
    phases_.insert(phases_.begin() + static_cast<std::ptrdiff_t>(j), wait);
  }
  return true;
}

Eigen::Vector2d WalkPattern::AdjustLanding(const Eigen::Vector2d& offset, double reach) {
  size_t k = 0;
  while (k < steps_.size() && !(steps_[k].start <= tick_ && tick_ < steps_[k].land)) ++k;
  if (k == steps_.size() || !steps_[k].swing) return Eigen::Vector2d::Zero();
  Scheduled& st = steps_[k];
  // In the stance foot's frame: the landing stays on the swing foot's side,
  // no nearer to it sideways than planned (a foot moved inward narrows the
  // support and never crosses to catch a push toward the stance side), within `reach`.
  const Pose2& stance = st.stance;
  const double c = std::cos(stance.theta), s = std::sin(stance.theta);
  const Eigen::Vector2d want = st.planned.xy() + offset - stance.xy(), plan = st.planned.xy() - stance.xy();
  Eigen::Vector2d local(c * want.x() + s * want.y(), -s * want.x() + c * want.y());
  const double side = SideSign(st.step.side), planned_y = -s * plan.x() + c * plan.y();
  local.y() = side * std::max(side * local.y(), std::max(side * planned_y, 0.8 * g_.foot_separation));
  if (local.norm() > reach) local *= reach / local.norm();
  const Eigen::Vector2d land =
      stance.xy() + Eigen::Vector2d(c * local.x() - s * local.y(), s * local.x() + c * local.y());
  const Eigen::Vector2d old_z = ZmpPoint(st.step.pose);
  st.step.pose.x = land.x();
  st.step.pose.y = land.y();
  const Eigen::Vector2d new_z = ZmpPoint(st.step.pose), d = new_z - old_z;
  // The reference from the landing on: the foot's ZMP point, and the end
  // shift's middle when this step or the next one is the last.
  const Eigen::Vector2d mid_this = 0.5 * (old_z + ZmpPoint(st.stance));
  const Eigen::Vector2d mid_next =
      k + 1 < steps_.size() ? Eigen::Vector2d(0.5 * (old_z + ZmpPoint(steps_[k + 1].step.pose))) : mid_this;
  const auto moved = [&](const Eigen::Vector2d& p) -> Eigen::Vector2d {
    if ((p - old_z).norm() < 1e-9) return new_z;
    if ((p - mid_this).norm() < 1e-9 || (p - mid_next).norm() < 1e-9) return p + 0.5 * d;
    return p;
  };
  for (Phase& p : phases_) {
    if (p.start < st.land) continue;
    p.from = moved(p.from);
    p.to = moved(p.to);
  }
  if (k + 1 < steps_.size()) steps_[k + 1].stance = st.step.pose;
  if (k + 2 < steps_.size()) steps_[k + 2].from = st.step.pose;
  return st.step.pose.xy() - st.planned.xy();
}

const WalkPattern::Scheduled* WalkPattern::Swinging() const {
  for (const Scheduled& s : steps_) {
    if (s.start <= tick_ && tick_ < s.land) return &s;
  }
  return nullptr;
}

bool WalkPattern::standing() const {
  if (tick_ < phases_.back().end) return false;
  return std::none_of(steps_.begin(), steps_.end(), [&](const Scheduled& s) { return s.land > tick_; });
}

bool WalkPattern::settled(double tolerance) const {
  return standing() && (com() - zmp_ref()).norm() <= tolerance && com_velocity().norm() <= tolerance;
}

int WalkPattern::unstarted_steps() const {
  return static_cast<int>(
      std::count_if(steps_.begin(), steps_.end(), [&](const Scheduled& s) { return s.start > tick_; }));
}

double WalkPattern::planned_ahead() const {
  if (steps_.empty() || steps_.back().land <= tick_) return 0;
  return static_cast<double>(steps_.back().land - tick_) * tick_s_;
}

Side WalkPattern::support_side() const {
  const Scheduled* s = Swinging();
  return s ? Other(s->step.side) : Side::kLeft;
}

bool WalkPattern::double_support() const { return Swinging() == nullptr; }

Eigen::Vector2d WalkPattern::zmp() const {
  const double k = -g_.com_height / 9.81;  // only for the read-out; the preview uses its own g
  return {cx_(0) + k * cx_(2), cy_(0) + k * cy_(2)};
}

void WalkPattern::UpdateFeet() {
  foot_[0] = rest_[0];
  foot_[1] = rest_[1];
  height_[0] = height_[1] = 0;
  for (const Scheduled& st : steps_) {
    if (st.start > tick_) break;
    const int sw = static_cast<int>(st.step.side);
    if (tick_ >= st.land) {
      foot_[sw] = st.step.pose;
      continue;
    }
    if (!st.swing) continue;  // a stand on the stance foot (StopSoon)
    if (st.start == tick_) ++started_;
    const double s = SwingProgress(st);
    const double m = std::clamp((s - 0.1) / 0.8, 0.0, 1.0);
    foot_[sw] = Lerp(st.from, st.step.pose, 0.5 * (1 - std::cos(std::numbers::pi * m)));
    height_[sw] = g_.step_height * 0.5 * (1 - std::cos(2 * std::numbers::pi * s));
  }
}

void WalkPattern::Tick() {
  ++tick_;
  const std::int64_t phase = tick_ % every_;
  if (phase == 1 || every_ == 1) {  // a preview sample starts: its jerk holds for `every_` ticks
    const Eigen::Vector3d x0 = px_.state(), y0 = py_.state();
    const std::int64_t base = tick_ - 1;
    for (size_t j = 0; j < future_x_.size(); ++j) {
      const Eigen::Vector2d z = ZmpAt(base + static_cast<std::int64_t>(j + 1) * every_);
      future_x_[j] = z.x();
      future_y_[j] = z.y();
    }
    const Eigen::Vector2d now = ZmpAt(base);
    ux_ = px_.Step(now.x(), future_x_);
    uy_ = py_.Step(now.y(), future_y_);
    sample_x_ = x0;
    sample_y_ = y0;
  }
  const double t = static_cast<double>(phase == 0 ? every_ : phase) * tick_s_;
  cx_ = ZmpPreview::Propagate(sample_x_, ux_, t);
  cy_ = ZmpPreview::Propagate(sample_y_, uy_, t);
  UpdateFeet();
}

double WalkPattern::SwingProgress(const Scheduled& s) const {
  if (s.retimed < 0) return static_cast<double>(tick_ - s.start) / static_cast<double>(s.land - s.start);
  return s.s_retimed + (1 - s.s_retimed) * static_cast<double>(tick_ - s.retimed) /
                           static_cast<double>(std::max<std::int64_t>(1, s.land - s.retimed));
}

void WalkPattern::SetComState(const Eigen::Vector2d& com, const Eigen::Vector2d& com_vel) {
  // The acceleration that puts the model's ZMP at the reference now; the
  // preview sample in progress restarted so that the state is the CoM's now.
  const double w2 = gravity_ / g_.com_height;
  const Eigen::Vector2d p = ZmpAt(tick_);
  const Eigen::Vector3d sx(com.x(), com_vel.x(), w2 * (com.x() - p.x()));
  const Eigen::Vector3d sy(com.y(), com_vel.y(), w2 * (com.y() - p.y()));
  const std::int64_t phase = tick_ % every_ == 0 ? every_ : tick_ % every_;
  const double back = -static_cast<double>(phase) * tick_s_,
               ahead = static_cast<double>(every_ - phase) * tick_s_;
  sample_x_ = ZmpPreview::Propagate(sx, 0, back);
  sample_y_ = ZmpPreview::Propagate(sy, 0, back);
  px_.SetState(ZmpPreview::Propagate(sx, 0, ahead));
  py_.SetState(ZmpPreview::Propagate(sy, 0, ahead));
  ux_ = uy_ = 0;
  cx_ = sx;
  cy_ = sy;
}

double WalkPattern::time_to_landing() const {
  const Scheduled* s = Swinging();
  return s && s->swing ? static_cast<double>(s->land - tick_) * tick_s_ : 0.0;
}

int WalkPattern::SupportPolygon(std::array<Eigen::Vector2d, 16>& hull) const {
  if (const Scheduled* s = Swinging()) {
    const auto c = Corners(foot_[1 - static_cast<int>(s->step.side)], g_);
    std::copy(c.begin(), c.end(), hull.begin());
    return 4;
  }
  return HullOfSoles(foot_[0], foot_[1], g_, hull);
}

int HullOfSoles(const Pose2& fa, const Pose2& fb, const GaitParams& g,
                std::array<Eigen::Vector2d, 16>& hull) {
  // Monotone chain, counter-clockwise.
  std::array<Eigen::Vector2d, 8> pts;
  const auto a = Corners(fa, g), b = Corners(fb, g);
  std::copy(a.begin(), a.end(), pts.begin());
  std::copy(b.begin(), b.end(), pts.begin() + 4);
  std::sort(pts.begin(), pts.end(),
            [](const auto& u, const auto& v) { return u.x() < v.x() || (u.x() == v.x() && u.y() < v.y()); });
  int n = 0;
  for (int i = 0; i < 8; ++i) {
    while (n >= 2 && Cross(hull[n - 2], hull[n - 1], pts[i]) <= 0) --n;
    hull[n++] = pts[i];
  }
  for (int i = 6, lo = n + 1; i >= 0; --i) {
    while (n >= lo && Cross(hull[n - 2], hull[n - 1], pts[i]) <= 0) --n;
    hull[n++] = pts[i];
  }
  return n - 1;
}

bool WalkPattern::InSupport(const Eigen::Vector2d& p, double margin) const {
  std::array<Eigen::Vector2d, 16> hull;
  const int n = SupportPolygon(hull);
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector2d e = hull[(i + 1) % n] - hull[i];
    const double len = e.norm();
    if (len < 1e-12) continue;
    if (Cross(hull[i], hull[(i + 1) % n], p) / len < margin) return false;
  }
  return true;
}

}  // namespace robotalk::walking
