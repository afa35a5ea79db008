// Pure maths of the ode driver's planar bases (private): the closed-loop GOTO
// controller. No ODE, no I/O.
#pragma once

#include "robotalk/driver_support.h"

#include <cstdint>

namespace robotalk::ode_detail {

/// A planar body twist command.
struct Twist2 {
  double v = 0;      ///< forward speed, m/s
  double omega = 0;  ///< yaw rate, rad/s
};

/// Turn-drive-turn GOTO on a measured pose, with proportional gains:
/// turn toward the goal (|heading error| > kDriveCone), drive with the speed
/// proportional to the distance while steering, then turn to the goal heading
/// once within `tolerance` (and stay there unless pushed beyond 3 x tolerance).
class GotoController {
 public:
  struct Gains {
    double k_v = 1.5;                 ///< 1/s: forward speed per metre of distance
    double k_omega = 3.0;             ///< 1/s: yaw rate per radian of heading error
    double max_v = 0.7;               ///< m/s
    double max_omega = 2.0;           ///< rad/s
    double tolerance = 0.02;          ///< m
    double heading_tolerance = 0.02;  ///< rad
  };
  static constexpr double kTurnCone = 0.6;   ///< rad: drive only when the goal is this close to ahead
  static constexpr double kDriveCone = 0.1;  ///< rad: start driving once aligned this well

  void Start(double x, double y, double theta, const Gains& gains);
  /// The command for the measured pose; sets done() when within tolerance.
  Twist2 Update(double x, double y, double theta);
  bool done() const { return done_; }

 private:
  enum class Phase : std::uint8_t { kTurn, kDrive, kFinalTurn };
  Gains g_;
  double gx_ = 0, gy_ = 0, gtheta_ = 0;
  Phase phase_ = Phase::kTurn;
  bool done_ = false;
};

/// Angle wrapped into (-pi, pi]: the project's one WrapAngle.
using driver_support::WrapAngle;

}  // namespace robotalk::ode_detail
