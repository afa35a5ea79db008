// The ode driver's joint servos (private): per dof a mode — set-point, speed,
// force, passive, mimic follower, or driven by the base controller (a
// walking humanoid's legs) — with its target and the dof's limits. Apply()
// sets the ODE motors every physics step; docs/ode_sim.md, "Controllers and
// gains", gives the control laws.
//
// Threading and allocation as in ode_driver.h: one thread; the tables are
// sized in the constructor and nothing allocates afterwards.
#pragma once

#include "ode_driver.h"
#include "ode_world.h"
#include "robotalk/dof_table.h"
#include "robotalk/kinematics.h"

#include <Eigen/Core>
#include <cstdint>
#include <vector>

namespace robotalk::ode_detail {

inline constexpr double kMovingSpeed =
    1e-3;  ///< rad/s or m/s: below this a dof (or the base) counts as still
inline constexpr double kTargetReached = 2e-3;  ///< rad or m: a set-point counts as reached
/// s: a dof that reached its set-point moves again when it stays off it this
/// long (a joint against its stop bounces off it for a step or two).
inline constexpr double kBounce = 0.02;

class JointServos {
 public:
  /// The model's limits (robotalk/dof_table.h) with the options' defaults for
  /// infinite speed and effort limits; every dof holds q0() (below), mimic
  /// followers follow, joints without servo types are passive.
  JointServos(const RobotModel& model, const OdeDriverOptions& options);

  /// The start pose: q = 0 clamped into the limits, mimic couplings applied.
  const Eigen::VectorXd& q0() const { return q0_; }
  double lower(Eigen::Index i) const { return table_.lower[i]; }
  double upper(Eigen::Index i) const { return table_.upper[i]; }
  /// Speed and force limits with the options' defaults for infinite ones.
  const Eigen::VectorXd& vmax() const { return vmax_; }
  const Eigen::VectorXd& fmax() const { return fmax_; }

  /// Servo dof `i` to position `q` (REQUIRES: within the limits; not base_driven(i)).
  void SetPoint(Eigen::Index i, double q);
  /// Track a trajectory's reference for dof `i` from this step on: position
  /// `p`, velocity `v`, acceleration `a` (Driver::Track). Each step the motor
  /// runs at the reference's velocity at mid-step plus kp times the position
  /// error (velocity feed-forward; ODE's motor constraint supplies the force
  /// the dynamics need), the reference advanced along its own polynomial for
  /// at most one control period, then held.
  void Reference(Eigen::Index i, double p, double v, double a);
  /// Run dof `i` at `v`; it stops and holds at a position limit.
  void Speed(Eigen::Index i, double v);
  /// Apply `f` to dof `i` (N·m or N), motor off.
  void Force(Eigen::Index i, double f);
  /// Stop dof `i` at once: its motor at zero velocity with its full force (a
  /// position hold would drive back over the braking distance). Mimic
  /// followers follow their leader; passive and base-driven dofs are left alone.
  void Hold(Eigen::Index i, OdeWorld& world);
  /// From now on the base controller sets dof `i`'s motor itself; Apply(),
  /// Hold() and Moving() leave it alone.
  void GiveToBase(Eigen::Index i) { mode_[static_cast<std::size_t>(i)] = Mode::kBase; }
  bool base_driven(Eigen::Index i) const { return mode_[static_cast<std::size_t>(i)] == Mode::kBase; }

  /// One physics step: every dof's motor or effort from its mode.
  void Apply(OdeWorld& world);
  /// Whether a servo has a live target: a set-point not reached yet (within
  /// kTargetReached), a hold not yet at rest (slower than kMovingSpeed), a
  /// speed, a force or a trajectory reference. A settled dof moves again only
  /// when a new command comes or it stays kTargetReached off its target for
  /// kBounce: a joint held against its stop bounces off it now and then
  /// (contact bounce, up to 2 rad/s for a step) and is not moving.
  bool Moving(const Eigen::VectorXd& q, const Eigen::VectorXd& qd) const;

 private:
  enum class Mode : std::uint8_t { kPosition, kVelocity, kForce, kPassive, kMimic, kBase, kReference };

  DofTable table_;
  double kp_;
  double step_;     // s, one physics step
  double horizon_;  // s, how far a reference is advanced (one control period)
  Eigen::VectorXd q0_, vmax_, fmax_;
  std::vector<Mode> mode_;
  std::vector<std::uint8_t> settled_;  // kPosition, or kVelocity at speed 0: reached and came to rest
  std::vector<std::uint16_t> away_;    // settled, physics steps in a row off the target
  int bounce_steps_ = 1;               // kBounce in physics steps
  bool Away(Eigen::Index i) const { return away_[static_cast<std::size_t>(i)] >= bounce_steps_; }
  Eigen::VectorXd target_, speed_, force_;
  Eigen::VectorXd ref_accel_, ref_age_;  // kReference: target_ = p, speed_ = v at age 0
};

}  // namespace robotalk::ode_detail
