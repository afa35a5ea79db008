// Push recovery by regenerating the walking pattern from the measured state
// (issue 26, item 4; docs/ode_sim.md, "Pushes and disturbances"). Pure
// maths, no ODE; tests/drivers/push_recovery_test.cpp pushes a linear
// inverted pendulum that walks on the pattern's ZMP.
//
// Why not a correction of the plan: the legs are stiff position servos, so
// a plan that goes on open loop after a push pulls the CoM back to where the
// plan has moved on (docs/ode_sim.md, "Balance feedback"). Instead, when the
// measured DCM (xi = c + c'/w) departs from the plan's by more than the
// ankles absorb (`threshold`), the plan is regenerated from the measured
// state (in the spirit of Nishiwaki & Kagami's online pattern regeneration
// and Urata et al.'s online foot placement):
//  - the preview's CoM state becomes the measured CoM and velocity (its
//    acceleration such that its ZMP is the reference's now: no jump);
//  - both the plan and the robot walk on the same ZMP from now on, so the
//    DCM error e0 grows as e0 e^{w t}; the foot that lands next (the one in
//    the air, or the next to lift) lands shifted by CaptureShift(e0, ...),
//    which leaves no error once the weight has shifted onto it, and every
//    later footstep (and stance centre) moves with it: the walk goes on
//    from the new landing, re-planned from it (WalkPattern::Regenerate);
//  - the moved landing stays beside its stance foot (never across it) and
//    within reach; what that clamp leaves of the shift is caught by the
//    next regeneration, on the next step (a push toward the stance leg is
//    caught by the other foot: a two-step recovery).
//  - step timing: when the shift is beyond reach, a foot in the air lands
//    sooner (down to `min_swing` s of swing): e^{w T} is smaller.
// The reference ZMP stays at the feet's ZMP points (inside the support) and
// continuous: the cut is at the moved foot's landing.
//
// Stop and stand (Watch): traced on ODE, the walker does not fall from the
// push itself (half a second after it the DCM is within 7 cm of the plan's)
// but 2-3 s and 3-4 steps later, mostly forward over a stance toe: the walk,
// going on at full speed on a gait that uses the whole sole, feeds the
// oscillation the push started. So a push the DcmEstimator reads (its
// impulse(), the push's change of velocity) stops the walk at once
// (WalkPattern::StopSoon: continuous at any phase) and the robot stands a
// while before the walk goes on; measured on ODE it survives equal or larger
// pushes in all 8 directions (docs/ode_sim.md, "Pushes and disturbances").
//
// Threading: one thread. Allocation: Regenerate re-plans the schedule.
#pragma once

#include "walking/step_timing.h"
#include "walking/walk_pattern.h"

#include <Eigen/Core>

#include <cstdint>
#include <optional>

namespace robotalk::walking {

/// The foothold shift that captures a DCM error e0 (m) which grows on the
/// plan's ZMP for T s until the foot lands, then while the weight shifts
/// onto it linearly over D s: the error at the end of that shift equals
/// the shift (the DCM stands where the plan has it, relative to the moved
/// foot). With the ZMP held `u` (m) from the plan's until the landing (the
/// ankles), e_T = u + (e0 - u) e^{wT} and
/// d = (e_T e^{wD} - u (e^{wD} - 1 - f)) / (1 + f), f = (e^{wD} - 1 - wD) / (wD).
Eigen::Vector2d CaptureShift(const Eigen::Vector2d& e0, double omega, double T, double D,
                             const Eigen::Vector2d& u = Eigen::Vector2d::Zero());

/// A point (or with `vector`, a direction) given relative to the pose
/// `from`, placed the same way relative to `to`: the measured CoM relative
/// to the measured support foot, put on the planned one.
Eigen::Vector2d Relocate(const Pose2& from, const Pose2& to, const Eigen::Vector2d& p, bool vector = false);

struct RecoveryParams {
  double threshold = 0.07;  ///< m (per axis): beyond this DCM error the pattern regenerates (on ODE, walking
                            ///< unpushed, the measured error reaches 4 cm)
  double interval = 0.05;   ///< s: at most one regeneration per interval
  double min_swing = 0.35;  ///< s: a step in the air may land this soon after its lift-off, at the soonest
  double late = 0.03;  ///< s: a foot in the air this close to landing keeps its landing; the next one moves
  double swing_speed = 2.0;  ///< m/s: a foot in the air moves its landing at most this much per second left
  /// m/s, 0: off (option push_swing_reach). A foot in the air lands at most
  /// this far per second of its swing's move left (to 0.9 of the swing) from
  /// where the swing has it now (or as far as its landing already was): each
  /// regeneration's swing_speed bounds only its own move, and moves 50 ms
  /// apart add up beyond what the legs follow.
  double swing_reach = 0;
  /// m/s, 0: off (option push_lift_reach). A moved step not yet in the air
  /// (the next to lift, and the ones the regeneration moves after it) lands
  /// at most this far per second of its swing's horizontal move (0.8 of its
  /// swing: from 0.1 to 0.9) from where its foot stands before it (or as far as its plan
  /// had it): swing_reach bounds only the foot in the air, and a capture
  /// step planned in double support asked the foot for 0.67 m in a 0.32 s
  /// swing (2 m/s, peaks of 3.8) that the legs did not follow (docs/ode_sim.md,
  /// "Why the walker falls at a quarter of the bound").
  double lift_reach = 0;
  // A moved landing's ankle from its stance foot's ankle, in that foot's frame:
  double reach = 0.45;         ///< m: at most this far ahead
  double reach_back = 0.30;    ///< m: at most this far behind
  double min_width = 0.14;     ///< m: at least this far sideways (the soles never overlap nor cross)
  double max_width = 0.40;     ///< m: at most this far sideways
  double ankle_margin = 0.03;  ///< m: the stance foot's ZMP moves toward the error, this far inside its sole
  double ankle_ramp = 0.05;    ///< s: ... over this long (the reference stays continuous)
  bool in_double_support = true;  ///< false: only a foot in the air moves (no regeneration in double support)
  bool early_lift = true;         ///< in double support, the next step lifts within fast_double
  int fast_steps = 2;             ///< the steps after the moved one taken at the fast timing below
  double fast_single = 0.4;       ///< s: their single support
  double fast_double = 0.1;       ///< s: their double support
  // Stop and stand (Watch): walking, a push of more than stop_impulse (the
  // DcmEstimator's impulse(), m/s per unit mass: walking unpushed on ODE it
  // stays under 0.084; 10 N s on the 52.5 kg humanoid is 0.19) stops the
  // walk (WalkPattern::StopSoon) and the robot stands stop_hold s before the
  // walk goes on. 0: off.
  double stop_impulse = 0.1;  ///< m/s
  double stop_hold = 3.0;     ///< s
  // The event-driven stop (GateLift below; driver option push_stop_wait):
  // while a push's stop holds, a step's foot lifts only once the foot it
  // leaves the weight on carries at least `wait_share` of the weight and the
  // measured DCM is `wait_margin` inside that foot's sole, and (touch_share
  // > 0; the driver's push_stop_land) the shift onto a landing foot waits
  // until it carries `touch_share`: at most `stop_wait` s per lift or
  // landing (0: off, the timed pattern); the plan's CoM
  // state becomes the measured one when a lift that waited goes
  // (`wait_reanchor`): the preview plans on from there.
  double stop_wait = 0;     ///< s (the driver's push_stop_wait, off by default)
  double wait_share = 0.8;  ///< of the weight
  double wait_margin = 0;   ///< m (the pushed GOTO from the left on ODE: 0.03: 7 of 21 fell, 0: 5, timed: 6)
  double touch_share = 0.15;  ///< of the weight: a landed foot has touched down (0: landings never wait)
  bool wait_reanchor = true;
  // The capture stop (CaptureStop below; option push_capture): the stop's
  // last step lands where the measured DCM is caught, the plan re-anchored
  // on the measured CoM state, re-planned every `interval` until it lands.
  bool capture_stop = false;
  double capture_margin = 0.05;  ///< m: the caught ZMP this far inside the final support
  double capture_shift = 0.1;    ///< s: after the landing the ZMP goes to the DCM this fast ...
  double capture_hold = 0.3;     ///< s: ... holds there this long, then shifts back to the middle (end_shift)
  bool capture_reanchor = true;  ///< the plan's CoM state becomes the measured one at each re-plan
  bool capture_tidy = true;      ///< a landing moved off alongside: then the other foot steps alongside it
  double capture_tidy_beyond = 0.03;  ///< m: ... when moved more than this
  // The regeneration's footholds during the push's stop (from Watch's stop
  // until the stop's steps have landed; driver option push_stop_feet):
  // kMove as walking; kKeep: the stop's landings stay where and when
  // StopSoon put them (the CoM state, the ankles, the early lift and the
  // fast timing of the steps after the first as walking); kStill: no
  // regeneration at all until the walk resumes (nothing re-anchored).
  enum class StopFeet : std::uint8_t { kMove, kKeep, kStill };
  StopFeet stop_feet = StopFeet::kMove;
  // Step timing adaptation with step location (step_timing.h; driver option
  // push_step_timing, off): kPush: from Watch's stop (the push read) until
  // the step in the air lands, when the adapter lands it `timing_sooner` sooner than planned (read in double
  // support: the next step, from its lift-off; before it the regeneration as ever), every `interval` that
  // step lands where and when StepTimingAdapter says for the measured DCM (WalkPattern::AdaptStep, in place
  // of the regeneration); kThreshold: instead whenever the DCM error passes `threshold` with a foot in the
  // air (in place of the regeneration's step); kAlways: both. The soonest landing is min_swing after the
  // lift-off; the next steps at the fast timing.
  enum class TimingMode : std::uint8_t { kOff, kPush, kThreshold, kAlways };
  TimingMode step_timing = TimingMode::kOff;
  StepTimingParams timing;  ///< its weights; reach and widths are copied from above
  /// s: after a push's reading a step is re-planned only when the adapter
  /// lands it at least this much sooner than planned (its place alone cannot
  /// catch the DCM); else the regeneration as ever.
  double timing_sooner = 0.02;
};

/// The event-driven stop's test: the foot that stays down (`stance`, its
/// measured ankle point and yaw) carries `force` >= wait_share of `weight`
/// (N) and the measured DCM `dcm` lies wait_margin inside its sole.
bool LiftReady(const Pose2& stance, const GaitParams& g, const Eigen::Vector2d& dcm, double force,
               double weight, const RecoveryParams& p);
/// ... and for a landing: the foot that lands carries `force` >= touch_share of `weight`.
bool LandReady(double force, double weight, const RecoveryParams& p);

class PushRecovery {
 public:
  /// omega = sqrt(g / z_c) > 0, tick > 0 (s), else std::invalid_argument.
  PushRecovery(double omega, double tick, RecoveryParams params = {});
  /// One control tick with the measured CoM and velocity (plan frame).
  /// Regenerates `pattern` when the DCM error passes the threshold and a
  /// step can still take it (during Watch's stop, its footholds as
  /// stop_feet says); during a capture stop (capture_stop, after
  /// Watch stopped the walk) re-plans the stop from the measured state
  /// instead (WalkPattern::CaptureStop). Returns true when it did either:
  /// the plan's CoM state is then the measured one.
  bool Update(WalkPattern& pattern, const Eigen::Vector2d& com, const Eigen::Vector2d& com_vel);
  /// The last measured DCM error (m), and how many regenerations so far.
  const Eigen::Vector2d& error() const { return error_; }
  int regenerations() const { return count_; }
  const RecoveryParams& params() const { return p_; }

  /// What the walk does after Watch().
  enum class Walk : std::uint8_t {
    kOn,      ///< walks on (no push, or the hold is over)
    kHold,    ///< stopped by a push: stands; queue no steps
    kResume,  ///< this tick the hold ended: re-plan (a GOTO) and walk on
  };
  /// One control tick with the estimated push impulse (m/s): when it passes
  /// stop_impulse while the pattern walks, stops it (the step in the air
  /// lands, the next brings the other foot alongside, the weight shifts to
  /// the middle: WalkPattern::StopSoon, continuous at any phase) and holds
  /// stop_hold s; a push while holding holds on.
  Walk Watch(WalkPattern& pattern, const Eigen::Vector2d& impulse);
  /// The event-driven stop (stop_wait > 0), one tick before pattern.Tick():
  /// while the stop holds and a step lifts at the next tick, it lifts a
  /// tick later unless `ready` (LiftReady for its stance foot) or it has
  /// waited stop_wait s; a foot that lands at the next tick: the shift of
  /// weight onto it starts a tick later unless `ready` (LandReady for it)
  /// or it has waited stop_wait s. When an event that waited goes, with wait_reanchor,
  /// the plan's CoM state becomes `com`, `com_vel` (measured, plan frame).
  /// Returns true when it re-anchored.
  bool GateLift(WalkPattern& pattern, bool ready, const Eigen::Vector2d& com, const Eigen::Vector2d& com_vel);
  /// s the stop's lifts have waited so far (GateLift).
  double waited() const { return waited_total_; }
  /// Walks stopped by a push so far.
  int stops() const { return stops_; }
  /// Watch's stop holds: from a push's stop until the walk goes on (the
  /// stop's steps and the stance after them).
  bool holding() const { return hold_ > 0; }
  /// With capture_stop: the capture stop's re-plans so far (Update returns
  /// true for each; every `interval` from the stop until its last step lands).
  int captures() const { return captures_; }
  /// With step_timing: the step timing's re-plans so far (Update returns true for each).
  int timings() const { return timed_; }

 private:
  double omega_, tick_;
  RecoveryParams p_;
  double since_ = 1e9;
  Eigen::Vector2d error_ = Eigen::Vector2d::Zero();
  int count_ = 0;
  double hold_ = 0;  // s of standing left
  int stops_ = 0;
  bool capturing_ = false;  // a capture stop whose last step has not landed
  int captures_ = 0;
  std::optional<StepTimingAdapter> timing_;  // step_timing != kOff
  bool pushed_ = false;                      // a push read; no step it re-planned has landed yet
  bool adapted_ = false;                     // ... and one was re-planned
  int timed_ = 0;
  double waiting_ = 0, waited_total_ = 0;  // s this lift has waited; all lifts
};

}  // namespace robotalk::walking
