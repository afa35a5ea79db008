#include "walking/hip_strategy.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace robotalk::walking {

HipStrategy::HipStrategy(double tick, HipStrategyParams params) : tick_(tick), p_(params) {
  const double positive[] = {tick,     p_.trigger, p_.gain,       p_.max_lean, p_.accel,
                             p_.brake, p_.rate,    p_.back_accel, p_.back_rate};
  for (double v : positive) {
    if (!(v > 0)) throw std::invalid_argument("HipStrategy: tick and every gain and bound must be > 0");
  }
  if (!(p_.hold >= 0)) throw std::invalid_argument("HipStrategy: hold must be >= 0");
}

void HipStrategy::Track(double to, double accel, double brake, double rate) {
  // The speed from which braking at `brake` still stops at `to` after this
  // tick's move (v^2 = 2 brake (|e| - v dt): no overshoot in discrete time),
  // bounded by `rate`; speeding up at most `accel`, slowing down at most `brake`.
  const double e = to - angle_;
  if (std::abs(e) <= brake * tick_ * tick_ && std::abs(rate_) <= brake * tick_) {
    angle_ = to;  // within a tick's braking: there
    rate_ = 0;
    return;
  }
  const double bt = brake * tick_;
  const double want = std::copysign(std::min(rate, std::sqrt(bt * bt + 2 * brake * std::abs(e)) - bt), e);
  const double limit = std::abs(want) > std::abs(rate_) && want * rate_ >= 0 ? accel : brake;
  rate_ += std::clamp((want - rate_) / tick_, -limit, limit) * tick_;
  angle_ += rate_ * tick_;
}

const Eigen::Vector2d& HipStrategy::Update(const Eigen::Vector2d& impulse) {
  const double j = impulse.norm();
  if (phase_ == Phase::kIdle && j > p_.trigger) {
    phase_ = Phase::kLean;
    dir_ = impulse / j;
    target_ = peak_ = 0;
    ++leans_;
  }
  constexpr double kReached = 1e-3;  // rad, rad/s
  constexpr double kPast = 0.9;      // of the impulse's peak: the push is over
  switch (phase_) {
    case Phase::kIdle:
      break;
    case Phase::kLean: {
      // The target grows with the impulse while the push lasts (its direction is the trigger's);
      // the lean holds once reached and the impulse is past its peak.
      const double along = impulse.dot(dir_);
      peak_ = std::max(peak_, along);
      target_ = std::min(p_.max_lean, p_.gain * peak_);
      Track(target_, p_.accel, p_.brake, p_.rate);
      if (std::abs(angle_ - target_) < kReached && std::abs(rate_) < kReached && along < kPast * peak_) {
        phase_ = Phase::kHold;
        held_ = 0;
      }
      break;
    }
    case Phase::kHold:
      held_ += tick_;
      if (held_ >= p_.hold - 1e-12) phase_ = Phase::kBack;
      break;
    case Phase::kBack:
      Track(0, p_.back_accel, p_.back_accel, p_.back_rate);
      if (std::abs(angle_) < kReached && std::abs(rate_) < kReached) {
        phase_ = Phase::kIdle;
        angle_ = rate_ = 0;
      }
      break;
  }
  lean_ = angle_ * dir_;
  return lean_;
}

}  // namespace robotalk::walking
