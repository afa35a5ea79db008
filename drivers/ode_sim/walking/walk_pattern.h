// The walking pattern: a schedule of footsteps in time and, tick by tick,
// the feet's poses (swing trajectories), the ZMP reference and the centre of
// mass that ZMP preview control (zmp_preview.h) derives from it. Pure maths,
// no ODE; the ode driver turns its output into joint targets (leg_ik.h).
//
// The ZMP reference is a chain of phases, each a straight move (or a hold)
// between two points over a number of ticks: standing (hold at the middle of
// the feet's ZMP points), a first shift of `start_shift` s onto the first
// stance foot, per step `single_support` s on the stance foot (the other
// foot swings) and `double_support` s of shifting onto the landed foot, and
// after the last step `end_shift` s back to the middle of both feet.
//
// Replanning is a splice: the schedule is cut at a phase boundary (or inside
// a standing hold), everything before the cut stays as it was, and the new
// steps continue from the reference's value there. So the reference is
// continuous whatever the command and its instant. A walk command (Append,
// DropUnstarted) cuts no earlier than `start_lead` s ahead: the preview sees
// every change of its reference at least that long before it happens (ZMP
// preview control moves the CoM about a second ahead of a change). A stop
// (StopSoon) keeps the step in the
// air; the next step, whose single support the preview already counts on,
// brings its foot alongside instead (or, with the feet side by side, the
// weight stays on its stance foot for that time without a swing), and the
// weight shifts back to the middle after it. So a stop changes the reference
// no sooner than single_support ahead, whatever its phase.
//
// Swing foot: lifts and sets down with zero vertical speed (height
// step_height * (1 - cos 2 pi s) / 2), moves horizontally and turns within
// the middle 80 % of single support on a cosine profile.
//
// Time: ticks of `tick` seconds (the driver's 1 ms); the preview runs every
// `preview_every` ticks and the CoM in between follows the same jerk.
// Thread safety: none (one thread). Allocation: planning (Append,
// DropUnstarted, StopSoon) grows and prunes the schedule; Tick() does not allocate.
#pragma once

#include "walking/gait.h"
#include "walking/zmp_preview.h"

#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <vector>

namespace robotalk::walking {

struct RecoveryParams;    // push_recovery.h
class StepTimingAdapter;  // step_timing.h

class WalkPattern {
 public:
  WalkPattern(const GaitParams& g, double tick, int preview_every, double gravity, double horizon = 1.6);

  /// Standing with both feet around `centre`, the CoM at `com` (xy), at rest.
  void Reset(const Pose2& centre, const Eigen::Vector2d& com);

  /// Where new steps start after a splice: the stance centre they are
  /// planned from, and the side of the first swing: forced (the weight is on
  /// the other foot, or shifting to it) or free (standing).
  struct Splice {
    Pose2 centre;
    Side next = Side::kLeft;
    bool side_free = true;
  };
  /// Cuts the schedule `start_lead` s ahead (at the next boundary), dropping
  /// the steps that would start after the cut (GOTO and SETSPEED re-plan);
  /// returns where new steps start.
  Splice DropUnstarted();
  /// Where Append() would continue now without dropping anything.
  Splice AppendPoint() const;
  /// Appends steps (with their centres) after the last one, or after the
  /// cut `start_lead` s ahead when the schedule ends sooner. REQUIRES: the
  /// first step's side is AppendPoint().next unless side_free; steps alternate.
  void Append(const std::vector<Footstep>& steps, const std::vector<Pose2>& centres);
  /// STOP: keeps the step in the air, then at most one step bringing the
  /// other foot alongside (above), then the shift back to the middle of the
  /// feet. Returns the final stance centre.
  Pose2 StopSoon();
  /// One tick forward.
  void Tick();
  /// Step adjustment (balance): the foot in the air lands `offset` (m, plan
  /// frame) from where it was planned to (not from where the last adjustment
  /// put it), bounded so that it lands beside the stance foot, never across
  /// it nor farther than `reach` (m) from it. The ZMP reference moves with the
  /// landed foot from the landing on (the shift onto it, its stance, the end
  /// shift); the next steps start from it. Returns the offset applied; zero
  /// in double support.
  Eigen::Vector2d AdjustLanding(const Eigen::Vector2d& offset, double reach);
  /// Push recovery (push_recovery.h): the plan regenerated from the measured
  /// CoM and velocity (plan frame). The CoM state becomes the measured one;
  /// the next foot to land (the one in the air unless within `late` of its
  /// landing, else the next to lift) lands shifted by the CaptureShift of
  /// the DCM error, sooner when that is beyond reach (not sooner than
  /// `min_swing` after its lift-off), clamped beside its stance foot and
  /// within reach; every later step and stance centre moves by the full
  /// shift, re-planned from the landing on (the reference is cut there:
  /// continuous). False (nothing changed) when no step can move: standing,
  /// the end shift, a stop's stand without a swing. `stopping` (a push's
  /// stop, PushRecovery::Watch): the landings as RecoveryParams::stop_feet says.
  bool Regenerate(const Eigen::Vector2d& com, const Eigen::Vector2d& com_vel, const RecoveryParams& p,
                  bool stopping = false);
  /// Step timing adaptation (step_timing.h; push_recovery.h's step_timing):
  /// the foot in the air (unless within `late` of its landing) lands where
  /// and when `adapter` says for the measured CoM and velocity (plan frame):
  /// the stance ZMP until then moved toward the DCM error as the
  /// regeneration's ankles do (`ankle_margin` inside the sole), not sooner
  /// than `min_swing` after its lift-off, within reach and width of its
  /// stance foot and `swing_reach` from where the foot is; every later step
  /// moves with it, the next `fast_steps` at the fast timing (the next lifts
  /// within `fast_double`). The CoM state becomes the measured one. False
  /// (nothing changed) when no foot is in the air or it is too late.
  /// `only_sooner`: changes nothing (false) unless the adapter lands the
  /// step at least `sooner` s before the plan's time (its place alone
  /// cannot catch the DCM).
  bool AdaptStep(const Eigen::Vector2d& com, const Eigen::Vector2d& com_vel, const StepTimingAdapter& adapter,
                 const RecoveryParams& p, bool only_sooner = false);
  /// The capture stop (push_recovery.h), after StopSoon: the stop's last
  /// step (the foot brought alongside) lands where the measured DCM (from
  /// `com`, `com_vel`, plan frame) is caught. Predicted on the reference's
  /// ZMP until that landing (in the air: the stance ZMP at the sole's point
  /// nearest the DCM, `ankle_margin` inside), the DCM at the landing must be
  /// the reference's own from then on: the ZMP goes to a point q within
  /// `capture_shift` s, holds `capture_hold` s, then shifts to the middle of
  /// the feet over end_shift. The foot lands where it was to, moved only as
  /// far as q needs to be `capture_margin` inside the two soles' hull (within
  /// reach and width of the stance foot: beyond them q is clamped into the hull);
  /// while that does not fit, a foot in the air lands sooner (not sooner than
  /// `min_swing` after its lift-off). The plan's CoM state becomes the
  /// measured one. False (nothing changed) when no step can still move.
  bool CaptureStop(const Eigen::Vector2d& com, const Eigen::Vector2d& com_vel, const RecoveryParams& p);

  /// The step whose foot lifts at the next Tick() (its single support
  /// starts then, with a swing), or null.
  const Footstep* lifting_next() const;
  /// The event-driven stop (push_recovery.h, stop_wait): the step that
  /// lifts at the next Tick() lifts `ticks` later, and everything after it
  /// (its landing, the later steps, the end shift) moves as late. The
  /// reference holds its value at the lift (the stance foot's ZMP point,
  /// where the step's single support held it) for those ticks: continuous,
  /// inside the stance sole, and unchanged for the step's single support
  /// ahead (it first differs where the step's single support ended). False
  /// (nothing changed) when no step lifts at the next tick.
  bool DelayLift(std::int64_t ticks);
  /// The step whose foot lands at the next Tick() (its shift of weight
  /// follows), or null.
  const Footstep* landing_next() const;
  /// The event-driven stop's other wait: the foot that lands at the next
  /// Tick() lands `ticks` later (the end of its swing stretched: it is a
  /// hair above its landing, which no longer moves), the shift of weight
  /// onto it and everything after it as late; the reference
  /// holds on the stance foot's ZMP point meanwhile (its single support
  /// lasts longer: continuous, inside the stance sole). False (nothing
  /// changed) when no foot lands at the next tick.
  bool DelayShift(std::int64_t ticks);
  /// The plan's CoM state becomes the measured CoM and velocity (plan
  /// frame), its acceleration such that its ZMP is the reference's now: the
  /// preview plans on from the measured state.
  void Reanchor(const Eigen::Vector2d& com, const Eigen::Vector2d& com_vel) { SetComState(com, com_vel); }

  /// True when no step is scheduled or running and the end shift is over.
  bool standing() const;
  /// Standing and the planned CoM at rest over the reference ZMP: within
  /// `tolerance` (m) of it and slower than `tolerance` per second. The
  /// preview's CoM settles a few tenths of a second after the last shift of
  /// weight ends (standing() turns true).
  bool settled(double tolerance = 1e-3) const;
  /// Steps scheduled but not yet started (the one in the air excluded).
  int unstarted_steps() const;
  /// Time from now until the last scheduled step lands, s (0 when none is ahead).
  double planned_ahead() const;
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
  const Pose2& final_centre() const { return steps_.empty() ? rest_centre_ : steps_.back().centre; }
  /// Steps whose swing has started since construction.
  int started_steps() const { return started_; }
  /// The feet's support polygon now contains p (m)? For tests: a foot's
  /// sole rectangle, or in double support the convex hull of both.
  bool InSupport(const Eigen::Vector2d& p, double margin = 0) const;
  /// That polygon's corners, counter-clockwise, into `out`; returns how many.
  int SupportPolygon(std::array<Eigen::Vector2d, 16>& out) const;
  /// Time until the foot in the air lands, s; 0 in double support.
  double time_to_landing() const;
  /// The step of the foot in the air (its landing), or null in double support.
  const Footstep* swing_step() const {
    const Scheduled* s = Swinging();
    return s && s->swing ? &s->step : nullptr;
  }
  const GaitParams& gait() const { return g_; }
  double time() const { return static_cast<double>(tick_) * tick_s_; }

 private:
  enum class Kind : std::uint8_t { kHold, kShift, kSingle, kEnd };
  struct Phase {
    std::int64_t start = 0, end = 0;  // ticks [start, end)
    Eigen::Vector2d from = Eigen::Vector2d::Zero(), to = Eigen::Vector2d::Zero();
    Kind kind = Kind::kHold;
    int next = -1;  // the side that swings after this phase ends, -1: free
  };
  struct Scheduled {
    Footstep step;
    Pose2 centre;
    Pose2 from;                        // the swing foot before the step
    Pose2 stance;                      // the other foot during the step
    std::int64_t start = 0, land = 0;  // single support [start, land)
    bool swing = true;                 // false: the foot stays (a stop with the feet side by side)
    Pose2 planned;                     // step.pose before AdjustLanding
    std::int64_t retimed = -1;         // Regenerate landed it sooner at this tick (-1: never)
    double s_retimed = 0;              // the swing's progress (0..1) then
    bool captured = false;             // CaptureStop moved it from `uncaptured`
    bool tidy = false;                 // CaptureStop's step bringing the other foot alongside after
    Pose2 uncaptured;
  };
  Eigen::Vector2d ZmpPoint(const Pose2& foot) const;
  Eigen::Vector2d ZmpAt(std::int64_t tick) const;
  int PhaseAt(std::int64_t tick) const;  // index of the phase holding tick, or -1 (before) / size (after)
  std::int64_t CutTick(std::int64_t t) const;
  std::int64_t AppendTick() const;
  Splice SpliceAt(std::int64_t t) const;
  void Cut(std::int64_t t);
  void Prune();
  void AddPhase(std::int64_t ticks, const Eigen::Vector2d& to, Kind kind, int next);
  // The first `fast` steps with single and double support of ss and ds
  // ticks; the first step's stance ZMP `first_offset` from its point.
  void AppendAt(std::int64_t t, const std::vector<Footstep>& steps, const std::vector<Pose2>& centres,
                int fast = 0, std::int64_t ss = 0, std::int64_t ds = 0,
                const Eigen::Vector2d& first_offset = Eigen::Vector2d::Zero());
  void UpdateFeet();
  double SwingProgress(const Scheduled& s) const;  // 0 at lift-off .. 1 at landing
  void SetComState(const Eigen::Vector2d& com, const Eigen::Vector2d& com_vel);
  Eigen::Vector2d NominalDcm() const;
  // CaptureStop with step k as the stop's last (the later ones dropped); false: q did not fit.
  bool CaptureWith(size_t k, const Eigen::Vector2d& com, const Eigen::Vector2d& com_vel,
                   const RecoveryParams& rp);
  // The DCM at tick `at` of a pendulum whose DCM is xi0 now and whose ZMP is the reference's.
  Eigen::Vector2d DcmAt(std::int64_t at, const Eigen::Vector2d& xi0) const;
  // A step in the air within `late` ticks (or the last tenth of its move) of its landing.
  bool TooLate(const Scheduled& st, std::int64_t late) const;
  // The phase j (holding now) ends now at `p_now`; the later ones are dropped.
  void TruncateNow(int j, const Eigen::Vector2d& p_now);
  // Moves the landing of `st` by `by` (m) at tick `land`; in the air, the foot goes on from where it is.
  void MoveLanding(Scheduled& st, const Eigen::Vector2d& by, std::int64_t land);
  void Rebuild(size_t k, std::int64_t land, std::int64_t lift, const Eigen::Vector2d& u,
               const std::vector<Eigen::Vector2d>& shift, const RecoveryParams& rp);
  const Scheduled* Swinging() const;                    // the step in single support now, or null
  bool DelayFrom(std::int64_t at, std::int64_t ticks);  // DelayLift's and DelayShift's move

  GaitParams g_;
  double tick_s_;
  int every_;
  double gravity_;
  std::int64_t ss_ticks_, ds_ticks_, start_ticks_, end_ticks_, lead_ticks_;
  ZmpPreview px_, py_;
  std::vector<double> future_x_, future_y_;
  Eigen::Vector3d cx_ = Eigen::Vector3d::Zero(), cy_ = Eigen::Vector3d::Zero();
  double ux_ = 0, uy_ = 0;
  Eigen::Vector3d sample_x_ = Eigen::Vector3d::Zero(), sample_y_ = Eigen::Vector3d::Zero();
  std::int64_t tick_ = 0;
  std::vector<Phase> phases_;     // contiguous; never empty
  std::vector<Scheduled> steps_;  // in order; landed ones pruned when planning
  Pose2 rest_[2];                 // the feet after the pruned steps
  Pose2 rest_centre_;             // their stance centre
  Pose2 foot_[2];
  double height_[2] = {0, 0};
  int started_ = 0;
};

/// A foot's sole rectangle, counter-clockwise from the front left corner.
std::array<Eigen::Vector2d, 4> Corners(const Pose2& foot, const GaitParams& g);
/// The convex hull of two feet's soles, counter-clockwise, into `hull`; returns how many corners.
int HullOfSoles(const Pose2& a, const Pose2& b, const GaitParams& g, std::array<Eigen::Vector2d, 16>& hull);
/// Point-in-convex-polygon test helper: the sole rectangle of a foot.
bool InFoot(const Pose2& foot, const GaitParams& g, const Eigen::Vector2d& p, double margin);

}  // namespace robotalk::walking
