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

std::array<Eigen::Vector2d, 4> Corners(const Pose2& f, const GaitParams& g) {
  return {f.Apply(g.foot_front, g.foot_half_width), f.Apply(-g.foot_back, g.foot_half_width),
          f.Apply(-g.foot_back, -g.foot_half_width), f.Apply(g.foot_front, -g.foot_half_width)};
}

// R of the preview's cost (Qe = 1): 1e-5 tracks a 0.8 s weight shift seen
// 1 s ahead within 6 mm; Kajita's 1e-6 swings the ZMP harder for little gain.
constexpr double kJerkWeight = 1e-5;

bool SamePose(const Pose2& a, const Pose2& b) {
  return std::hypot(a.x - b.x, a.y - b.y) < 1e-6 && std::abs(Wrap(a.theta - b.theta)) < 1e-6;
}

}  // namespace

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
  Reset({}, Eigen::Vector2d::Zero());
}

void WalkPattern::Reset(const Pose2& centre, const Eigen::Vector2d& com) {
  steps_.clear();
  rest_[0] = foot_[0] = FootAt(centre, Side::kLeft, g_);
  rest_[1] = foot_[1] = FootAt(centre, Side::kRight, g_);
  height_[0] = height_[1] = 0;
  final_centre_ = centre;
  px_.Reset(com.x());
  py_.Reset(com.y());
  cx_ = px_.state();
  cy_ = py_.state();
  sample_x_ = cx_;
  sample_y_ = cy_;
  ux_ = uy_ = 0;
  walk_start_ = tick_;
}

Eigen::Vector2d WalkPattern::ZmpPoint(const Pose2& foot) const { return foot.Apply(g_.zmp_x, 0); }

std::int64_t WalkPattern::EndTick() const {
  return steps_.empty() ? walk_start_ : steps_.back().start + ss_ticks_ + end_ticks_;
}

int WalkPattern::StepAt(std::int64_t tick) const {
  if (steps_.empty() || tick < steps_.front().start) return -1;
  const auto k = (tick - steps_.front().start) / (ss_ticks_ + ds_ticks_);
  return static_cast<int>(std::min<std::int64_t>(k, static_cast<std::int64_t>(steps_.size()) - 1));
}

Eigen::Vector2d WalkPattern::ZmpAt(std::int64_t tick) const {
  const Eigen::Vector2d mid0 = 0.5 * (ZmpPoint(rest_[0]) + ZmpPoint(rest_[1]));
  if (steps_.empty() || tick <= walk_start_) return mid0;
  const int k = StepAt(tick);
  if (k < 0) {  // the first shift of weight onto the first stance foot
    const double s = static_cast<double>(tick - walk_start_) / static_cast<double>(start_ticks_);
    return mid0 + std::min(1.0, s) * (ZmpPoint(steps_.front().stance) - mid0);
  }
  const Scheduled& st = steps_[static_cast<size_t>(k)];
  const Eigen::Vector2d stance = ZmpPoint(st.stance);
  const std::int64_t local = tick - st.start;
  if (local < ss_ticks_) return stance;
  const Eigen::Vector2d landed = ZmpPoint(st.step.pose);
  if (k + 1 < static_cast<int>(steps_.size())) {
    const double s = static_cast<double>(local - ss_ticks_) / static_cast<double>(ds_ticks_);
    return stance + std::min(1.0, s) * (landed - stance);
  }
  const double s = static_cast<double>(local - ss_ticks_) / static_cast<double>(end_ticks_);
  return stance + std::min(1.0, s) * (0.5 * (stance + landed) - stance);
}

void WalkPattern::Append(const std::vector<Footstep>& steps, const std::vector<Pose2>& centres) {
  if (steps.empty()) return;
  // In the last step's double support the schedule goes on (the next step
  // starts where it would have); later, in the end shift or standing, the
  // walk starts again from the feet as they are.
  const bool restart = steps_.empty() || tick_ >= steps_.back().start + ss_ticks_ + ds_ticks_;
  if (restart) {
    rest_[0] = foot_[0];
    rest_[1] = foot_[1];
    steps_.clear();
    walk_start_ = tick_ + lead_ticks_;  // the preview needs to see a start ahead
  }
  Pose2 last[2] = {rest_[0], rest_[1]};
  for (const Scheduled& s : steps_) last[static_cast<int>(s.step.side)] = s.step.pose;
  for (size_t i = 0; i < steps.size(); ++i) {
    Scheduled s;
    s.step = steps[i];
    s.centre = centres[i];
    s.from = last[static_cast<int>(s.step.side)];
    s.stance = last[static_cast<int>(Other(s.step.side))];
    s.start = steps_.empty() ? walk_start_ + start_ticks_ : steps_.back().start + ss_ticks_ + ds_ticks_;
    steps_.push_back(s);
    last[static_cast<int>(s.step.side)] = s.step.pose;
  }
  final_centre_ = steps_.back().centre;
}

void WalkPattern::Reschedule(size_t keep) {
  steps_.resize(keep);
  if (!steps_.empty()) final_centre_ = steps_.back().centre;
}

Pose2 WalkPattern::DropUnstarted(Side* next_swing) {
  size_t keep = 0;
  while (keep < steps_.size() && steps_[keep].start <= tick_) ++keep;
  Reschedule(keep);
  if (steps_.empty()) {
    // No step has started: the stance is the rest one.
    final_centre_ = {0.5 * (rest_[0].x + rest_[1].x), 0.5 * (rest_[0].y + rest_[1].y),
                     Wrap(rest_[1].theta + 0.5 * Wrap(rest_[0].theta - rest_[1].theta))};
    const Eigen::Vector2d back = final_centre_.Apply(-g_.ankle_x, 0) - final_centre_.xy();
    final_centre_.x += back.x();
    final_centre_.y += back.y();
    if (next_swing) *next_swing = Side::kLeft;
    return final_centre_;
  }
  if (next_swing) *next_swing = Other(steps_.back().step.side);
  return final_centre_;
}

Pose2 WalkPattern::StopSoon() {
  Side next = Side::kLeft;
  const Pose2 centre = DropUnstarted(&next);
  if (steps_.empty()) {
    rest_[0] = foot_[0];
    rest_[1] = foot_[1];
    walk_start_ = tick_;
    return centre;
  }
  const Scheduled& last = steps_.back();
  const Pose2 along = FootAt(centre, next, g_);
  if (!SamePose(last.stance, along)) Append({Footstep{next, along}}, {centre});
  return centre;
}

bool WalkPattern::standing() const { return steps_.empty() || tick_ >= EndTick(); }

bool WalkPattern::settled(double tolerance) const {
  return standing() && (com() - zmp_ref()).norm() <= tolerance && com_velocity().norm() <= tolerance;
}

int WalkPattern::unstarted_steps() const {
  int n = 0;
  for (auto it = steps_.rbegin(); it != steps_.rend() && it->start > tick_; ++it) ++n;
  return n;
}

double WalkPattern::time_to_end() const {
  return standing() ? 0.0 : static_cast<double>(EndTick() - tick_) * tick_s_;
}

Side WalkPattern::support_side() const {
  if (double_support()) return Side::kLeft;
  return Other(steps_[static_cast<size_t>(StepAt(tick_))].step.side);
}

bool WalkPattern::double_support() const {
  const int k = StepAt(tick_);
  return k < 0 || tick_ - steps_[static_cast<size_t>(k)].start >= ss_ticks_;
}

Eigen::Vector2d WalkPattern::zmp() const {
  const double k = -g_.com_height / 9.81;  // only for the read-out; the preview uses its own g
  return {cx_(0) + k * cx_(2), cy_(0) + k * cy_(2)};
}

void WalkPattern::UpdateFeet() {
  const int k = StepAt(tick_);
  height_[0] = height_[1] = 0;
  if (k < 0) {
    foot_[0] = rest_[0];
    foot_[1] = rest_[1];
    return;
  }
  const Scheduled& st = steps_[static_cast<size_t>(k)];
  const int sw = static_cast<int>(st.step.side);
  foot_[1 - sw] = st.stance;
  const double s =
      std::clamp(static_cast<double>(tick_ - st.start) / static_cast<double>(ss_ticks_), 0.0, 1.0);
  const double m = std::clamp((s - 0.1) / 0.8, 0.0, 1.0);
  foot_[sw] = Lerp(st.from, st.step.pose, 0.5 * (1 - std::cos(std::numbers::pi * m)));
  height_[sw] = g_.step_height * 0.5 * (1 - std::cos(2 * std::numbers::pi * s));
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
  const int k = StepAt(tick_);
  if (k >= 0 && steps_[static_cast<size_t>(k)].start == tick_) ++started_;
  UpdateFeet();
}

bool WalkPattern::InSupport(const Eigen::Vector2d& p, double margin) const {
  const int k = StepAt(tick_);
  if (k >= 0 && !double_support()) {
    return InFoot(foot_[1 - static_cast<int>(steps_[static_cast<size_t>(k)].step.side)], g_, p, margin);
  }
  // Convex hull of both soles (monotone chain), then the point against each edge.
  std::array<Eigen::Vector2d, 8> pts;
  const auto a = Corners(foot_[0], g_), b = Corners(foot_[1], g_);
  std::copy(a.begin(), a.end(), pts.begin());
  std::copy(b.begin(), b.end(), pts.begin() + 4);
  std::sort(pts.begin(), pts.end(),
            [](const auto& u, const auto& v) { return u.x() < v.x() || (u.x() == v.x() && u.y() < v.y()); });
  std::array<Eigen::Vector2d, 16> hull;
  int n = 0;
  for (int i = 0; i < 8; ++i) {
    while (n >= 2 && Cross(hull[n - 2], hull[n - 1], pts[i]) <= 0) --n;
    hull[n++] = pts[i];
  }
  for (int i = 6, lo = n + 1; i >= 0; --i) {
    while (n >= lo && Cross(hull[n - 2], hull[n - 1], pts[i]) <= 0) --n;
    hull[n++] = pts[i];
  }
  --n;
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector2d e = hull[(i + 1) % n] - hull[i];
    const double len = e.norm();
    if (len < 1e-12) continue;
    if (Cross(hull[i], hull[(i + 1) % n], p) / len < margin) return false;
  }
  return true;
}

}  // namespace robotalk::walking
