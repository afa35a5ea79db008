// The ode driver's fixed, wheeled and kinematic bases and the choice among
// them (base_controller.h); the walking base is walking_humanoid.cpp.
// docs/ode_sim.md, "Base", describes their behaviour.
#include "base_controller.h"
#include "robotalk/error.h"
#include "robotalk/kinematics.h"
#include "robotalk/log_writer.h"
#include "walking_humanoid.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <utility>

namespace robotalk::ode_detail {

using driver_support::Answer;
using driver_support::Num;
using driver_support::Quote;

walking::Pose2 RootPose2(const OdeWorld& world, const RobotModel& model) {
  const Eigen::Isometry3d p = world.LinkPose(model.roots().front().link);
  const Eigen::Vector3d fwd = p.linear().col(0);
  return {p.translation().x(), p.translation().y(), std::atan2(fwd.y(), fwd.x())};
}

Twist2 RootTwist(const OdeWorld& world, const RobotModel& model) {
  const int root = model.roots().front().link;
  return {.v = world.LinkLinearVelocity(root).dot(world.LinkPose(root).linear().col(0)),
          .omega = world.LinkAngularVelocity(root).z()};
}

std::optional<DriverResult> CheckBaseValues(const DriverCommand& c) {
  const CommandTraits& t = Traits(c.type);
  if (ValueCountFits(t, static_cast<std::size_t>(c.num_values), 0)) return std::nullopt;
  return Answer(Signal::kError, std::string(t.name) + ": expected " + ValueCountText(t) + ", got " +
                                    std::to_string(c.num_values));
}

DriverResult BaseController::TrackSpeed(const BaseReference&) {
  return Answer(
      Signal::kNa,
      "SETSPEED: this base plans its own speed changes (a walking humanoid's step planner, one step at a "
      "time): a SETSPEED ramp is not followed; send its SETSPEED frames in a step package");
}

namespace {

// ---------------------------------------------------------------- fixed

// Bolted to the world: GOTO and SETSPEED answer NA.
class FixedBase final : public BaseController {
 public:
  explicit FixedBase(const RobotModel& model) : model_(model) {}
  void Prepare(OdeWorldOptions&, std::vector<CollisionShape>&) override {}
  void Attach(OdeWorld&, JointServos&, const std::vector<CollisionShape>&) override {}
  DriverResult Goto(const DriverCommand& c) override { return Refuse(c); }
  DriverResult SetSpeed(const DriverCommand& c) override { return Refuse(c); }
  DriverResult TrackSpeed(const BaseReference& r) override { return SetSpeed(driver_support::SetSpeedOf(r)); }
  void Stop(const std::string&, std::vector<Completion>&) override {}
  bool Drives(int) const override { return false; }
  std::optional<DriverResult> Release(int, std::string_view) override { return std::nullopt; }
  void Control(std::vector<Completion>&) override {}
  Twist2 twist() const override { return {}; }
  bool moving() const override { return false; }

 private:
  DriverResult Refuse(const DriverCommand& c) const {
    return Answer(Signal::kNa,
                  std::string(ToString(c.type)) + ": robot " + Quote(model_.name()) + " has a fixed base");
  }
  const RobotModel& model_;
};

// ---------------------------------------------------------------- planar

// What the wheeled and the kinematic base share: GOTO closed-loop on the
// measured pose (GotoController) and SETSPEED held until changed; how a
// planar twist moves the robot is theirs (Drive, Brake).
class PlanarBase : public BaseController {
 public:
  PlanarBase(const RobotModel& model, const OdeDriverOptions& options) : model_(model), options_(options) {}

  DriverResult Goto(const DriverCommand& c) override {
    if (auto bad = CheckBaseValues(c)) return *bad;
    if (mode_ == Mode::kGoto) return Answer(Signal::kBusy, "GOTO: GOTO in progress (command " + Id() + ")");
    GotoController::Gains g;
    g.max_v = options_.base_max_v;
    g.max_omega = options_.base_max_omega;
    g.tolerance = options_.goto_tolerance;
    g.heading_tolerance = options_.goto_heading_tolerance;
    goto_.Start(c.values[0], c.values[1], c.values[2], g);
    cmd_ = {};
    const walking::Pose2 at = RootPose2(*world_, model_);
    goto_.Update(at.x, at.y, at.theta);
    if (goto_.done()) {  // already there
      mode_ = Mode::kIdle;
      Brake();
      return Answer(Signal::kSuccess);
    }
    goto_.Start(c.values[0], c.values[1], c.values[2], g);
    mode_ = Mode::kGoto;
    goto_id_ = c.id;
    DriverResult r;
    r.in_progress = true;
    return r;
  }

  DriverResult SetSpeed(const DriverCommand& c) override {
    if (auto bad = CheckBaseValues(c)) return *bad;
    if (mode_ == Mode::kGoto)
      return Answer(Signal::kBusy, "SETSPEED: GOTO in progress (command " + Id() + ")");
    driver_support::BaseTwist t = driver_support::ShapeBaseSpeed(
        c, model_.roots().front().base, options_.base_max_v, options_.base_max_omega);
    Limit(t);
    cmd_ = {t.vx, t.vy, t.omega};
    rate_ = {};
    rate_steps_ = 0;
    mode_ = (t.vx == 0 && t.vy == 0 && t.omega == 0) ? Mode::kIdle : Mode::kSpeed;
    if (mode_ == Mode::kIdle) Brake();
    return t.note.empty() ? Answer(Signal::kSuccess) : Answer(Signal::kModified, "SETSPEED: " + t.note);
  }

  // The ramp's twist now, and its rate: Control() advances the twist along
  // it at every physics step, for at most one control period (the next
  // reference comes by then), so the wheels follow a ramp, not a staircase.
  DriverResult TrackSpeed(const BaseReference& r) override {
    DriverResult result = SetSpeed(driver_support::SetSpeedOf(r));
    if (mode_ == Mode::kSpeed && (result.signal == Signal::kSuccess || result.signal == Signal::kModified)) {
      // Unless the twist was shaped to a limit (then it holds there).
      if (cmd_.vx == r.vx && cmd_.vy == r.vy && cmd_.omega == r.omega) rate_ = {r.ax, r.ay, r.alpha};
    }
    return result;
  }

  void Stop(const std::string& why, std::vector<Completion>& completed) override {
    if (mode_ == Mode::kGoto) {
      completed.push_back(
          Completion{.id = goto_id_, .signal = Signal::kInterrupted, .message = "GOTO: " + why});
    }
    Idle();
    Brake();
  }

  void Control(std::vector<Completion>& completed) override {
    if (mode_ == Mode::kIdle) return;
    const walking::Pose2 at = RootPose2(*world_, model_);
    // A ramp's twist advances along its rate within the control period.
    const double s =
        std::min(static_cast<double>(rate_steps_++) / options_.step_hz, ToSeconds(options_.period));
    Twist2 t{.v = cmd_.vx + rate_.vx * s, .omega = cmd_.omega + rate_.omega * s};
    double vy = cmd_.vy + rate_.vy * s;
    if (mode_ == Mode::kGoto) {
      t = goto_.Update(at.x, at.y, at.theta);
      vy = 0;
      if (goto_.done()) {
        completed.push_back(Reached(goto_id_));
        mode_ = Mode::kIdle;
      }
    }
    Drive(t, vy, at.theta);
    if (mode_ == Mode::kIdle) Brake();  // the GOTO just finished
  }

  Twist2 twist() const override { return RootTwist(*world_, model_); }
  bool moving() const override { return mode_ != Mode::kIdle; }

 protected:
  enum class Mode : std::uint8_t { kIdle, kSpeed, kGoto };

  // SETSPEED's own limits after the common shaping (a note says what changed).
  virtual void Limit(driver_support::BaseTwist& t) const = 0;
  // One step's twist: forward v, lateral vy (body frame), yaw rate; heading theta.
  virtual void Drive(const Twist2& t, double vy, double theta) = 0;
  // Come to rest now.
  virtual void Brake() = 0;
  // The completion of a GOTO that reached its goal.
  virtual Completion Reached(CommandId id) const = 0;
  std::string Id() const { return std::to_string(goto_id_); }
  // No GOTO, no SETSPEED (the actuators are left as they are).
  void Idle() {
    mode_ = Mode::kIdle;
    cmd_ = {};
    rate_ = {};
  }

  const RobotModel& model_;
  const OdeDriverOptions& options_;
  OdeWorld* world_ = nullptr;
  JointServos* servos_ = nullptr;
  Mode mode_ = Mode::kIdle;

 private:
  GotoController goto_;
  CommandId goto_id_ = 0;
  struct Speed {
    double vx = 0, vy = 0, omega = 0;
  };
  Speed cmd_;            // SETSPEED, body frame (m/s, m/s, rad/s)
  Speed rate_;           // a ramp's rate (m/s², m/s², rad/s²); 0 for a SETSPEED
  long rate_steps_ = 0;  // physics steps since the twist was set
};

// ---------------------------------------------------------------- wheels

// A differential base on two wheel joints: SETSPEED v ω sets the wheel
// motors to (v ∓ ω·b/2)/r.
class WheeledBase final : public PlanarBase {
 public:
  using PlanarBase::PlanarBase;

  // A wheel touches the ground at one point: its collision cylinder becomes
  // a sphere of the same radius (a cylinder's rim contacts scrub when the
  // base turns, which widens the effective track by ~15 %).
  void Prepare(OdeWorldOptions& world, std::vector<CollisionShape>& shapes) override {
    world.place_on_ground = true;
    for (const std::string& w : {options_.left_wheel, options_.right_wheel}) {
      const std::optional<int> j = model_.FindJoint(w);
      if (!j) continue;
      const std::string& link = model_.link(model_.joint(*j).child_link).name;
      for (CollisionShape& s : shapes) {
        if (s.link != link || s.kind != CollisionShape::Kind::kCylinder) continue;
        s.kind = CollisionShape::Kind::kSphere;
        s.size = {s.size.x(), 0, 0};
      }
    }
  }

  void Attach(OdeWorld& world, JointServos& servos, const std::vector<CollisionShape>& shapes) override;

  bool Drives(int joint) const override { return IsWheel(joint) && mode_ != Mode::kIdle; }
  std::optional<DriverResult> Release(int joint, std::string_view command) override {
    if (!IsWheel(joint)) return std::nullopt;
    if (mode_ == Mode::kGoto) {
      return Answer(Signal::kBusy, std::string(command) + " " + Quote(model_.joint(joint).name) +
                                       ": the wheel is driven by a GOTO in progress (command " + Id() + ")");
    }
    Idle();  // a wheel command takes the wheels over from SETSPEED
    return std::nullopt;
  }
  void Stop(const std::string& why, std::vector<Completion>& completed) override {
    PlanarBase::Stop(why, completed);
    for (const int d : wheel_dof_) servos_->Hold(d, *world_);
  }

 private:
  bool IsWheel(int joint) const { return joint == wheel_joint_[0] || joint == wheel_joint_[1]; }

  void Limit(driver_support::BaseTwist& t) const override {  // the wheels' own speed limit
    const double b = 0.5 * separation_;
    double k = 1;
    for (int s = 0; s < 2; ++s) {
      const double rate = std::abs((t.vx + (s == 0 ? -b : b) * t.omega) / radius_);
      const double lim = servos_->vmax()[wheel_dof_[s]];
      if (rate > lim) k = std::min(k, lim / rate);
    }
    if (k < 1) {
      t.Note("scaled by " + Num(k) + " to the wheels' velocity limit");
      t.vx *= k;
      t.omega *= k;
    }
  }
  void Drive(const Twist2& t, double, double) override { SetWheels(t.v, t.omega); }
  void Brake() override { SetWheels(0, 0); }
  Completion Reached(CommandId id) const override {
    return {.id = id, .signal = Signal::kSuccess, .message = {}};
  }

  void SetWheels(double v, double omega) {
    const double side[2] = {v - 0.5 * omega * separation_, v + 0.5 * omega * separation_};
    for (int w = 0; w < 2; ++w) servos_->Speed(wheel_dof_[w], side[w] / (radius_ * sign_[w]));
  }

  int wheel_joint_[2] = {-1, -1};  // left, right
  int wheel_dof_[2] = {-1, -1};
  double sign_[2] = {1, 1};
  double radius_ = 0, separation_ = 0;
};

void WheeledBase::Attach(OdeWorld& world, JointServos& servos, const std::vector<CollisionShape>& shapes) {
  world_ = &world;
  servos_ = &servos;
  const std::optional<int> l = model_.FindJoint(options_.left_wheel),
                           r = model_.FindJoint(options_.right_wheel);
  for (const auto& [found, name] : {std::pair{l, options_.left_wheel}, std::pair{r, options_.right_wheel}}) {
    if (!found || model_.joint(*found).dofs.size() != 1 ||
        model_.joint(*found).dofs[0].type != DofType::kRevolute) {
      throw Error("OdeDriver: robot '" + model_.name() +
                  "' has a differential base but no 1-dof revolute wheel joint '" + name +
                  "' (options left_wheel, right_wheel)");
    }
  }
  Kinematics kin(model_);
  const Eigen::Isometry3d root = world.initial_root_pose();
  kin.Update(world.q(), std::vector<Eigen::Isometry3d>{root});
  double y[2];
  for (int w = 0; w < 2; ++w) {
    const int j = w == 0 ? *l : *r;
    const Joint& joint = model_.joint(j);
    wheel_joint_[w] = j;
    wheel_dof_[w] = model_.dof_offset(j);
    const Eigen::Isometry3d frame = kin.link_pose(joint.parent_link) *
                                    Eigen::Translation3d(model_.link(joint.parent_link).com + joint.inboard) *
                                    joint.rest.normalized();
    const Eigen::Vector3d p = root.inverse() * frame.translation();
    const Eigen::Vector3d a = root.linear().transpose() * frame.linear() * joint.dofs[0].axis;
    if (std::abs(a.y()) < 0.5) {
      throw Error("OdeDriver: wheel joint '" + joint.name + "' does not turn about the base's lateral axis");
    }
    sign_[w] = a.y() > 0 ? 1.0 : -1.0;  // forward rolling = rotation about +y of the base
    y[w] = p.y();
    if (radius_ == 0) {
      const std::string& child = model_.link(joint.child_link).name;
      for (const CollisionShape& s : shapes) {
        if (s.link != child) continue;
        if (s.kind == CollisionShape::Kind::kCylinder || s.kind == CollisionShape::Kind::kSphere)
          radius_ = s.size.x();
      }
      if (radius_ == 0) radius_ = frame.translation().z();  // axle height above the ground (z = 0)
    }
  }
  if (y[0] < y[1]) {  // the left wheel is the one at +y
    std::swap(wheel_joint_[0], wheel_joint_[1]);
    std::swap(wheel_dof_[0], wheel_dof_[1]);
    std::swap(sign_[0], sign_[1]);
  }
  if (options_.wheel_radius > 0) radius_ = options_.wheel_radius;
  separation_ = options_.wheel_separation > 0 ? options_.wheel_separation : std::abs(y[0] - y[1]);
  if (radius_ <= 0 || separation_ <= 0) {
    throw Error("OdeDriver: cannot derive the wheel radius or separation of '" + model_.name() +
                "' (options wheel_radius, wheel_separation)");
  }
  for (const int d : wheel_dof_) servos.Speed(d, 0);  // braked at 0
}

// ---------------------------------------------------------------- kinematic root

constexpr double kGaitStride = 0.5;                 // m of root travel per gait cycle
constexpr double kGaitHip = 0.35, kGaitKnee = 0.6;  // rad: gait amplitudes

std::optional<int> FindAny(const RobotModel& m, std::initializer_list<const char*> names) {
  for (const char* n : names) {
    if (auto j = m.FindJoint(n); j && m.joint(*j).dofs.size() == 1) return j;
  }
  return std::nullopt;
}

// A holonomic or floating first root moved by velocity (an ODE kinematic
// body); every answer is MODIFIED. While it moves, a floating humanoid's
// hip-pitch and knee joints follow a sinusoidal gait (the feet touch the
// ground but do not carry the robot): the look of walking, not walking.
class KinematicRoot final : public PlanarBase {
 public:
  /// `no_walk`: why walk=true was not granted ("" when it was not asked).
  KinematicRoot(const RobotModel& model, const OdeDriverOptions& options, double step, std::string no_walk)
      : PlanarBase(model, options), step_(step), no_walk_(std::move(no_walk)) {}

  void Prepare(OdeWorldOptions& world, std::vector<CollisionShape>&) override {
    world.kinematic_first_root = true;
    world.place_on_ground = true;
  }
  void Attach(OdeWorld& world, JointServos& servos, const std::vector<CollisionShape>&) override;
  bool Drives(int) const override { return false; }
  std::optional<DriverResult> Release(int, std::string_view) override { return std::nullopt; }

 private:
  void Limit(driver_support::BaseTwist& t) const override {
    t.Note("the root moves kinematically (" + std::string(ToString(model_.roots().front().base)) + " base" +
           NoWalk() + ")");
  }
  void Drive(const Twist2& t, double vy, double theta) override {
    const double c = std::cos(theta), s = std::sin(theta);
    world_->SetRootVelocity({c * t.v - s * vy, s * t.v + c * vy, 0}, {0, 0, t.omega});
    if (gait_dof_[0] < 0) return;
    phase_ += 2 * std::numbers::pi * std::hypot(t.v, vy) * step_ / kGaitStride;
    const double sn = std::sin(phase_);
    for (int leg = 0; leg < 2; ++leg) {
      const double sl = leg == 0 ? sn : -sn;
      const auto hip = static_cast<Eigen::Index>(gait_dof_[2 * leg]);
      const auto knee = static_cast<Eigen::Index>(gait_dof_[2 * leg + 1]);
      servos_->SetPoint(hip, std::clamp(-kGaitHip * sl, servos_->lower(hip), servos_->upper(hip)));
      servos_->SetPoint(
          knee, std::clamp(kGaitKnee * std::max(0.0, sl), servos_->lower(knee), servos_->upper(knee)));
    }
  }
  void Brake() override { world_->SetRootVelocity(Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()); }
  Completion Reached(CommandId id) const override {
    return {.id = id,
            .signal = Signal::kModified,
            .message = std::string("GOTO: reached by moving the root kinematically (") +
                       ToString(model_.roots().front().base) + " base; " +
                       (gait_dof_[0] >= 0 ? "the legs followed a scripted gait" : "no gait") + NoWalk() +
                       ")"};
  }
  std::string NoWalk() const { return no_walk_.empty() ? "" : "; walk=true ignored: " + no_walk_; }

  double step_;                         // s
  int gait_dof_[4] = {-1, -1, -1, -1};  // left hip, left knee, right hip, right knee
  double phase_ = 0;
  std::string no_walk_;
};

void KinematicRoot::Attach(OdeWorld& world, JointServos& servos, const std::vector<CollisionShape>&) {
  world_ = &world;
  servos_ = &servos;
  std::optional<int> j[4];
  if (!options_.gait_joints.empty()) {
    std::string s = options_.gait_joints;
    for (int k = 0; k < 4; ++k) {
      const size_t plus = s.find('+');
      const std::string name = s.substr(0, plus);
      j[k] = model_.FindJoint(name);
      if (!j[k] || model_.joint(*j[k]).dofs.size() != 1) {
        throw Error("OdeDriver: gait joint '" + name + "' is not a 1-dof joint of '" + model_.name() + "'");
      }
      s = plus == std::string::npos ? "" : s.substr(plus + 1);
    }
  } else {
    j[0] = FindAny(model_, {"l_leg_hpy", "left_hip_pitch", "l_hip_pitch", "LHipPitch"});
    j[1] = FindAny(model_, {"l_leg_kny", "left_knee", "l_knee", "left_knee_pitch", "LKneePitch"});
    j[2] = FindAny(model_, {"r_leg_hpy", "right_hip_pitch", "r_hip_pitch", "RHipPitch"});
    j[3] = FindAny(model_, {"r_leg_kny", "right_knee", "r_knee", "right_knee_pitch", "RKneePitch"});
  }
  for (int k = 0; k < 4; ++k) {
    if (!j[k]) return;  // no gait
  }
  for (int k = 0; k < 4; ++k) gait_dof_[k] = model_.dof_offset(*j[k]);
}

}  // namespace

std::unique_ptr<BaseController> MakeBaseController(const RobotModel& model, const OdeDriverOptions& options,
                                                   const std::vector<CollisionShape>& shapes, double step) {
  switch (model.roots().front().base) {
    case BaseType::kFixed:
      return std::make_unique<FixedBase>(model);
    case BaseType::kDifferential:
      return std::make_unique<WheeledBase>(model, options);
    case BaseType::kFloating:
      if (options.walk) {
        // A model that cannot walk (no feet, no soles) moves kinematically
        // instead: its GOTO/SETSPEED answers say why, and so does one line here
        // (through the process's writer of stderr: one that takes nothing
        // must not keep the server from serving).
        std::string why;
        if (auto walker = WalkingHumanoid::Create(model, shapes, options, step, &why)) {
          LogWriter::Stderr().Write("robotalk ode driver: '" + model.name() + "': walks with " +
                                    walker->gait_said());
          return walker;
        }
        LogWriter::Stderr().Write("robotalk ode driver: '" + model.name() + "': walk=true ignored: " + why +
                                  "; the root moves kinematically");
        return std::make_unique<KinematicRoot>(model, options, step, why);
      }
      [[fallthrough]];
    case BaseType::kHolonomic:
      return std::make_unique<KinematicRoot>(model, options, step, "");
  }
  return std::make_unique<FixedBase>(model);
}

}  // namespace robotalk::ode_detail
