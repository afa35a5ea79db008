// ZMP preview control (Kajita et al., "Biped walking pattern generation by
// using preview control of zero-moment point", ICRA 2003), one horizontal
// axis. The centre of mass moves as a cart on a table (linear inverted
// pendulum at height zc):
//   x = [c, c', c''],  x(k+1) = A x(k) + B u(k),  u = jerk,
//   p = c - (zc/g) c''  (the ZMP),
// and the jerk minimises sum Qe e^2 + R u^2 over an infinite horizon with
// the ZMP reference known `horizon` ahead (the integral-action form):
//   u(k) = -Gi sum_{i<=k} e(i) - Gx x(k) - sum_{j=1..N} Gd(j) p_ref(k+j).
// The gains come from the discrete algebraic Riccati equation, solved by
// iteration in the constructor.
//
// Units: m, s. Thread safety: const methods are safe; Step() writes the
// state. Allocation: gains in the constructor only.
#pragma once

#include <Eigen/Core>

#include <span>
#include <vector>

namespace robotalk::walking {

class ZmpPreview {
 public:
  /// dt: sample time (s, > 0); zc: CoM height (m); horizon: preview time (s).
  /// Throws std::invalid_argument for a non-positive argument.
  ZmpPreview(double dt, double zc, double gravity, double horizon, double qe = 1.0, double r = 1e-6);

  /// Preview samples N = round(horizon / dt): Step() reads N future references.
  int horizon_samples() const { return static_cast<int>(gd_.size()); }
  double dt() const { return dt_; }

  /// Resets the state to rest at position c (ZMP = c, no error integral).
  void Reset(double c);
  /// Sets the state [c, c', c''] (a measured one: the walking pattern
  /// regenerated after a push), with no error integral.
  void SetState(const Eigen::Vector3d& x);
  /// One sample: `future` holds p_ref(k+1) .. p_ref(k+N) (size N), `now` p_ref(k).
  /// Returns the jerk applied; the state moves on by dt.
  double Step(double now, std::span<const double> future);
  /// The state [c, c', c''] and its ZMP.
  const Eigen::Vector3d& state() const { return x_; }
  double zmp() const { return c_.dot(x_); }
  /// The state after `t` (0 <= t) under constant jerk u from x.
  static Eigen::Vector3d Propagate(const Eigen::Vector3d& x, double u, double t);

 private:
  double dt_;
  Eigen::Matrix3d a_;
  Eigen::Vector3d b_, c_;
  double gi_ = 0;
  Eigen::RowVector3d gx_;
  std::vector<double> gd_;
  Eigen::Vector3d x_ = Eigen::Vector3d::Zero();
  double sum_e_ = 0;
};

}  // namespace robotalk::walking
