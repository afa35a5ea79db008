// The hip strategy after a push (issue 26, item 4; docs/ode_sim.md, "Pushes
// and disturbances", tenth session): the upper body leans toward the push,
// fast, then comes back upright slowly. Pure maths, no ODE, no I/O
// (tests/drivers/hip_strategy_test.cpp pushes a pendulum with an upper body).
//
// Why: traced on ODE, a push tips the walker as one rigid body about its
// stance sole's edge (the stiff servos hold the body to the foot), and the
// ankles cannot move the centre of pressure past that edge. The hips can
// still push the centre of mass back: accelerating the upper body (pelvis and
// torso, ~2/3 of the mass) to lean toward the push turns the body's angular
// momentum that way, and its reaction on the legs turns them, with the stance
// sole, the other way, back onto the ground; the ground's horizontal force
// then points against the push (the centroidal moment pivot beyond the
// centre of pressure: Stephens 2007, "Humanoid push recovery"; Hofmann,
// Popovic and Herr 2009, "Exploiting angular momentum to enhance bipedal
// centre-of-mass control"). Returning upright reverses that torque, so the
// return is slow (little torque, spread over a second).
//
// What it does: when the push's impulse (the DcmEstimator's impulse(), m/s:
// walking unpushed on ODE it stays under 0.084) passes `trigger`, the lean
// (an angle along the impulse's horizontal direction at that tick) goes to
// min(max_lean, gain |impulse|) (the target grows with the impulse while the
// push lasts) on a time-optimal profile bounded by `accel` and `rate`, is held
// `hold` s, then returns to 0 bounded by `back_accel` and `back_rate`. A push
// while leaning or returning is not a new trigger (the lean finishes first).
//
// Frame: the walker's plan frame (x forward, y left); the lean (x, y) is the
// direction the top of the pelvis moves toward, times the angle (rad).
// Threading: one thread. Allocation: none.
#pragma once

#include <Eigen/Core>

namespace robotalk::walking {

struct HipStrategyParams {
  double trigger = 0.1;    ///< m/s of impulse (the push stop's threshold)
  double gain = 1.5;       ///< rad of lean per m/s of impulse (20 N s read as ~0.25 m/s on ODE)
  double max_lean = 0.25;  ///< rad (the hips' roll limit is 0.5 on the simple humanoid)
  double accel = 20;       ///< rad/s^2 while leaning (with ~3 kg m^2 above the hips: 60 N m)
  double brake = 4;        ///< rad/s^2 slowing the lean (its reaction tips the legs toward the push)
  double rate = 1.0;       ///< rad/s while leaning (the joints' limit is 3)
  double hold = 0.4;       ///< s at the lean
  double back_accel = 2;   ///< rad/s^2 returning upright
  double back_rate = 0.3;  ///< rad/s returning upright
};

class HipStrategy {
 public:
  /// tick > 0 (s), every parameter > 0 (hold >= 0), else std::invalid_argument.
  HipStrategy(double tick, HipStrategyParams params = {});
  /// One tick with the push's impulse (m/s, the plan frame). Returns lean().
  const Eigen::Vector2d& Update(const Eigen::Vector2d& impulse);
  /// The lean: the direction the upper body leans toward times the angle (rad).
  const Eigen::Vector2d& lean() const { return lean_; }
  /// Leaning, holding or returning (a new push is not a trigger meanwhile).
  bool active() const { return phase_ != Phase::kIdle; }
  /// How many pushes triggered a lean.
  int leans() const { return leans_; }

 private:
  enum class Phase { kIdle, kLean, kHold, kBack };
  double tick_;
  HipStrategyParams p_;
  Phase phase_ = Phase::kIdle;
  Eigen::Vector2d dir_ = Eigen::Vector2d::UnitX(), lean_ = Eigen::Vector2d::Zero();
  double angle_ = 0, rate_ = 0, target_ = 0, peak_ = 0, held_ = 0;
  int leans_ = 0;
  // One tick of the time-optimal profile toward `to` within `accel`, `rate`.
  void Track(double to, double accel, double brake, double rate);
};

}  // namespace robotalk::walking
