// The ode driver's joint servos: see joint_servos.h.
#include "joint_servos.h"

#include <algorithm>
#include <cmath>

namespace robotalk::ode_detail {

JointServos::JointServos(const RobotModel& model, const OdeDriverOptions& options)
    : table_(model), kp_(options.kp), step_(1.0 / options.step_hz), horizon_(ToSeconds(options.period)) {
  const int n = model.num_dofs();
  vmax_ =
      table_.velocity.unaryExpr([&](double v) { return std::isfinite(v) ? v : options.default_velocity; });
  fmax_ = table_.effort.unaryExpr([&](double f) { return std::isfinite(f) ? f : options.default_effort; });
  mode_.assign(static_cast<std::size_t>(n), Mode::kPosition);
  settled_.assign(static_cast<std::size_t>(n), 0);
  away_.assign(static_cast<std::size_t>(n), 0);
  bounce_steps_ = std::max(1, static_cast<int>(std::lround(kBounce / step_)));
  for (int i = 0; i < n; ++i) {
    if (table_.is_mimic(i)) {
      mode_[static_cast<std::size_t>(i)] = Mode::kMimic;
    } else if (model.joint(table_.joint_of[static_cast<std::size_t>(i)]).servo_types.empty()) {
      mode_[static_cast<std::size_t>(i)] = Mode::kPassive;
    }
  }
  q0_ = table_.lower.cwiseMax(0.0).cwiseMin(table_.upper);
  ApplyMimics(model, q0_);
  target_ = q0_;
  speed_.setZero(n);
  force_.setZero(n);
  ref_accel_.setZero(n);
  ref_age_.setZero(n);
}

void JointServos::Reference(Eigen::Index i, double p, double v, double a) {
  mode_[static_cast<std::size_t>(i)] = Mode::kReference;
  settled_[static_cast<std::size_t>(i)] = 0;
  target_[i] = p;
  speed_[i] = v;
  ref_accel_[i] = a;
  ref_age_[i] = 0;
  force_[i] = 0;
}

void JointServos::SetPoint(Eigen::Index i, double q) {
  mode_[static_cast<std::size_t>(i)] = Mode::kPosition;
  settled_[static_cast<std::size_t>(i)] = 0;
  target_[i] = q;
  speed_[i] = 0;
  force_[i] = 0;
}

void JointServos::Speed(Eigen::Index i, double v) {
  mode_[static_cast<std::size_t>(i)] = Mode::kVelocity;
  settled_[static_cast<std::size_t>(i)] = 0;
  speed_[i] = v;
}

void JointServos::Force(Eigen::Index i, double f) {
  mode_[static_cast<std::size_t>(i)] = Mode::kForce;
  force_[i] = f;
}

void JointServos::Hold(Eigen::Index i, OdeWorld& world) {
  const Mode m = mode_[static_cast<std::size_t>(i)];
  if (m == Mode::kMimic || m == Mode::kPassive || m == Mode::kBase) return;
  mode_[static_cast<std::size_t>(i)] = Mode::kVelocity;
  settled_[static_cast<std::size_t>(i)] = 0;
  target_[i] = std::clamp(world.q()[i], table_.lower[i], table_.upper[i]);
  speed_[i] = 0;
  force_[i] = 0;
  world.SetMotor(static_cast<int>(i), 0, fmax_[i]);
}

void JointServos::Apply(OdeWorld& world) {
  const Eigen::VectorXd& q = world.q();
  const Eigen::VectorXd& qd = world.qd();
  for (Eigen::Index i = 0; i < q.size(); ++i) {
    const auto u = static_cast<std::size_t>(i);
    if (mode_[u] == Mode::kVelocity &&
        ((q[i] >= table_.upper[i] && speed_[i] > 0) || (q[i] <= table_.lower[i] && speed_[i] < 0))) {
      SetPoint(i, std::clamp(q[i], table_.lower[i],
                             table_.upper[i]));  // a speed command stops and holds at a limit
    }
    // A set-point is reached within kTargetReached (a joint on its stop
    // bounces faster than kMovingSpeed); a hold when the joint is at rest.
    if (!settled_[u] && mode_[u] == Mode::kPosition && std::abs(target_[i] - q[i]) <= kTargetReached)
      settled_[u] = 1;
    // A settled dof off its target: counted, so that a bounce (a step or two) is not a move.
    away_[u] = settled_[u] && std::abs(target_[i] - q[i]) > kTargetReached
                   ? static_cast<std::uint16_t>(std::min<int>(away_[u] + 1, 60000))
                   : std::uint16_t{0};
    if (!settled_[u] && std::abs(qd[i]) <= kMovingSpeed) {
      if (mode_[u] == Mode::kVelocity && speed_[i] == 0) {
        target_[i] = std::clamp(q[i], table_.lower[i], table_.upper[i]);  // where it came to rest
        settled_[u] = 1;
      }
    }
    switch (mode_[u]) {
      case Mode::kPosition:
        world.SetMotor(static_cast<int>(i), std::clamp(kp_ * (target_[i] - q[i]), -vmax_[i], vmax_[i]),
                       fmax_[i]);
        break;
      case Mode::kVelocity:
        world.SetMotor(static_cast<int>(i), speed_[i], fmax_[i]);
        break;
      case Mode::kReference: {
        // The reference at this step and its velocity at mid-step (exact for
        // a constant acceleration), advanced at most one control period.
        const double age = std::min(ref_age_[i], horizon_);
        const double mid = std::min(ref_age_[i] + step_ / 2, horizon_);
        const double p = target_[i] + speed_[i] * age + 0.5 * ref_accel_[i] * age * age;
        const double v = ref_age_[i] + step_ / 2 <= horizon_ ? speed_[i] + ref_accel_[i] * mid : 0.0;
        const double want = std::clamp(p, table_.lower[i], table_.upper[i]);
        world.SetMotor(static_cast<int>(i), std::clamp(v + kp_ * (want - q[i]), -vmax_[i], vmax_[i]),
                       fmax_[i]);
        ref_age_[i] += step_;
        break;
      }
      case Mode::kForce:
        world.SetEffort(static_cast<int>(i), force_[i]);
        break;
      case Mode::kPassive:
        world.SetMotor(static_cast<int>(i), 0, 0);
        break;
      case Mode::kMimic: {
        const auto l = static_cast<Eigen::Index>(table_.mimic_leader[u]);
        const double k = table_.mimic_multiplier[u];
        const double want = k * q[l] + table_.mimic_offset[u];
        world.SetMotor(static_cast<int>(i), std::clamp(k * qd[l] + kp_ * (want - q[i]), -vmax_[i], vmax_[i]),
                       fmax_[i]);
        break;
      }
      case Mode::kBase:
        break;
    }
  }
}

bool JointServos::Moving(const Eigen::VectorXd& q, const Eigen::VectorXd& qd) const {
  for (Eigen::Index i = 0; i < q.size(); ++i) {
    switch (mode_[static_cast<std::size_t>(i)]) {
      case Mode::kPosition:
        if (!settled_[static_cast<std::size_t>(i)] || Away(i)) return true;
        break;
      case Mode::kVelocity:
        if (speed_[i] != 0 || !settled_[static_cast<std::size_t>(i)] || Away(i)) return true;
        break;
      case Mode::kReference:
        if (speed_[i] != 0 || std::abs(target_[i] - q[i]) > kTargetReached || std::abs(qd[i]) > kMovingSpeed)
          return true;
        break;
      case Mode::kForce:
        if (force_[i] != 0) return true;
        break;
      case Mode::kPassive:
      case Mode::kMimic:
      case Mode::kBase:
        break;
    }
  }
  return false;
}

}  // namespace robotalk::ode_detail
