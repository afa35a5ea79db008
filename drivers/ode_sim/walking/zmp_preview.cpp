// ZMP preview control: see zmp_preview.h. The gain formulas follow Kajita's
// formulation with the augmented state [integral of e; x].
#include "walking/zmp_preview.h"

#include <Eigen/Dense>

#include <cmath>
#include <stdexcept>
#include <string>

namespace robotalk::walking {

ZmpPreview::ZmpPreview(double dt, double zc, double gravity, double horizon, double qe, double r) : dt_(dt) {
  if (!(dt > 0) || !(zc > 0) || !(gravity > 0) || !(horizon > dt) || !(qe > 0) || !(r > 0)) {
    throw std::invalid_argument(
        "ZmpPreview: dt, zc, gravity, horizon, qe and r must be > 0 (horizon > dt); got dt=" +
        std::to_string(dt) + " zc=" + std::to_string(zc) + " horizon=" + std::to_string(horizon));
  }
  a_ << 1, dt, dt * dt / 2, 0, 1, dt, 0, 0, 1;
  b_ << dt * dt * dt / 6, dt * dt / 2, dt;
  c_ << 1, 0, -zc / gravity;
  using M4 = Eigen::Matrix4d;
  using V4 = Eigen::Vector4d;
  M4 at = M4::Zero();
  at(0, 0) = 1;
  at.block<1, 3>(0, 1) = c_.transpose() * a_;
  at.block<3, 3>(1, 1) = a_;
  V4 bt;
  bt << c_.dot(b_), b_;
  V4 it = V4::Zero();
  it(0) = 1;
  Eigen::Matrix<double, 4, 3> ft;
  ft.row(0) = c_.transpose() * a_;
  ft.block<3, 3>(1, 0) = a_;
  M4 q = M4::Zero();
  q(0, 0) = qe;
  M4 p = q;
  for (int i = 0; i < 100000; ++i) {
    const double s = r + bt.dot(p * bt);
    const M4 next = at.transpose() * p * at + q - (at.transpose() * p * bt) * (bt.transpose() * p * at) / s;
    const double change = (next - p).cwiseAbs().maxCoeff();
    p = next;
    if (change < 1e-12 * p.cwiseAbs().maxCoeff()) break;
  }
  const double s = r + bt.dot(p * bt);
  gi_ = bt.dot(p * it) / s;
  gx_ = (bt.transpose() * p * ft) / s;
  const M4 ac = at - bt * (bt.transpose() * p * at) / s;
  const int n = static_cast<int>(std::lround(horizon / dt));
  gd_.resize(static_cast<size_t>(n));
  gd_[0] = -gi_;
  V4 xv = -ac.transpose() * p * it;
  for (int j = 1; j < n; ++j) {
    gd_[static_cast<size_t>(j)] = bt.dot(xv) / s;
    xv = ac.transpose() * xv;
  }
}

void ZmpPreview::Reset(double c) {
  x_ = {c, 0, 0};
  sum_e_ = 0;
}

void ZmpPreview::SetState(const Eigen::Vector3d& x) {
  x_ = x;
  sum_e_ = 0;
}

double ZmpPreview::Step(double now, std::span<const double> future) {
  sum_e_ += zmp() - now;
  double u = -gi_ * sum_e_ - gx_.dot(x_);
  const size_t n = std::min(future.size(), gd_.size());
  for (size_t j = 0; j < n; ++j) u -= gd_[j] * future[j];
  x_ = a_ * x_ + b_ * u;
  return u;
}

Eigen::Vector3d ZmpPreview::Propagate(const Eigen::Vector3d& x, double u, double t) {
  return {x(0) + t * x(1) + t * t / 2 * x(2) + t * t * t / 6 * u, x(1) + t * x(2) + t * t / 2 * u,
          x(2) + t * u};
}

}  // namespace robotalk::walking
