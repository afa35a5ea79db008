#include "walking/dcm_estimator.h"

#include <stdexcept>

namespace robotalk::walking {

DcmEstimator::DcmEstimator(double omega, double tick, DcmEstimatorParams params)
    : omega_(omega), tick_(tick), p_(params) {
  if (!(omega > 0)) throw std::invalid_argument("DcmEstimator: omega must be > 0");
  if (!(tick > 0)) throw std::invalid_argument("DcmEstimator: tick must be > 0 s");
  if (!(p_.com_noise > 0)) throw std::invalid_argument("DcmEstimator: com_noise must be > 0 m");
  if (!(p_.accel_noise > 0))
    throw std::invalid_argument("DcmEstimator: accel_noise must be > 0 m/s^2/sqrt(Hz)");
  if (!(p_.force_noise > 0))
    throw std::invalid_argument("DcmEstimator: force_noise must be > 0 m/s^3/sqrt(Hz)");
  if (!(p_.impulse_window > 0)) throw std::invalid_argument("DcmEstimator: impulse_window must be > 0 s");
}

void DcmEstimator::Reset(const Eigen::Vector2d& com) {
  c_ = com;
  v_.setZero();
  d_.setZero();
  impulse_.setZero();
  const double r = p_.com_noise * p_.com_noise;
  cov_ = Eigen::Vector3d(r, 0.01 * r * omega_ * omega_, 0.01 * r * omega_ * omega_ * omega_ * omega_)
             .asDiagonal();
  started_ = true;
}

void DcmEstimator::Update(const Eigen::Vector2d& com, const Eigen::Vector2d* cop) {
  if (!started_) {
    Reset(com);
    return;
  }
  const double dt = tick_, k = cop ? omega_ * omega_ : 0.0;
  // Predict: the pendulum on the measured CoP held over the tick (without
  // contact no ground force), plus d.
  const Eigen::Vector2d a = (cop ? Eigen::Vector2d(k * (c_ - *cop)) : Eigen::Vector2d::Zero()) + d_;
  c_ += v_ * dt + 0.5 * a * dt * dt;
  v_ += a * dt;
  Eigen::Matrix3d f;
  f << 1 + 0.5 * k * dt * dt, dt, 0.5 * dt * dt, k * dt, 1, dt, 0, 0, 1;
  const double qa = p_.accel_noise * p_.accel_noise, qd = p_.force_noise * p_.force_noise;
  Eigen::Matrix3d q = Eigen::Matrix3d::Zero();
  q(1, 1) = qa * dt;
  q(2, 2) = qd * dt;
  cov_ = f * cov_ * f.transpose() + q;
  // Correct with the kinematic CoM.
  const double s = cov_(0, 0) + p_.com_noise * p_.com_noise;
  const Eigen::Vector3d gain = cov_.col(0) / s;
  const Eigen::Vector2d innovation = com - c_;
  c_ += gain.x() * innovation;
  v_ += gain.y() * innovation;
  d_ += gain.z() * innovation;
  cov_ -= (gain * cov_.row(0)).eval();
  impulse_ += (d_ - impulse_ / p_.impulse_window) * dt;
}

}  // namespace robotalk::walking
