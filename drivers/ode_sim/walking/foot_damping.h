// Foot damping control: the feet in the balance loop (docs/ode_sim.md,
// "Balance feedback", "Foot damping"). Pure maths, no ODE, no I/O
// (tests/drivers/foot_damping_test.cpp checks it on a spring-supported sole).
//
// A position-controlled ankle holds its foot at the angle the leg IK asks;
// when the body's ZMP leaves where the plan put it, the stiff ankle levers
// the foot onto an edge or a corner and the whole robot rotates about it.
// Foot damping (Kajita et al. 2010, "Biped walking stabilization based on
// linear inverted pendulum tracking"; Caron et al. 2019, "Stair climbing
// stabilization of the HRP-4 humanoid robot using whole-body admittance
// control") drives each foot's ankle roll and pitch by the error between the
// foot's desired and measured torque about its ankle: an admittance, so the
// ankle gives way instead of levering the sole onto its edge, and the
// foot's centre of pressure tracks the one it was given:
//   d(theta)/dt = A (tau_measured - tau_desired) - theta / T_leak,
// with tau = f_z (p - ankle) (roll about the foot's x axis from the lateral
// offset, pitch about its y axis from the forward one) and the measured
// normal force f_z for both (so the error is f_z (p_measured - p_desired):
// an unloaded foot is not driven). A foot in the air returns to flat; a foot
// that touches down is *landing* until it carries `loaded` of the weight:
// meanwhile it is at least as compliant as a fully loaded foot, so a corner
// touch turns the sole flat onto the ground instead of levering the body.
//
// The desired CoP of each foot comes from DistributeZmp: the ZMP the walker
// wants (the plan's, or the DCM stabilizer's command) split between the feet
// on the ground by where it lies between them (the pressure ratio), the rest
// of it (across that line) given to both soles.
//
// Frames: a foot's frame is its ankle point on the ground with the foot's
// yaw (x forward, y to its left). Offsets: (roll, pitch) in rad, roll > 0
// lifts the sole's left edge, pitch > 0 lowers its toe.
// Threading: one thread. Allocation: none.
#pragma once

#include "ode_walk_status.h"  // Pose2

#include <Eigen/Core>

#include <array>

namespace robotalk::walking {

/// The simple humanoid's tuned admittance (rad/s per N·m) and its sole (N/m per corner, m long).
inline constexpr double kTunedAdmittance = 0.001, kTunedSoleStiffness = 2e5, kTunedSoleLength = 0.24;

struct FootDampingGains {
  /// rad/s per N·m of ankle torque error. Measured on the simple humanoid's
  /// rubber soles: 0.004 and 0.01 shake the feet heel to toe (the sole
  /// springs' and servos' lag) and it falls; 0.001 is stable. The driver
  /// sets it from the model's sole (AdmittanceFor).
  double admittance = kTunedAdmittance;
  double loaded = 0.3;        ///< fraction of the weight that ends a foot's landing
  double contact_force = 20;  ///< N: below it the foot is in the air
  double leak = 1.0;          ///< s: the offset's leak toward flat while in contact
  double air_return = 0.05;   ///< s: the offset's return to flat in the air
  double max_angle = 0.08;    ///< rad: bound of roll and pitch offsets
  double max_rate = 1.5;      ///< rad/s: bound of their rates
};

/// A foot's measured contact: normal force (N) and centre of pressure (m,
/// the foot's frame).
struct FootWrench {
  double force = 0;
  Eigen::Vector2d cop = Eigen::Vector2d::Zero();
};

/// A sole rectangle around the ankle point: front and back of it along the
/// foot, half its width (m, > 0).
struct SoleRect {
  double front = 0.1, back = 0.1, half_width = 0.05;
};

/// Where each foot should press: the CoP in its own frame and its share of
/// the weight (0..1, the two sum to 1 when a foot is on the ground).
struct FootTargets {
  std::array<Eigen::Vector2d, 2> cop{Eigen::Vector2d::Zero(), Eigen::Vector2d::Zero()};
  std::array<double, 2> share{0, 0};
};

/// Splits `zmp` (any planar frame) between the feet `feet` (ankle point and
/// yaw, same frame; index 0 left, 1 right) that are on the ground: with
/// one, it takes all, its CoP the ZMP clamped into its sole (`margin`, m,
/// inside); with both, the shares come from where the ZMP projects on the
/// segment between the soles' centres (clamped to it) and each CoP is its
/// sole's centre moved by the ZMP's offset from that projection, clamped into
/// its sole. With none, shares 0 and CoPs at the soles' centres.
FootTargets DistributeZmp(const Eigen::Vector2d& zmp, const std::array<Pose2, 2>& feet,
                          const std::array<bool, 2>& on_ground, const SoleRect& sole, double margin);

/// The admittance (rad/s per N·m) for a sole resting on four corner springs
/// of `stiffness` (N/m each) `length` (m) long: the closed loop's rate is the
/// admittance times the sole's rolling stiffness (stiffness · length²), so it
/// keeps the rate measured stable on the simple humanoid (0.001 on its 0.24 m
/// sole of 2e5 N/m corners: 11.5/s; kTunedAdmittance); a stiffer or longer
/// sole gets less (atlas.urdf: the tuned 0.001 shook its feet and it fell
/// in its first goal, docs/ode_sim.md). Within 0.1 % of the tuned sole it is
/// the tuned value exactly. stiffness, length > 0, else std::invalid_argument.
double AdmittanceFor(double stiffness, double length);

class FootDamping {
 public:
  /// weight (N, the robot's m g) > 0, dt (s) > 0, gains positive (leak and
  /// air_return > 0, loaded in (0, 1]); else std::invalid_argument.
  FootDamping(double weight, double dt, FootDampingGains gains = {});
  /// One control step of foot `foot` (0 left, 1 right) from its desired CoP
  /// (foot frame) and its measured contact; returns its (roll, pitch) offset.
  const Eigen::Vector2d& Update(int foot, const Eigen::Vector2d& desired_cop, const FootWrench& measured);
  /// One control step of foot `foot` without damping (the loop switched
  /// off): its offset returns to flat over `leak` (no faster than max_rate);
  /// returns it.
  const Eigen::Vector2d& Relax(int foot);
  const Eigen::Vector2d& offset(int foot) const { return offset_[Index(foot)]; }
  /// Touched down and not yet carrying `loaded` of the weight.
  bool landing(int foot) const { return landing_[Index(foot)]; }
  /// Both feet flat, in the air state.
  void Reset();
  const FootDampingGains& gains() const { return gains_; }

 private:
  static size_t Index(int foot);
  double weight_, dt_;
  FootDampingGains gains_;
  std::array<Eigen::Vector2d, 2> offset_{Eigen::Vector2d::Zero(), Eigen::Vector2d::Zero()};
  std::array<bool, 2> landing_{false, false}, in_contact_{true, true};
};

/// Foot force difference control (Kajita et al. 2010, section III.E; the
/// LIPM walking controller's "dfz" loop): in double support the feet's
/// heights move apart so that the difference of their normal forces follows
/// the desired one (the shares of DistributeZmp times the measured total):
///   d(h)/dt = A ((f_l - f_r) - (f_l,d - f_r,d)) - h / T_leak,
/// the left sole raised by h/2 and the right lowered by h/2: an overloaded
/// foot yields and an unloaded one presses down, so the stance cannot roll
/// onto one foot's edge with the other foot lifted (the ODE walker's fall
/// after a push's stop: docs/ode_sim.md, "Pushes"). Out of double support h
/// returns to 0 over `air_return`.
struct ForceDifferenceGains {
  /// m/s per N of force difference error. The loop's rate is A times the
  /// feet's vertical stiffness (the sole springs): ForceDifferenceFor.
  double admittance = 1.25e-5;
  double leak = 1.0;         ///< s: h's leak toward 0 in double support
  double air_return = 0.1;   ///< s: h's return to 0 out of double support
  double max_height = 0.02;  ///< m: bound of |h|
  double max_rate = 0.1;     ///< m/s: bound of |dh/dt|
};

/// The force difference gains for feet on `stiffness` (N/m, each foot's
/// vertical stiffness: its contact springs together), the loop's rate
/// `rate` (1/s, > 0). stiffness, rate > 0, else std::invalid_argument.
ForceDifferenceGains ForceDifferenceFor(double stiffness, double rate);

class ForceDifference {
 public:
  /// dt (s) > 0 and gains positive, else std::invalid_argument.
  explicit ForceDifference(double dt, ForceDifferenceGains gains = {});
  /// One control step: `share` the desired fractions of the weight of the
  /// left and right foot (DistributeZmp), `force` their measured normal
  /// forces (N), `double_support` both feet planned on the ground. Returns h
  /// (m): the left sole's target raised by h/2, the right's lowered by h/2.
  double Update(const std::array<double, 2>& share, const std::array<double, 2>& force, bool double_support);
  /// One step with the loop switched off: h returns to 0 over `leak`.
  double Relax();
  double height() const { return h_; }
  const ForceDifferenceGains& gains() const { return gains_; }

 private:
  double Move(double rate);
  double dt_;
  ForceDifferenceGains gains_;
  double h_ = 0;
};

}  // namespace robotalk::walking
