// The `ode` driver: any RobotModel simulated with the Open Dynamics Engine.
// One ODE body per link (links joined by fixed joints fused into one body,
// massless ones given a small virtual mass), hinge/slider chains per joint
// with the model's limits, collision shapes from the URDF against a ground
// plane, gravity. Joints are servoed by ODE velocity motors bounded by the
// effort limits (control-frame set-points through inverse kinematics); a
// differential base is driven through its wheel joints; a floating or
// holonomic first root is moved kinematically, or with walk=true a humanoid
// walks (the base is one strategy chosen at construction). The physics steps
// at a fixed rate on its own simulated time. docs/ode_sim.md describes the
// physics mapping, controllers, gains and tolerances.
//
// Threading contract (driver.h): every method is called from one thread, the
// server's RobotDaemon; the class has no locks and is not thread-safe. ODE's
// per-thread data is allocated in whichever thread calls first. Per-dof
// buffers are allocated in the constructor; Update()/ReadState() allocate
// nothing of their own (ODE's step uses its internal arenas); Execute()
// allocates only for reply messages and, for FRAME_SETPOINT (solved by
// InverseKinematics from the measured state), the Jacobian that
// Kinematics::FrameJacobian returns on each of at most 200 IK iterations.
//
// Copy/move: neither (owns ODE handles behind a private implementation).
#pragma once

#include "collision_shapes.h"
#include "ode_walk_status.h"
#include "robotalk/driver.h"

#include <chrono>
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace robotalk {

/// Options of the ode driver; as key=value strings they are parsed by FromMap().
struct OdeDriverOptions {
  /// Physics rate, steps per simulated second. Key "step_hz", > 0.
  double step_hz = 1000;
  /// Period at which the RobotDaemon should call Update(). Key "period_ms", > 0.
  Duration period = std::chrono::milliseconds(10);
  /// Gravity, m/s² along -z. Key "gravity", >= 0.
  double gravity = 9.81;
  /// Ground friction coefficient (contacts of caster links use 0). Key "friction", >= 0.
  double friction = 1.0;
  /// Seed of ODE's random numbers (used by the quickstep solver). Key "seed", integer.
  std::uint32_t seed = 1;
  /// "step" (dWorldStep, exact LCP, default) or "quickstep" (iterative). Key "solver".
  std::string solver = "step";
  /// Set-point gain: motor velocity = kp * (target - q), 1/s. Key "kp", > 0.
  double kp = 20.0;
  /// Speed of dofs whose velocity limit is infinite, rad/s or m/s. Key "default_velocity", > 0.
  double default_velocity = 1.0;
  /// Motor force of dofs whose effort limit is infinite, N·m or N. Key "default_effort", > 0.
  double default_effort = 200.0;
  /// Largest base speed, m/s. Key "base_max_v", > 0.
  double base_max_v = 0.7;
  /// Largest base yaw rate, rad/s. Key "base_max_omega", > 0.
  double base_max_omega = 2.0;
  /// A GOTO succeeds this close to its goal, m. Key "goto_tolerance", > 0.
  double goto_tolerance = 0.02;
  /// ... and this close to its heading, rad. Key "goto_heading_tolerance", > 0.
  double goto_heading_tolerance = 0.02;
  /// Wheel joints of a differential base. Keys "left_wheel", "right_wheel".
  std::string left_wheel = "left_wheel_joint";
  std::string right_wheel = "right_wheel_joint";
  /// Wheel radius, m; 0 = from the wheel's collision cylinder/sphere, else the
  /// wheel joint's height above the ground. Key "wheel_radius", >= 0.
  double wheel_radius = 0;
  /// Distance between the wheels, m; 0 = between the wheel joints' origins.
  /// Key "wheel_separation", >= 0.
  double wheel_separation = 0;
  /// Links whose ground contacts are frictionless (ball casters). Key
  /// "casters", link names separated by '+'; "" for none.
  std::vector<std::string> casters = {"caster"};
  /// Overrides the first root's base type ("fixed", "differential",
  /// "holonomic", "floating"); empty = the model's. Key "base".
  std::string base;
  /// Import option: merge massless chains (UrdfImportOptions). Key "merge_chains".
  bool merge_chains = false;
  /// Most simulated time one Update() catches up, ms; beyond it the simulation
  /// drops time (counted by dropped_time()). Key "max_catchup_ms", > 0.
  double max_catchup_ms = 100;
  /// Mass of massless bodies (virtual), kg. Key "virtual_mass", > 0.
  double virtual_mass = 0.05;
  /// Gait of a floating base while it moves: hip and knee pitch joints (1 dof)
  /// of each leg, '+'-separated "left_hip+left_knee+right_hip+right_knee";
  /// empty = guessed from common names. Key "gait_joints".
  std::string gait_joints;
  /// A floating base with feet (a box sole on each of left_foot/right_foot)
  /// walks on physics: ZMP preview plan, leg IK, fall detection
  /// (docs/ode_sim.md, "Walking"). A model that cannot walk moves its root
  /// kinematically and says why (GOTO/SETSPEED answers, one line on stderr);
  /// with solver=quickstep the driver refuses walking (Error). false
  /// (default) = the root moves kinematically (the scripted gait). Key "walk".
  bool walk = false;
  /// With walk=true: the DCM stabilizer closes the balance loop from the
  /// measured CoM and contact forces (docs/ode_sim.md, "Balance feedback");
  /// it stands down while a push's stop holds. On by default since the
  /// fourteenth session, measured against the open loop (false) on one
  /// build: the phase sweep 0 falls of 505, the walking push sweep no worse
  /// (122 against 124 of 384, McNemar z -0.29), the pushed GOTO 8 falls of
  /// 42 against 9, the 20 seeded goals 20/20 with end errors 0.6 mm; it
  /// keeps a walker up through an arm swing that topples the open loop
  /// (docs/ode_sim.md, "The default decided on measured figures"). Key
  /// "stabilizer".
  bool stabilizer = true;
  /// With the stabilizer: also move the foot in the air toward the capture
  /// point when the ankles saturate. Measured to make walking pushes worse
  /// (docs/ode_sim.md, "Balance feedback"), so off by default. Key "step_adjustment".
  bool step_adjustment = false;
  /// With walk=true: push recovery (walking/push_recovery.h; docs/ode_sim.md,
  /// "Pushes and disturbances"): a push the DCM estimator reads as more than
  /// 0.1 m/s stops the walk and the robot stands 3 s before it walks on; when
  /// the measured DCM leaves the plan's by more than 7 cm the walking pattern
  /// is also regenerated from the measured CoM state. On by default:
  /// measured better or equal in all 8 push directions, with the 20-goal
  /// benchmark and the phase sweep unchanged. Key "push_recovery".
  bool push_recovery = true;
  /// With push_recovery: the capture stop (walking/push_recovery.h,
  /// RecoveryParams::capture_stop; docs/ode_sim.md, "Pushes and
  /// disturbances"): the stop's last step lands where the measured DCM is
  /// caught, the plan re-anchored on the measured CoM state, in place of the
  /// regeneration until that step lands. Key "push_capture".
  bool push_capture = false;
  /// With push_recovery: a foot in the air moved by the regeneration lands
  /// at most this far per second of its swing's move left from where its
  /// swing has it now (RecoveryParams::swing_reach; docs/ode_sim.md, "Pushes
  /// and disturbances"), m/s; 0: off (the regenerations' moves then add up
  /// beyond what the legs follow). 1 m/s by default: measured better or
  /// equal in all 16 cells of the push sweep (seeds 1 and 2), the traces
  /// showing the moved landing reached. Key "push_swing_reach".
  double push_swing_reach = 1.0;
  /// With push_recovery: a step the regeneration moves before it lifts (the
  /// next to lift and the ones after it) lands at most this far per second
  /// of its swing's horizontal move from where its foot stands before it
  /// (RecoveryParams::lift_reach; docs/ode_sim.md, "Why the walker falls at
  /// a quarter of the bound"), m/s; 0: off (the default). Key "push_lift_reach".
  double push_lift_reach = 0;
  /// With push_recovery: the regeneration's footholds during the push's
  /// stop (RecoveryParams::stop_feet; docs/ode_sim.md, "Pushes and
  /// disturbances"): "move" as walking, "keep" the stop's landings stay
  /// where and when the stop put them, "still" no regeneration during the
  /// stop. Key "push_stop_feet".
  std::string push_stop_feet = "move";
  /// With push_recovery: balance feedback only while a push's stop holds
  /// (from the stop until the walk goes on; docs/ode_sim.md, "Pushes and
  /// disturbances"): "off" none, or any of "damping" (foot damping),
  /// "stabilizer" (the DCM stabilizer) and "forces" (foot force difference
  /// control in double support, walking/foot_damping.h) joined by '+';
  /// "both" is damping+stabilizer. Afterwards their offsets return to the
  /// plan (1 s, 0.5 s, 1 s). foot_damping, on anyway, stays on; the
  /// "stabilizer" part (or "both") with stabilizer=true is refused (it would
  /// mean nothing); a value other than "off" without push_recovery is
  /// refused. Off by default: "forces", measured better or equal in all 8
  /// directions at both seeds of the push sweep, is not shown by its traces
  /// to be the cause (its height stays under 1 mm; the runs diverge
  /// chaotically), so it stays an option. Key "push_balance".
  std::string push_balance = "off";
  /// With push_recovery: step timing adaptation with step location
  /// (walking/step_timing.h, RecoveryParams::step_timing; docs/ode_sim.md,
  /// "Earlier and faster capture steps"): "off"; "push": from the push's
  /// reading until a re-planned step lands, a step in the air whose place
  /// alone cannot catch the DCM lands sooner, where the DCM needs, the next
  /// steps at the fast timing (otherwise the regeneration as ever);
  /// "threshold": instead whenever the DCM error passes the regeneration's
  /// threshold with a foot in the air (in place of the regeneration's
  /// step); "always": both. Off: measured no better on ODE. A value other
  /// than "off" without push_recovery is refused. Key "push_step_timing".
  std::string push_step_timing = "off";
  /// With push_recovery: the soonest a foot in the air may land after its
  /// lift-off when the regeneration or the step timing lands it sooner
  /// (RecoveryParams::min_swing), s. Key "push_min_swing".
  double push_min_swing = 0.35;
  /// With push_recovery: the event-driven stop (RecoveryParams::stop_wait;
  /// docs/ode_sim.md, "The event-driven stop"): while a push's stop holds, a
  /// step's foot lifts only once the foot it leaves the weight on carries
  /// 0.8 of the weight and the measured DCM is inside that sole, waiting at
  /// most this long per lift, then the plan goes on from the measured CoM
  /// state; s, 0: off (the timed stop; the default: measured, the walking
  /// push sweep is worse with it). Key "push_stop_wait".
  double push_stop_wait = 0;
  /// With push_stop_wait: the shift of weight onto a landed foot also waits
  /// (at most push_stop_wait) until that foot carries 0.15 of the weight
  /// (RecoveryParams::touch_share); off by default (measured worse:
  /// docs/ode_sim.md, "The event-driven stop"). Key "push_stop_land".
  bool push_stop_land = false;
  /// With walk=true: foot damping (walking/foot_damping.h; docs/ode_sim.md,
  /// "Balance feedback", "Foot damping"): each foot's ankle roll and pitch
  /// yield to the error between its measured and desired centre of pressure
  /// (the plan's ZMP, or the stabilizer's command, split between the feet),
  /// and a landing foot is compliant until loaded. Off by default:
  /// measured, it halves the centre of pressure's median error from the
  /// plan and survives larger walking pushes in four of eight directions,
  /// but one direction fell at a smaller push and the walking arm swing
  /// still topples it without the stabilizer. Key "foot_damping".
  bool foot_damping = false;
  /// With walk=true, the gait (docs/ode_sim.md, "Walking"): "fast" (default)
  /// derives step length, duration and turn from the model's legs
  /// (walking/gait_limits.h); "slow" is the earlier 0.10 m / 1.1 s gait
  /// (0.09 m/s). Key "gait".
  std::string gait = "fast";
  /// Overrides of the chosen gait where the model cannot say (0 = the
  /// gait's own): per step step_length, step_back, step_side (m),
  /// step_yaw (rad); single_support, double_support (s); step_height (m).
  /// Keys of the same names; values > 0.
  struct GaitOverrides {
    double step_length = 0, step_back = 0, step_side = 0, step_yaw = 0;
    double single_support = 0, double_support = 0, step_height = 0;
  } gait_overrides;

  /// Parses DriverConfig::options. Throws Error naming an unknown key (and the
  /// known ones) or a bad value: "ode driver: option step_hz='0': expected a rate > 0 (Hz)".
  static OdeDriverOptions FromMap(const std::map<std::string, std::string>& options);
  /// Throws Error naming the first field that is out of range.
  void Validate() const;
};

class OdeDriver final : public Driver {
 public:
  /// Builds the simulation. `shapes` are the model's collision shapes
  /// (LoadCollisionShapes); without them nothing touches the ground. Joints
  /// start at q = 0 clamped into the limits; a mobile first root is placed so
  /// that its lowest shape rests on the ground. Throws Error for bad options,
  /// a base type override that is unknown, or a differential base whose wheel
  /// joints are not in the model.
  OdeDriver(RobotModel model, const OdeDriverOptions& options = {}, std::vector<CollisionShape> shapes = {});
  ~OdeDriver() override;
  OdeDriver(const OdeDriver&) = delete;
  OdeDriver& operator=(const OdeDriver&) = delete;

  const RobotModel& model() const override;
  Duration period() const override;

  /// Advances the simulation to `now` first, then starts `command`.
  DriverResult Execute(const DriverCommand& command, TimePoint now,
                       std::vector<Completion>& completed) override;
  /// Advances the simulation to `now`, then servos the joint along the
  /// reference: PD on position with velocity feed-forward at every physics
  /// step (joint_servos.h). A leg the walking controller drives answers NA.
  DriverResult Track(const JointReference& reference, TimePoint now,
                     std::vector<Completion>& completed) override;
  /// Advances the simulation to `now`, then drives the base along the
  /// reference: a wheeled or kinematic root runs, at every physics step,
  /// the reference's twist advanced by its rate (for at most one control
  /// period). A walking humanoid answers NA (its step planner changes speed
  /// one step at a time: send its SETSPEED in a step package).
  DriverResult TrackBase(const BaseReference& reference, TimePoint now,
                         std::vector<Completion>& completed) override;
  /// Steps the physics as many fixed steps as fit up to `now` (at most
  /// max_catchup_ms of them); the first call only sets the time base.
  void Update(TimePoint now, std::vector<Completion>& completed) override;
  void ReadState(RobotState& state) const override;
  void Stop(TimePoint now, std::vector<Completion>& interrupted) override;
  /// The scope's joints stop and hold; with the base, the base (a walking
  /// humanoid's walk) stops and a GOTO in progress completes INTERRUPTED.
  void StopOnly(const StopScope& scope, TimePoint now, std::vector<Completion>& interrupted) override;
  void Halt(std::vector<Completion>& interrupted) override;
  void Resume() override;
  /// A walking humanoid that fell: "the robot has fallen (torso tilt X rad)"
  /// (the server halts it and holds it in panic); "" otherwise.
  std::string_view Fault() const override;

  /// As fast as possible: `n` fixed steps now, whatever the clock says (the
  /// simulated time moves on by n steps). Completions go to `completed`.
  void Step(int n, std::vector<Completion>& completed);
  /// Steps until the simulated time reaches `t`, without the catch-up limit.
  void AdvanceTo(TimePoint t, std::vector<Completion>& completed);
  /// The simulated time (after the first Update/Execute/Step).
  TimePoint sim_time() const;
  /// Simulated time dropped because Update() fell behind by more than max_catchup_ms.
  Duration dropped_time() const;
  /// The walking controller's status (docs/ode_sim.md, "Walking"); nullopt
  /// when the robot does not walk (not a floating humanoid, or walk=false).
  std::optional<walking::WalkStatus> walk_status() const;
  /// World pose of a link's frame, from the physics.
  Eigen::Isometry3d LinkPose(int link) const;
  /// Test hook (issue 26): pushes the first root (a humanoid's pelvis) at its
  /// centre of mass with `force` (N, world frame) during the next `duration`
  /// of simulated time, an impulse of force x duration. No command, option
  /// or server path reaches it: tests and robotalk-walk-sweep --push call it.
  void PushForTesting(const Eigen::Vector3d& force, Duration duration);
  /// Bodies, geoms and fused links of the simulation (for docs and tests).
  struct Stats {
    int bodies = 0, geoms = 0, fused_links = 0, mesh_boxes = 0, skipped_meshes = 0;
    std::int64_t steps = 0;
  };
  Stats stats() const;

 private:
  class Impl;
  std::unique_ptr<Impl> impl_;
};

/// Registers "ode": loads DriverConfig::urdf_path with LoadUrdfFile (renamed to
/// DriverConfig::robot_name) and its collision shapes, options parsed by
/// OdeDriverOptions::FromMap. Throws Error (UrdfError for the file).
void RegisterOdeDriver(DriverRegistry& registry);

}  // namespace robotalk
