// The CoM state and DCM estimated from the kinematic CoM and the measured
// centre of pressure (issue 26, item 4; docs/ode_sim.md, "Pushes and
// disturbances"). Pure maths, no ODE; tests/drivers/dcm_estimator_test.cpp
// pushes a noisy linear inverted pendulum.
//
// Why: the CoM's velocity differenced from the kinematic CoM (and low-passed
// over 10 ms) makes a DCM xi = c + c'/w that is noisy by +-3 cm on ODE, which
// the push recovery's footholds amplify e^{wT} (x15 in double support).
// Here a Kalman filter per horizontal axis on x = (c, c', d) predicts with the
// linear inverted pendulum, c'' = w^2 (c - p) + d, p the MEASURED centre of
// pressure (the contact forces), d an unmodelled acceleration (a push, the
// kinematic CoM's offset w^2 b, the angular momentum the LIPM ignores; a
// random walk), and corrects with the kinematic CoM. The velocity then comes
// from the forces that make it, not from differencing a position; a push
// shows in the innovation and d follows it at the rate `force_noise` allows.
//
// Threading: one thread. Allocation: none.
#pragma once

#include <Eigen/Core>

namespace robotalk::walking {

struct DcmEstimatorParams {
  double com_noise = 0.0005;     ///< m: standard deviation of the kinematic CoM (the measurement)
  double accel_noise = 0.05;     ///< m/s^2/sqrt(Hz): white acceleration the model does not see
  double force_noise = 5;        ///< m/s^3/sqrt(Hz): how fast d (a push, per unit mass) may change
  double impulse_window = 0.15;  ///< s: impulse() forgets d over this time constant
};

class DcmEstimator {
 public:
  /// omega = sqrt(g / z_c) > 0, tick > 0 (s), the noises > 0, else std::invalid_argument.
  DcmEstimator(double omega, double tick, DcmEstimatorParams params = {});
  /// Starts from a CoM at rest at `com`.
  void Reset(const Eigen::Vector2d& com);
  /// One tick: predict with the pendulum on the measured centre of pressure
  /// `cop` (nullptr: no contact, the CoM's velocity is kept), then correct
  /// with the kinematic CoM `com`. The first call resets to `com`.
  void Update(const Eigen::Vector2d& com, const Eigen::Vector2d* cop);
  const Eigen::Vector2d& com() const { return c_; }
  const Eigen::Vector2d& com_velocity() const { return v_; }
  /// The unmodelled acceleration d (m/s^2): a push's force per unit mass.
  const Eigen::Vector2d& disturbance() const { return d_; }
  /// d integrated over the last `impulse_window` s (leaky, m/s): the change
  /// of speed a push made. On ODE (walking at 0.29 m/s, unpushed) it stays
  /// below 0.084 m/s; 0.1 s pushes of 10-20 N*s reach 0.12-0.25 m/s.
  const Eigen::Vector2d& impulse() const { return impulse_; }
  Eigen::Vector2d dcm() const { return c_ + v_ / omega_; }

 private:
  double omega_, tick_;
  DcmEstimatorParams p_;
  bool started_ = false;
  Eigen::Vector2d c_ = Eigen::Vector2d::Zero(), v_ = Eigen::Vector2d::Zero(), d_ = Eigen::Vector2d::Zero();
  Eigen::Vector2d impulse_ = Eigen::Vector2d::Zero();
  Eigen::Matrix3d cov_ = Eigen::Matrix3d::Zero();  // the same on both axes (same model, same noises)
};

}  // namespace robotalk::walking
