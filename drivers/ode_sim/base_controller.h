// The base of a robot in the ode driver, as a strategy chosen once when the
// driver is built (MakeBaseController), from the first root's base type and
// the options: a fixed base, a differential base on its wheels, a root moved
// kinematically (the legs of a floating base following a scripted gait), or
// a humanoid walking on physics (walking_humanoid.h). The driver's body knows
// nothing else of the base: it hands it GOTO and SETSPEED, asks it before a
// joint command or a scoped stop touches a joint it may drive, runs
// Control() every physics step before the joint servos, and reads its
// motion, fault and walk status into the state.
//
// Threading and allocation as in ode_driver.h: the driver's one thread;
// buffers allocated by Attach(); completions and replies allocate messages.
#pragma once

#include "goto_controller.h"
#include "joint_servos.h"
#include "ode_driver.h"
#include "ode_world.h"

#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace robotalk::ode_detail {

class BaseController {
 public:
  virtual ~BaseController() = default;

  /// Before the world is built: the world options this base needs (a
  /// kinematic first root, placing the robot on the ground) and changes to
  /// its collision shapes.
  virtual void Prepare(OdeWorldOptions& world, std::vector<CollisionShape>& shapes) = 0;
  /// After: binds the world and the joint servos (both outlive the base).
  /// Throws Error naming what the model lacks for this base.
  virtual void Attach(OdeWorld& world, JointServos& servos, const std::vector<CollisionShape>& shapes) = 0;

  /// GOTO x y θ: an answer, or in_progress (the completion follows from
  /// Control() or Stop()). NA on a fixed base.
  virtual DriverResult Goto(const DriverCommand& c) = 0;
  /// SETSPEED v ω or vx vy ω. NA on a fixed base.
  virtual DriverResult SetSpeed(const DriverCommand& c) = 0;
  /// A SETSPEED ramp's reference (Driver::TrackBase), every control period.
  /// Default: NA (a base that plans its own speed changes, the walker's).
  virtual DriverResult TrackSpeed(const BaseReference& reference);
  /// STOP and panic: the base stops; a GOTO in progress completes
  /// INTERRUPTED ("GOTO: " + why).
  virtual void Stop(const std::string& why, std::vector<Completion>& completed) = 0;
  /// The watchdog's scoped stop: Stop() when the scope holds the base.
  virtual void StopOnly(const StopScope& scope, std::vector<Completion>& completed) {
    if (scope.base) Stop("interrupted by STOP", completed);
  }
  /// Whether the base's controller drives `joint` now (a wheel under a GOTO
  /// or SETSPEED, a leg of a walk): a scoped stop leaves it to the base.
  virtual bool Drives(int joint) const = 0;
  /// Before a joint command to `joint`: BUSY (naming `command`) if the base
  /// keeps the joint; else nullopt, and the base lets it go.
  virtual std::optional<DriverResult> Release(int joint, std::string_view command) = 0;
  /// One physics step, before the joint servos: the base's actuators and
  /// the completion of a GOTO.
  virtual void Control(std::vector<Completion>& completed) = 0;

  /// The base's measured speed (0 for a fixed base).
  virtual Twist2 twist() const = 0;
  /// A task or a walk is in progress.
  virtual bool moving() const = 0;
  /// Driver::Fault(): "" unless the base failed (a walking humanoid fell).
  virtual std::string_view fault() const { return {}; }
  /// OdeDriver::walk_status(): nullopt unless the base walks.
  virtual std::optional<walking::WalkStatus> walk_status() const { return std::nullopt; }
};

/// ERROR for a GOTO without 3 values or a SETSPEED without 2 or 3 (the
/// server checks them first: driver.h); nullopt otherwise.
std::optional<DriverResult> CheckBaseValues(const DriverCommand& c);

/// The first root's planar pose and measured speed, from the physics.
walking::Pose2 RootPose2(const OdeWorld& world, const RobotModel& model);
Twist2 RootTwist(const OdeWorld& world, const RobotModel& model);

/// The base of `model`'s first root: fixed, differential (wheel joints from
/// the options), holonomic, or floating — walking if options.walk and the
/// model has feet (WalkingHumanoid::Create), else kinematic. `step` is the
/// physics step, s.
std::unique_ptr<BaseController> MakeBaseController(const RobotModel& model, const OdeDriverOptions& options,
                                                   const std::vector<CollisionShape>& shapes, double step);

}  // namespace robotalk::ode_detail
