// The ode driver's walking controller for a humanoid on a floating base
// (docs/ode_sim.md, "Walking"): GOTO, SETSPEED, STOP and panic as steps of
// a ZMP-preview walking pattern (walking/walk_pattern.h), whole-leg joint
// targets from InverseKinematics (walking/leg_ik.h) tracked by the ODE
// hinge motors at every physics step, optional balance feedback (walking/
// dcm_stabilizer.h: the measured CoM and centre of pressure move the CoM
// reference and the swing foot's landing; options stabilizer,
// step_adjustment; walking/foot_damping.h: the ankles yield to each sole's
// centre-of-pressure error, option foot_damping; push_balance: these and
// foot force difference control only while a push's stop holds), and fall
// detection. The root is a free ODE body: the robot stands on its contacts
// and can fall.
//
// Frames: the pattern lives in its own planar frame; each plan maps a goal
// from the world into it with the support foot's pose measured at planning
// time (if the feet slipped the two would drift apart; the GOTO's closed
// loop re-plans from the measured pose). The soles' contacts are made
// compliant (SoleSpringFor: kSoleStiffness scaled to the model) so that they lie flat on the ground.
//
// It is the walking one of the driver's bases (base_controller.h): it owns
// the leg dofs (the joint servos leave them to it) and answers GOTO,
// SETSPEED, STOP and panic.
//
// Threading: the driver's one thread. Allocation: buffers in Create();
// planning (Goto, SetSpeed) allocates the step list; Control() allocates
// only what InverseKinematics::Solve does and completion messages.
#pragma once

#include "base_controller.h"
#include "ode_walk_status.h"
#include "ode_world.h"
#include "robotalk/driver.h"
#include "walking/dcm_estimator.h"
#include "walking/dcm_stabilizer.h"
#include "walking/foot_damping.h"
#include "walking/leg_ik.h"
#include "walking/push_recovery.h"
#include "walking/walk_pattern.h"

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace robotalk::ode_detail {

class WalkingHumanoid final : public BaseController {
 public:
  /// Motor gain of the leg servos: v = qd_ref + kKp (q_ref - q), 1/s.
  static constexpr double kKp = 100.0;
  /// The soles' ground contacts: a spring-damper per contact point (N/m,
  /// N·s/m), a rubber sole. With ODE's default stiff contacts a sole rests
  /// on two corners (a 0.01 rad tilt lifts the others) and the robot rocks
  /// heel to toe for seconds; its stance foot then turns on one corner.
  /// Here the weight presses each corner ~0.6 mm in, so a sole lies flat on
  /// four contacts, and the damping stops the rocking (docs/ode_sim.md).
  /// Tuned on models/simple_humanoid.urdf: kSoleTunedMass kg, its CoM
  /// kSoleTunedComHeight m up in the stance, box soles kSoleTunedWidth wide;
  /// other models get SoleSpringFor's.
  static constexpr double kSoleStiffness = 2e5, kSoleDamping = 4e3;
  static constexpr double kSoleTunedMass = 52.5, kSoleTunedComHeight = 0.7275, kSoleTunedWidth = 0.12;
  struct SoleSpring {
    double stiffness = kSoleStiffness, damping = kSoleDamping;  ///< per contact, N/m and N·s/m
  };
  /// The sole spring of a model of `mass` (kg) whose CoM stands
  /// `com_height` (m) above its soles under `gravity` (m/s²). The robot
  /// rocking sideways on a sole (a mass m at height h on the rolling
  /// stiffness of four corner springs k, w apart: k w², so ω² = k w² / (m h²)
  /// − g / h) keeps the tuned model's frequency (9.5 rad/s) and damping ratio
  /// on a sole of the tuned width; a narrower sole rolls more easily, as a
  /// rubber pad's would (and the 3 cm soles of OdeWalk.ARobotThatFalls... still
  /// fall). Measured on atlas.urdf (docs/ode_sim.md, "Published humanoids"):
  /// scaled by mass per contact alone (each contact sinking as deep), its
  /// sole was too soft for its 1.17 m high CoM: it rolled onto its outer
  /// edge and fell in the fourth step. Scales within 0.1 % of 1 are 1 (the
  /// tuned model keeps its values exactly).
  static SoleSpring SoleSpringFor(double mass, double com_height, double gravity);
  /// A sole derived from contact points becomes a box this thick (m) above
  /// the sole plane, in place of the points (Prepare()).
  static constexpr double kSoleBoxThickness = 0.02;
  /// A foot's z axis within this (rad) of vertical at the model's zero pose:
  /// its sole (found in the link frame) lies flat.
  static constexpr double kMaxSoleTilt = 0.01;
  /// Torso tilt beyond which the robot counts as fallen, rad.
  static constexpr double kFallTilt = 0.6;
  /// GOTO: success within these (m, rad), as the issue asks; re-plans at most kRetries times.
  static constexpr double kTolerance = 0.05, kHeadingTolerance = 0.05;
  static constexpr int kRetries = 4;
  /// GOTO: the walk ends within these (m, rad) where kRetries re-plans
  /// allow: the feet slip a few mm per step (more on long fast steps), and
  /// a corrective step from the measured pose takes it back.
  static constexpr double kPrecision = 0.005, kHeadingPrecision = 0.01;
  /// A GOTO is judged when the planned CoM has come to rest over the feet:
  /// within this (m) of the reference ZMP and slower than this per second.
  static constexpr double kSettled = 2e-3;
  /// During a GOTO, re-plan from the measured pose every this many steps.
  static constexpr int kReplanSteps = 4;

  /// The controller if `model` can walk: a floating first root and two feet
  /// found by name (left_foot/right_foot, l_foot/r_foot, LFoot/RFoot,
  /// l_ankle/r_ankle), flat at the zero pose, with a sole each (FindSole: a
  /// box, or contact points stood on as their box); else nullptr and *why
  /// says what is missing. The gait's geometry, the CoM height and the sole
  /// spring (SoleSpringFor) come from the model.
  /// Throws Error for a model that can walk with solver=quickstep (it falls there).
  static std::unique_ptr<WalkingHumanoid> Create(const RobotModel& model,
                                                 const std::vector<CollisionShape>& shapes,
                                                 const OdeDriverOptions& options, double step,
                                                 std::string* why);
  /// A free root standing on the ground.
  /// A free root standing on the ground; a foot whose sole was derived from
  /// contact points stands on that sole as a box instead of on the points
  /// (measured on atlas.urdf: as steady, 1.6x faster; docs/ode_sim.md,
  /// "Published humanoids").
  void Prepare(OdeWorldOptions& world, std::vector<CollisionShape>& shapes) override;
  /// Binds the world (after the driver built it), takes the leg dofs from
  /// the joint servos and plans the stance.
  void Attach(OdeWorld& world, JointServos& servos, const std::vector<CollisionShape>& shapes) override;

  /// Per dof: true if the walking controller drives it (the leg dofs).
  bool Owns(Eigen::Index dof) const { return owned_[static_cast<size_t>(dof)] != 0; }
  /// The legs, always.
  bool Drives(int joint) const override;
  /// BUSY for a leg: "the leg is driven by the walking controller".
  std::optional<DriverResult> Release(int joint, std::string_view command) override;

  DriverResult Goto(const DriverCommand& c) override;
  DriverResult SetSpeed(const DriverCommand& c) override;
  /// STOP (and panic): no new steps; the step in the air and one more end
  /// in double support. A running GOTO completes INTERRUPTED with `why`.
  void Stop(const std::string& why, std::vector<Completion>& completed) override;
  /// The walk stops with the base, or when a leg it drives is in the scope
  /// (stopping more than asked is safe).
  void StopOnly(const StopScope& scope, std::vector<Completion>& completed) override;
  /// One physics step's control: the pattern, balance feedback, IK, motors,
  /// fall check, GOTO completion.
  void Control(std::vector<Completion>& completed) override;

  Twist2 twist() const override { return RootTwist(*world_, model_); }
  /// A walk in progress: stepping (the steps and the last shift of weight
  /// of a STOP included), or the start-up's settling into the stance. Not
  /// the legs' balancing sway nor the soles' contact bounce while standing.
  bool moving() const override;
  /// The fall in words, "" before one: "the robot has fallen (torso tilt 0.71 rad)".
  std::string_view fault() const override { return fall_; }
  std::optional<walking::WalkStatus> walk_status() const override { return status(); }
  walking::WalkStatus status() const;
  /// The gait, its geometry (feet, soles, CoM height) from the model.
  const walking::GaitParams& gait() const { return g_; }
  /// Which gait and why, with its steps (the driver's start-up line).
  const std::string& gait_said() const { return gait_said_; }
  /// The soles' contact spring of this model (SoleSpringFor).
  const SoleSpring& sole_spring() const { return sole_spring_; }

 private:
  enum class Mode : std::uint8_t { kIdle, kGoto, kSpeed };
  WalkingHumanoid(const RobotModel& model, std::array<int, 2> feet, std::array<double, 2> sole_z,
                  const walking::GaitParams& g, double gravity, double step);
  walking::Pose2 MeasuredPelvis() const;
  walking::Pose2 MeasuredFoot(
      walking::Side side) const;  ///< the ankle point on the ground and the foot's yaw
  walking::Pose2 ToPlan(const walking::Pose2& world) const;
  walking::Pose2 ToWorld(const walking::Pose2& plan) const;
  void MapFrames();
  void PlanGoto();
  void KeepSpeedStepsQueued();
  void FinishGoto(std::vector<Completion>& completed);
  void DesiredPelvis(Eigen::Isometry3d* pelvis, std::array<Eigen::Isometry3d, 2>* soles) const;

  const RobotModel& model_;
  walking::GaitParams g_;
  std::string gait_said_;
  walking::WalkPattern pattern_;
  mutable walking::LegIk ik_;  // status() computes the measured CoM with its kinematics
  OdeWorld* world_ = nullptr;
  double step_;
  std::array<int, 2> feet_;
  std::vector<std::uint8_t> owned_;
  Eigen::VectorXd vmax_, fmax_;
  Eigen::VectorXd q_ref_, q_prev_, q_start_, q_stance_;  // IK solution, last servo target, start-up, stance
  Eigen::Vector3d com_in_pelvis_ = Eigen::Vector3d::Zero();
  double pelvis_z_ = 0;
  Eigen::Vector2d pelvis_start_ = Eigen::Vector2d::Zero();  // the pelvis at Attach(), world = plan frame
  std::int64_t tick_ = 0, settle_ticks_ = 0, ramp_ticks_ = 1;
  // Plan frame -> world (planar), set when a plan is made.
  walking::Pose2 plan_to_world_;
  Mode mode_ = Mode::kIdle;
  CommandId goto_id_ = 0;
  walking::Pose2 goal_;  // world
  int tries_ = 0;
  int replanned_at_ = 0;               // pattern_.started_steps() at the last plan
  double v_ = 0, vy_ = 0, omega_ = 0;  // SETSPEED per second
  bool fallen_ = false;
  std::string fall_;  // written once, when the fall is detected
  double tilt_ = 0;
  void MeasureContacts();
  void Balance();
  // Balance feedback (options.stabilizer): the DCM stabilizer's ZMP command
  // as an offset of the planned CoM (plan frame), from the measured CoM.
  bool stabilize_ = true;
  bool adjust_steps_ = false;  // options.step_adjustment
  // options.push_balance: foot damping / the stabilizer while a push's stop
  // holds (PushRecovery::holding); stabilizing_ is whether it ran this tick.
  bool push_damping_ = false, push_stabilizer_ = false, stabilizing_ = false;
  bool PushHolding() const { return recovery_ && recovery_->holding(); }
  // push_balance's forces: foot force difference control (walking/foot_damping.h).
  std::optional<walking::ForceDifference> push_forces_;
  /// Its loop rate (1/s) on the sole springs: the leg servos' 100/s is ten times faster.
  static constexpr double kForceRate = 10.0;
  std::optional<walking::DcmStabilizer> dcm_;
  std::optional<walking::ComOffset> com_offset_;
  std::optional<walking::PushRecovery> recovery_;      // options.push_recovery
  std::optional<walking::DcmEstimator> com_estimate_;  // with recovery_: the CoM state it reads
  walking::DcmStabilizer::Output balance_;
  Eigen::Vector2d com_world_prev_ = Eigen::Vector2d::Zero(), com_velocity_ = Eigen::Vector2d::Zero();
  bool zmp_valid_ = false;
  void AdjustStep();
  void GateLift();
  double weight_ = 0;       // N: the model's mass under gravity
  int adjusted_step_ = -1;  // started_steps() of the step AdjustStep() moves
  Eigen::Vector2d step_target_ = Eigen::Vector2d::Zero(), step_applied_ = Eigen::Vector2d::Zero();
  double foot_force_[2] = {0, 0};
  int foot_contacts_[2] = {0, 0};
  double foot_peak_force_[2] = {0, 0};
  // The feet in the loop (options.foot_damping): each foot's measured
  // contact (its frame), its CoP in the world, and where it should press.
  void DampFeet(std::array<Eigen::Isometry3d, 2>* soles);
  std::optional<walking::FootDamping> foot_damping_;  // options.foot_damping or push_balance's damping
  bool damp_feet_ = false;                            // options.foot_damping
  std::array<walking::FootWrench, 2> foot_wrench_;
  std::array<Eigen::Vector2d, 2> foot_cop_{Eigen::Vector2d::Zero(), Eigen::Vector2d::Zero()};  // world
  walking::FootTargets foot_targets_;                       // plan frame's feet
  Eigen::Vector2d zmp_measured_ = Eigen::Vector2d::Zero();  // world
  double tracking_error_ = 0;
  SoleSpring sole_spring_;
  std::array<Sole, 2> soles_;                           // as boxes
  std::array<bool, 2> sole_from_points_{false, false};  // Prepare() replaces the points by the box
};

}  // namespace robotalk::ode_detail
