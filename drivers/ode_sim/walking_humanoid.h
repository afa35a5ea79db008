// The ode driver's walking controller for a humanoid on a floating base
// (docs/ode_sim.md, "Walking"): GOTO, SETSPEED, STOP and panic as steps of
// a ZMP-preview walking pattern (walking/walk_pattern.h), whole-leg joint
// targets from InverseKinematics (walking/leg_ik.h) tracked by the ODE
// hinge motors at every physics step, and fall detection. The root is a
// free ODE body: the robot stands on its contacts and can fall.
//
// Frames: the pattern lives in its own planar frame; each plan maps a goal
// from the world into it with the pelvis pose measured at planning time
// (slip and tracking errors make the two drift apart, which the GOTO's
// closed loop corrects by re-planning from the measured pose).
//
// Threading: the driver's one thread. Allocation: buffers in Create();
// planning (Goto, SetSpeed) allocates the step list; Control() allocates
// only what InverseKinematics::Solve does and completion messages.
#pragma once

#include "ode_world.h"
#include "robotalk/driver.h"
#include "walking/leg_ik.h"
#include "walking/walk_pattern.h"
#include "walking/walk_status.h"

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace robotalk::ode_detail {

class WalkingHumanoid {
 public:
  /// Motor gain of the leg servos: v = qd_ref + kKp (q_ref - q), 1/s.
  static constexpr double kKp = 100.0;
  /// Torso tilt beyond which the robot counts as fallen, rad.
  static constexpr double kFallTilt = 0.6;
  /// GOTO: success within these (m, rad), as the issue asks; re-plans at most kRetries times.
  static constexpr double kTolerance = 0.05, kHeadingTolerance = 0.05;
  static constexpr int kRetries = 4;
  /// During a GOTO, re-plan from the measured pose every this many steps.
  static constexpr int kReplanSteps = 4;
  /// Pelvis shift per metre of divergent-component error (CoM + CoM rate / omega) and its bound, m.
  static constexpr double kBalanceGain = 1.0, kBalanceLimit = 0.04;

  /// The controller if `model` can walk: a floating first root and two feet
  /// found by name (left_foot/right_foot, l_foot/r_foot) with a box
  /// collision shape each; else nullptr and *why says what is missing.
  static std::unique_ptr<WalkingHumanoid> Create(const RobotModel& model,
                                                 const std::vector<CollisionShape>& shapes, double gravity,
                                                 double step, std::string* why);
  /// Binds the world (after the driver built it) and plans the stance.
  void Attach(OdeWorld* world, const Eigen::VectorXd& vmax, const Eigen::VectorXd& fmax);

  /// Per dof: true if the walking controller drives it (the leg dofs).
  bool Owns(Eigen::Index dof) const { return owned_[static_cast<size_t>(dof)] != 0; }
  bool busy() const { return mode_ == Mode::kGoto; }
  bool fallen() const { return fallen_; }

  DriverResult Goto(const DriverCommand& c);
  DriverResult SetSpeed(const DriverCommand& c);
  /// STOP (and panic): no new steps; the step in the air and one more end
  /// in double support. A running GOTO completes INTERRUPTED with `why`.
  void Stop(const std::string& why, std::vector<Completion>& completed);
  /// One physics step's control: the pattern, IK, motors, fall check, GOTO completion.
  void Control(std::vector<Completion>& completed);
  walking::WalkStatus status() const;

 private:
  enum class Mode : std::uint8_t { kIdle, kGoto, kSpeed };
  WalkingHumanoid(const RobotModel& model, std::array<int, 2> feet, double sole_z,
                  const walking::GaitParams& g, double gravity, double step);
  walking::Pose2 MeasuredPelvis() const;
  walking::Pose2 ToPlan(const walking::Pose2& world) const;
  walking::Pose2 ToWorld(const walking::Pose2& plan) const;
  void MapFrames();
  void PlanGoto();
  void KeepSpeedStepsQueued();
  void FinishGoto(std::vector<Completion>& completed);
  void DesiredPelvis(Eigen::Isometry3d* pelvis, std::array<Eigen::Isometry3d, 2>* soles) const;

  const RobotModel& model_;
  walking::GaitParams g_;
  walking::WalkPattern pattern_;
  mutable walking::LegIk ik_;  // status() computes the measured CoM with its kinematics
  OdeWorld* world_ = nullptr;
  double step_;
  std::array<int, 2> feet_;
  std::vector<std::uint8_t> owned_;
  Eigen::VectorXd vmax_, fmax_;
  Eigen::VectorXd q_ref_, q_prev_, q_start_, q_stance_;
  Eigen::Vector3d com_in_pelvis_ = Eigen::Vector3d::Zero();
  double pelvis_z_ = 0;
  std::int64_t tick_ = 0, settle_ticks_ = 0;
  // Plan frame -> world (planar), set when a plan is made.
  walking::Pose2 plan_to_world_;
  Mode mode_ = Mode::kIdle;
  CommandId goto_id_ = 0;
  walking::Pose2 goal_;  // world
  int tries_ = 0;
  int replanned_at_ = 0;               // pattern_.started_steps() at the last plan
  double v_ = 0, vy_ = 0, omega_ = 0;  // SETSPEED per second
  bool fallen_ = false;
  double tilt_ = 0;
  // Balance: the measured CoM's (and divergent component's) error against the
  // plan, both relative to the support foot, moves the pelvis (kBalanceGain).
  Eigen::Vector2d balance_ = Eigen::Vector2d::Zero(), err_prev_ = Eigen::Vector2d::Zero();
  Eigen::Vector2d err_rate_ = Eigen::Vector2d::Zero();
  walking::Side support_prev_ = walking::Side::kLeft;
  double omega_lipm_ = 3.7;  // sqrt(g / zc), 1/s
  void Balance();
};

}  // namespace robotalk::ode_detail
