// DCM (divergent component of motion, capture point) stabilizer: balance
// feedback for the walking controller from the measured centre of mass.
// Pure maths, no ODE, no I/O (tests/drivers/walking_test.cpp checks it on a
// simulated linear inverted pendulum with pushes).
//
// The linear inverted pendulum at height zc: c'' = w^2 (c - p), w = sqrt(g/zc),
// p the ZMP. Its DCM xi = c + c'/w moves as xi' = w (xi - p): only the DCM
// diverges, so balance is keeping it over the support.
//
// Ankle strategy: the ZMP command p = p_ref + (1 + k/w)(xi - xi_ref) makes the
// DCM error e = xi - xi_ref decay as e' = -k e, as long as p lies inside the
// support polygon (the soles can only press there). It is clamped into the
// polygon (shrunk by `margin`); then the error still shrinks if the clamped
// ZMP lies beyond the DCM, else it grows.
// Step strategy: when clamped, the DCM expected at the next touch-down
// (xi_T = p + (xi - p) e^{w T} with the clamped p, T the time to it) is off
// the planned one by d = xi_T - xi_T_ref; moving the next foothold by d puts
// the new support under the DCM, the capture point (Englsberger et al. 2011,
// Pratt et al. 2006).
//
// On a position-controlled robot (the ODE walker's leg servos hold their
// joints stiffly) a ZMP is commanded through the CoM: the ground pushes at
// p = c - c''/w^2, so the CoM reference is accelerated by w^2 (c - p): ComOffset
// integrates that, minus the plan's own acceleration, into an offset added to
// the planned CoM, with a feedback of the measured centre of pressure (the
// contact forces) on what the ZMP command asked. With perfect tracking the
// offset d obeys d'' = -k w d - (w + k) d' (it returns to the plan); the
// measured CoM's departures (a push, the body tipping on a sole edge) drive it.
//
// Threading: none needed (DcmStabilizer::Update is const; ComOffset is one
// thread's). Allocation: none.
#pragma once

#include <Eigen/Core>

#include <span>

namespace robotalk::walking {

struct DcmGains {
  double k = 3.0;          ///< 1/s: the DCM error's decay rate
  double margin = 0.01;    ///< m: the ZMP command stays this far inside the support
  double step_min = 0.01;  ///< m: a step adjustment smaller than this is not asked for
};

/// The closest point to `p` of the convex polygon `poly` (counter-clockwise
/// corners) shrunk by `margin` (m); p itself when inside. An empty polygon
/// returns p.
Eigen::Vector2d ClampToPolygon(const Eigen::Vector2d& p, std::span<const Eigen::Vector2d> poly,
                               double margin);

class DcmStabilizer {
 public:
  /// com_height, gravity > 0 (else std::invalid_argument).
  DcmStabilizer(double com_height, double gravity, DcmGains gains = {});
  double omega() const { return omega_; }

  struct Output {
    Eigen::Vector2d dcm = Eigen::Vector2d::Zero();         ///< measured DCM
    Eigen::Vector2d dcm_ref = Eigen::Vector2d::Zero();     ///< planned DCM
    Eigen::Vector2d zmp_wanted = Eigen::Vector2d::Zero();  ///< the ankle strategy's ZMP, unclamped
    Eigen::Vector2d zmp = Eigen::Vector2d::Zero();         ///< the ZMP command, inside the support
    bool saturated = false;                                ///< the ankles cannot do what is wanted
    /// Where to move the next foothold (m, world), zero unless saturated and
    /// a step is coming (time_to_touchdown > 0).
    Eigen::Vector2d step_offset = Eigen::Vector2d::Zero();
  };
  /// One control step from the measured CoM (com, com_vel) and the plan
  /// (com_ref, com_vel_ref, zmp_ref), with the support polygon now and the
  /// time until the swing foot lands (<= 0: no step coming).
  Output Update(const Eigen::Vector2d& com, const Eigen::Vector2d& com_vel, const Eigen::Vector2d& com_ref,
                const Eigen::Vector2d& com_vel_ref, const Eigen::Vector2d& zmp_ref,
                std::span<const Eigen::Vector2d> support, double time_to_touchdown) const;

 private:
  double omega_;
  DcmGains gains_;
};

struct ComOffsetGains {
  double zmp_gain = 20.0;    ///< 1/s^2: CoM acceleration per metre of ZMP command the CoP misses
  double max_offset = 0.05;  ///< m: the offset's bound (each axis)
  double max_speed = 0.5;    ///< m/s: the offset's rate bound (each axis)
};

/// The stabilizer's ZMP command as an offset of the CoM reference (above).
class ComOffset {
 public:
  /// omega > 0 (the stabilizer's), else std::invalid_argument.
  explicit ComOffset(double omega, ComOffsetGains gains = {});
  /// Back to no offset, at rest.
  void Reset();
  /// One control step of `dt` s from the stabilizer's output `o` for the
  /// measured CoM `com`, the plan (com_ref, zmp_ref) and the measured centre
  /// of pressure (nullptr: none, e.g. in the air). Returns the offset (m).
  const Eigen::Vector2d& Update(const DcmStabilizer::Output& o, const Eigen::Vector2d& com,
                                const Eigen::Vector2d& com_ref, const Eigen::Vector2d& zmp_ref,
                                const Eigen::Vector2d* cop, double dt);
  /// One control step of `dt` s without the stabilizer (switched off): the
  /// offset returns to the plan exponentially over `tau` s (> 0), its
  /// velocity that return's (no faster than max_speed). Returns the offset.
  const Eigen::Vector2d& Relax(double dt, double tau);
  const Eigen::Vector2d& offset() const { return offset_; }
  const Eigen::Vector2d& velocity() const { return velocity_; }

 private:
  double omega_;
  ComOffsetGains gains_;
  Eigen::Vector2d offset_ = Eigen::Vector2d::Zero(), velocity_ = Eigen::Vector2d::Zero();
};

}  // namespace robotalk::walking
