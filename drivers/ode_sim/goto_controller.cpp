#include "goto_controller.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace robotalk::ode_detail {

void GotoController::Start(double x, double y, double theta, const Gains& gains) {
  g_ = gains;
  gx_ = x;
  gy_ = y;
  gtheta_ = WrapAngle(theta);
  phase_ = Phase::kTurn;
  done_ = false;
}

Twist2 GotoController::Update(double x, double y, double theta) {
  const double dx = gx_ - x, dy = gy_ - y;
  const double dist = std::hypot(dx, dy);
  const double final_error = WrapAngle(gtheta_ - theta);
  if (dist <= g_.tolerance) phase_ = Phase::kFinalTurn;
  if (phase_ == Phase::kFinalTurn && dist > 3 * g_.tolerance) phase_ = Phase::kTurn;
  if (phase_ == Phase::kFinalTurn && std::abs(final_error) <= g_.heading_tolerance) {
    done_ = true;
    return {};
  }
  const double bearing_error = WrapAngle(std::atan2(dy, dx) - theta);
  if (phase_ == Phase::kDrive && std::abs(bearing_error) > kTurnCone) phase_ = Phase::kTurn;
  if (phase_ == Phase::kTurn && std::abs(bearing_error) <= kDriveCone) phase_ = Phase::kDrive;
  Twist2 t;
  switch (phase_) {
    case Phase::kTurn:
      t.omega = g_.k_omega * bearing_error;
      break;
    case Phase::kDrive:
      t.v = std::min(g_.max_v, g_.k_v * dist) * std::max(0.0, std::cos(bearing_error));
      t.omega = g_.k_omega * bearing_error;
      break;
    case Phase::kFinalTurn:
      t.omega = g_.k_omega * final_error;
      break;
  }
  t.omega = std::clamp(t.omega, -g_.max_omega, g_.max_omega);
  return t;
}

}  // namespace robotalk::ode_detail
