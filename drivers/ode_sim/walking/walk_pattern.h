// The walking pattern: a schedule of footsteps in time and, tick by tick,
// the feet's poses (swing trajectories), the ZMP reference and the centre of
// mass that ZMP preview control (zmp_preview.h) derives from it. Pure maths,
// no ODE; the ode driver turns its output into joint targets (leg_ik.h).
//
// The schedule, from Append() on a standing robot: `start_lead` s standing
// still (the preview must see the start coming: ZMP preview control moves the
// CoM about a second ahead of its reference), a weight shift of `start_shift` s from the
// centre of the feet onto the first stance foot, then per step `single_support`
// s of swing (ZMP at the stance foot's ZMP point) and `double_support` s of
// shifting onto the landed foot, the last step followed by `end_shift` s back
// to the centre of both feet, then standing. Steps can be appended while
// walking (SETSPEED keeps the queue ahead of the preview horizon) and the
// queue can be cut short (STOP: the step in the air, if any, and one step
// bringing the other foot alongside).
//
// Swing foot: lifts and sets down with zero vertical speed (height
// step_height * (1 - cos 2 pi s) / 2), moves horizontally and turns within
// the middle 80 % of single support on a cosine profile.
//
// Time: ticks of `tick` seconds (the driver's 1 ms); the preview runs every
// `preview_every` ticks and the CoM in between follows the same jerk.
// Thread safety: none (one thread). Allocation: the schedule grows when steps
// are appended; Tick() does not allocate.
#pragma once

#include "walking/gait.h"
#include "walking/zmp_preview.h"

#include <Eigen/Core>

#include <cstdint>
#include <vector>

namespace robotalk::walking {

class WalkPattern {
 public:
  WalkPattern(const GaitParams& g, double tick, int preview_every, double gravity, double horizon = 1.6);

  /// Standing with both feet around `centre`, the CoM at `com` (xy), at rest.
  void Reset(const Pose2& centre, const Eigen::Vector2d& com);
  /// Appends steps (with their centres) to the schedule; starts walking if
  /// standing or in the final shift of weight (after `start_lead`), else the
  /// first new step follows the last one's double support without a pause.
  void Append(const std::vector<Footstep>& steps, const std::vector<Pose2>& centres);
  /// Cuts the schedule: keeps the step in the air (or, in double support,
  /// none), then one step that brings the other foot alongside. Returns the
  /// final stance centre.
  Pose2 StopSoon();
  /// Drops the steps that have not started yet, keeping the one in the air
  /// (for SETSPEED to re-plan); returns the centre they would start from
  /// and the side of the next swing.
  Pose2 DropUnstarted(Side* next_swing);
  /// One tick forward.
  void Tick();

  /// True when no step is scheduled or running and the end shift is over.
  bool standing() const;
  /// Standing and the planned CoM at rest over the reference ZMP: within
  /// `tolerance` (m) of it and slower than `tolerance` per second. The
  /// preview's CoM settles a few tenths of a second after the last shift of
  /// weight ends (standing() turns true).
  bool settled(double tolerance = 1e-3) const;
  /// Steps scheduled but not yet started (the one in the air excluded).
  int unstarted_steps() const;
  /// Time until the end of the schedule's last step, s (0 when standing).
  double time_to_end() const;
  bool double_support() const;
  /// The foot that carries the robot: the stance foot in single support, else the left.
  Side support_side() const;
  /// The feet now: pose and height above the ground (m).
  const Pose2& foot(Side s) const { return foot_[static_cast<int>(s)]; }
  double foot_height(Side s) const { return height_[static_cast<int>(s)]; }
  /// The planned CoM (xy), its velocity, the model's ZMP and the reference ZMP.
  Eigen::Vector2d com() const { return {cx_(0), cy_(0)}; }
  Eigen::Vector2d com_velocity() const { return {cx_(1), cy_(1)}; }
  Eigen::Vector2d zmp() const;
  Eigen::Vector2d zmp_ref() const { return ZmpAt(tick_); }
  /// The stance centre of the last scheduled step (or the standing one).
  const Pose2& final_centre() const { return final_centre_; }
  /// The side of the next step to append (left when none is scheduled).
  Side next_side() const { return steps_.empty() ? Side::kLeft : Other(steps_.back().step.side); }
  /// Steps whose swing has started since construction.
  int started_steps() const { return started_; }
  /// The feet's support polygon now contains p (m)? For tests: a foot's
  /// sole rectangle, or in double support the convex hull of both.
  bool InSupport(const Eigen::Vector2d& p, double margin = 0) const;
  const GaitParams& gait() const { return g_; }
  double time() const { return static_cast<double>(tick_) * tick_s_; }

 private:
  struct Scheduled {
    Footstep step;
    Pose2 centre;
    Pose2 from;              // the swing foot before the step
    Pose2 stance;            // the other foot during the step
    std::int64_t start = 0;  // tick where single support starts
  };
  Eigen::Vector2d ZmpPoint(const Pose2& foot) const;
  Eigen::Vector2d ZmpAt(std::int64_t tick) const;
  int StepAt(std::int64_t tick) const;  // index of the step whose period holds tick, or -1 / size
  std::int64_t EndTick() const;
  void UpdateFeet();
  void Reschedule(size_t keep);

  GaitParams g_;
  double tick_s_;
  int every_;
  std::int64_t ss_ticks_, ds_ticks_, start_ticks_, end_ticks_, lead_ticks_;
  ZmpPreview px_, py_;
  std::vector<double> future_x_, future_y_;
  Eigen::Vector3d cx_ = Eigen::Vector3d::Zero(), cy_ = Eigen::Vector3d::Zero();
  double ux_ = 0, uy_ = 0;
  Eigen::Vector3d sample_x_ = Eigen::Vector3d::Zero(), sample_y_ = Eigen::Vector3d::Zero();
  std::int64_t tick_ = 0;
  std::int64_t walk_start_ = 0;  // tick where the start shift begins
  std::vector<Scheduled> steps_;
  Pose2 rest_[2];  // the feet when the schedule started
  Pose2 foot_[2];
  double height_[2] = {0, 0};
  Pose2 final_centre_;
  int started_ = 0;
};

/// Point-in-convex-polygon test helper: the sole rectangle of a foot.
bool InFoot(const Pose2& foot, const GaitParams& g, const Eigen::Vector2d& p, double margin);

}  // namespace robotalk::walking
