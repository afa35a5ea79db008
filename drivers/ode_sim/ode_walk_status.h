// What the ode driver's walking controller reports (OdeDriver::walk_status()):
// for tests, the benchmark and the plots. Plain data, installed beside
// ode_driver.h; the walking controller's own types (walking/) are private.
//
// Conventions: world frame, z up, metres, radians.
#pragma once

#include <Eigen/Core>

#include <cmath>
#include <numbers>

namespace robotalk::walking {

/// Angle wrapped into (-pi, pi].
inline double Wrap(double a) {
  a = std::remainder(a, 2 * std::numbers::pi);
  return a <= -std::numbers::pi ? a + 2 * std::numbers::pi : a;
}

/// A planar pose.
struct Pose2 {
  double x = 0, y = 0, theta = 0;  ///< m, m, rad
  Eigen::Vector2d xy() const { return {x, y}; }
  /// A point given in this pose's frame, in the world.
  Eigen::Vector2d Apply(double px, double py) const {
    const double c = std::cos(theta), s = std::sin(theta);
    return {x + c * px - s * py, y + s * px + c * py};
  }
};

struct WalkStatus {
  bool stepping = false;  ///< a step schedule is running (GOTO, SETSPEED or the steps of a STOP)
  bool fallen = false;    ///< the torso tilted past the bound; the driver halted the walk
  double tilt = 0;        ///< torso tilt from vertical now, rad
  int steps_taken = 0;    ///< footsteps started since the driver was built
  // In the world frame (the plan mapped with the pelvis pose measured when it was made):
  Eigen::Vector2d com_plan = Eigen::Vector2d::Zero();  ///< planned CoM, m
  Eigen::Vector2d zmp_ref = Eigen::Vector2d::Zero();   ///< reference ZMP, m
  Pose2 foot[2];                                       ///< planned feet (left, right)
  double foot_height[2] = {0, 0};                      ///< m
  // Measured.
  Eigen::Vector3d com = Eigen::Vector3d::Zero();  ///< whole-body CoM from the physics, m
  Pose2 pelvis;                                   ///< the root's planar pose
  Pose2 foot_measured[2];                         ///< the feet's planar poses (ankle point, yaw)
  double foot_tilt[2] = {0, 0};                   ///< the soles' tilt from level, rad
  double foot_force[2] = {0, 0};                  ///< vertical ground force on each foot, N
  int foot_contacts[2] = {0, 0};                  ///< contact points of each sole
  double foot_peak_force[2] = {0, 0};  ///< the largest vertical force on one contact of each sole, N
  double foot_low[2] = {
      0, 0};  ///< the height of each sole's lowest corner above the ground, m (< 0: pressed in)
  Eigen::Vector2d foot_cop[2] = {Eigen::Vector2d::Zero(), Eigen::Vector2d::Zero()};  ///< each sole's CoP, m
  /// Where each sole should press (the plan's ZMP, or the stabilizer's
  /// command, split between the feet on the ground; walking/foot_damping.h), m
  Eigen::Vector2d foot_cop_ref[2] = {Eigen::Vector2d::Zero(), Eigen::Vector2d::Zero()};
  double foot_roll[2] = {0, 0}, foot_pitch[2] = {0, 0};  ///< each foot's roll and pitch in its yaw frame, rad
  /// foot_damping=true: the ankle offsets (roll, pitch) foot damping adds, rad
  Eigen::Vector2d ankle_offset[2] = {Eigen::Vector2d::Zero(), Eigen::Vector2d::Zero()};
  Eigen::Vector2d zmp =
      Eigen::Vector2d::Zero();  ///< centre of pressure of the ground forces (plan frame mapped to the world)
  double tracking_error = 0;    ///< largest |q_ref - q| over the leg joints, rad
  // Balance feedback (zero with stabilizer=false or during the start-up):
  Eigen::Vector2d dcm = Eigen::Vector2d::Zero();          ///< measured DCM c + c'/w, m
  Eigen::Vector2d dcm_ref = Eigen::Vector2d::Zero();      ///< planned DCM, m
  Eigen::Vector2d zmp_command = Eigen::Vector2d::Zero();  ///< the stabilizer's ZMP, inside the support, m
  Eigen::Vector2d com_offset = Eigen::Vector2d::Zero();   ///< CoM reference minus the plan's (world axes), m
  /// push_balance's forces: the left sole's target raised by half of it and the right's lowered, m
  double force_difference = 0;
  int recoveries = 0;     ///< push recoveries so far (walking/push_recovery.h: the pattern regenerated)
  int push_stops = 0;     ///< walks stopped by a push so far (push_recovery's stop and stand)
  int push_captures = 0;  ///< push_capture=true: the capture stop's re-plans so far
  int push_timings = 0;   ///< push_step_timing: the step timing's re-plans so far
  double push_waited =
      0;  ///< push_stop_wait: s the push's stops' lifts waited so far (the event-driven stop)
  /// push_recovery: the push the DcmEstimator reads (its impulse(), world axes, m/s); past
  /// stop_impulse it stops the walk, or holds the stop on
  Eigen::Vector2d push_impulse = Eigen::Vector2d::Zero();
  bool push_holding = false;  ///< push_recovery: a push's stop holds (the walk waits)
  bool saturated = false;     ///< the ZMP the stabilizer wanted lay outside the support
};

}  // namespace robotalk::walking
