#include "ode_driver.h"
#include "robotalk/dof_table.h"

#include "ode_driver_impl.h"
#include "robotalk/error.h"
#include "robotalk/kinematics.h"
#include "robotalk/urdf_import.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <utility>

namespace robotalk {

using ode_detail::Answer;
using ode_detail::GotoController;
using ode_detail::Num;
using ode_detail::OdeWorld;
using ode_detail::Twist2;
using ode_detail::WrapAngle;

namespace {

// The model with its first root's base type replaced (option "base").
RobotModel WithBase(RobotModel model, const std::string& base) {
  if (base.empty()) return model;
  std::vector<RootLink> roots(model.roots().begin(), model.roots().end());
  roots.front().base = ParseBaseType(base);
  return RobotModel(model.name(), {model.links().begin(), model.links().end()},
                    {model.joints().begin(), model.joints().end()},
                    {model.frames().begin(), model.frames().end()}, std::move(roots));
}

std::optional<int> FindAny(const RobotModel& m, std::initializer_list<const char*> names) {
  for (const char* n : names) {
    if (auto j = m.FindJoint(n); j && m.joint(*j).dofs.size() == 1) return j;
  }
  return std::nullopt;
}

constexpr double kMovingSpeed = 1e-3;               // rad/s or m/s: below this a dof counts as still
constexpr double kTargetReached = 2e-3;             // rad or m: a set-point counts as reached
constexpr double kGaitStride = 0.5;                 // m of root travel per gait cycle
constexpr double kGaitHip = 0.35, kGaitKnee = 0.6;  // rad: gait amplitudes

}  // namespace

OdeDriver::Impl::Impl(RobotModel model, const OdeDriverOptions& options, std::vector<CollisionShape> shapes)
    : model_(WithBase(std::move(model), options.base)), options_(options), ik_(model_) {
  options_.Validate();
  step_ = FromSeconds(1.0 / options_.step_hz);
  if (step_ <= Duration::zero()) throw Error("OdeDriver: step_hz " + Num(options_.step_hz) + " is too high");
  const int n = model_.num_dofs();
  for (Eigen::VectorXd* v : {&target_, &speed_, &force_}) v->setZero(n);
  root_poses_.assign(model_.roots().size(), Eigen::Isometry3d::Identity());
  // The model's per-dof limits and mimic couplings (one table for the
  // project: robotalk/dof_table.h), with this driver's defaults for limits
  // the model leaves infinite.
  const DofTable dofs(model_);
  lower_ = dofs.lower;
  upper_ = dofs.upper;
  vmax_ = dofs.velocity.unaryExpr([&](double v) { return std::isfinite(v) ? v : options_.default_velocity; });
  fmax_ = dofs.effort.unaryExpr([&](double f) { return std::isfinite(f) ? f : options_.default_effort; });
  leader_ = dofs.mimic_leader;
  mimic_k_ = dofs.mimic_multiplier;
  mimic_c_ = dofs.mimic_offset;
  mode_.assign(static_cast<size_t>(n), Mode::kPosition);
  Eigen::VectorXd q0 = lower_.cwiseMax(0.0).cwiseMin(upper_);  // 0 clamped into the limits
  for (int i = 0; i < n; ++i) {
    const Joint& joint = model_.joint(dofs.joint_of[static_cast<size_t>(i)]);
    if (dofs.is_mimic(i)) {
      mode_[static_cast<size_t>(i)] = Mode::kMimic;
    } else if (joint.servo_types.empty()) {
      mode_[static_cast<size_t>(i)] = Mode::kPassive;
    }
  }
  ApplyMimics(model_, q0);
  target_ = q0;

  const BaseType base = model_.roots().front().base;
  ode_detail::OdeWorldOptions wo;
  wo.step = ToSeconds(step_);
  wo.gravity = options_.gravity;
  wo.friction = options_.friction;
  wo.quickstep = options_.solver == "quickstep";
  wo.virtual_mass = options_.virtual_mass;
  wo.caster_links = options_.casters;
  wo.seed = options_.seed;
  if (base == BaseType::kFloating && options_.walk) {  // walking hook
    walker_ =
        ode_detail::WalkingHumanoid::Create(model_, shapes, options_.gravity, ToSeconds(step_), &walk_why_);
  }
  wo.kinematic_first_root = (base == BaseType::kHolonomic || base == BaseType::kFloating) && !walker_;
  wo.place_on_ground = base != BaseType::kFixed;
  if (base == BaseType::kDifferential) {
    // A wheel touches the ground at one point: its collision cylinder becomes
    // a sphere of the same radius (a cylinder's rim contacts scrub when the
    // base turns, which widens the effective track by ~15 %).
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
  world_ = std::make_unique<OdeWorld>(model_, shapes, wo, q0);
  if (base == BaseType::kDifferential) {
    SetupWheels(shapes);
  } else if (base != BaseType::kFixed) {
    base_kind_ = BaseKind::kKinematic;
    if (walker_) {
      walker_->Attach(world_.get(), vmax_, fmax_);  // walking hook
    } else {
      SetupGait();
    }
  }
}

void OdeDriver::Impl::SetupWheels(const std::vector<CollisionShape>& shapes) {
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
  const Eigen::Isometry3d root = world_->initial_root_pose();
  kin.Update(world_->q(), std::vector<Eigen::Isometry3d>{root});
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
    wheel_sign_[w] = a.y() > 0 ? 1.0 : -1.0;  // forward rolling = rotation about +y of the base
    y[w] = p.y();
    if (wheel_radius_ == 0) {
      const std::string& child = model_.link(joint.child_link).name;
      for (const CollisionShape& s : shapes) {
        if (s.link != child) continue;
        if (s.kind == CollisionShape::Kind::kCylinder || s.kind == CollisionShape::Kind::kSphere)
          wheel_radius_ = s.size.x();
      }
      if (wheel_radius_ == 0)
        wheel_radius_ = frame.translation().z();  // axle height above the ground (z = 0)
    }
  }
  if (y[0] < y[1]) {  // the left wheel is the one at +y
    std::swap(wheel_joint_[0], wheel_joint_[1]);
    std::swap(wheel_dof_[0], wheel_dof_[1]);
    std::swap(wheel_sign_[0], wheel_sign_[1]);
  }
  if (options_.wheel_radius > 0) wheel_radius_ = options_.wheel_radius;
  wheel_separation_ = options_.wheel_separation > 0 ? options_.wheel_separation : std::abs(y[0] - y[1]);
  if (wheel_radius_ <= 0 || wheel_separation_ <= 0) {
    throw Error("OdeDriver: cannot derive the wheel radius or separation of '" + model_.name() +
                "' (options wheel_radius, wheel_separation)");
  }
  base_kind_ = BaseKind::kWheels;
  for (int w = 0; w < 2; ++w) mode_[static_cast<size_t>(wheel_dof_[w])] = Mode::kVelocity;  // braked at 0
}

void OdeDriver::Impl::SetupGait() {
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

// ---------------------------------------------------------------- time

void OdeDriver::Impl::Advance(TimePoint now, bool limit, std::vector<Completion>& completed) {
  if (!origin_) {
    origin_ = now;
    return;
  }
  const TimePoint sim = *origin_ + dropped_ + steps_ * step_;
  if (now <= sim) return;
  std::int64_t n = (now - sim) / step_;
  const auto max_steps = static_cast<std::int64_t>(options_.max_catchup_ms / 1000.0 / ToSeconds(step_)) + 1;
  if (limit && n > max_steps) {  // fell behind in real time: drop the excess
    dropped_ += (n - max_steps) * step_;
    n = max_steps;
  }
  Step(static_cast<int>(n), completed);
}

void OdeDriver::Impl::Step(int n, std::vector<Completion>& completed) {
  for (int s = 0; s < n; ++s) {
    ControlStep(completed);
    world_->Step();
    ++steps_;
  }
}

void OdeDriver::Impl::BasePose(double* x, double* y, double* theta) const {
  const Eigen::Isometry3d p = world_->LinkPose(model_.roots().front().link);
  *x = p.translation().x();
  *y = p.translation().y();
  const Eigen::Vector3d fwd = p.linear().col(0);
  *theta = std::atan2(fwd.y(), fwd.x());
}

void OdeDriver::Impl::SetWheels(double v, double omega) {
  const double side[2] = {v - 0.5 * omega * wheel_separation_, v + 0.5 * omega * wheel_separation_};
  for (int w = 0; w < 2; ++w) {
    const auto i = static_cast<size_t>(wheel_dof_[w]);
    mode_[i] = Mode::kVelocity;
    speed_[static_cast<Eigen::Index>(i)] = side[w] / (wheel_radius_ * wheel_sign_[w]);
  }
}

// The per-step controllers: joint servos, mimics, the base and the gait.
void OdeDriver::Impl::ControlStep(std::vector<Completion>& completed) {
  const Eigen::VectorXd& q = world_->q();
  const Eigen::VectorXd& qd = world_->qd();
  if (walker_) walker_->Control(completed);  // walking hook: drives the leg dofs
  if (base_mode_ != BaseMode::kIdle) {
    double x, y, th;
    BasePose(&x, &y, &th);
    Twist2 t{.v = cmd_vx_, .omega = cmd_omega_};
    double vy = cmd_vy_;
    if (base_mode_ == BaseMode::kGoto) {
      t = goto_.Update(x, y, th);
      vy = 0;
      if (goto_.done()) {
        const bool kinematic = base_kind_ == BaseKind::kKinematic;
        completed.push_back(Completion{
            .id = goto_id_,
            .signal = kinematic ? Signal::kModified : Signal::kSuccess,
            .message = kinematic ? std::string("GOTO: reached by moving the root kinematically (") +
                                       ToString(model_.roots().front().base) + " base; " +
                                       (gait_dof_[0] >= 0 ? "the legs followed a scripted gait)" : "no gait)")
                                 : std::string()});
        base_mode_ = BaseMode::kIdle;
      }
    }
    if (base_kind_ == BaseKind::kWheels) {
      SetWheels(t.v, t.omega);
    } else {
      const double c = std::cos(th), s = std::sin(th);
      world_->SetRootVelocity({c * t.v - s * vy, s * t.v + c * vy, 0}, {0, 0, t.omega});
      if (gait_dof_[0] >= 0) {
        gait_phase_ += 2 * std::numbers::pi * std::hypot(t.v, vy) * ToSeconds(step_) / kGaitStride;
        const double sn = std::sin(gait_phase_);
        for (int leg = 0; leg < 2; ++leg) {
          const double sl = leg == 0 ? sn : -sn;
          const auto hip = static_cast<Eigen::Index>(gait_dof_[2 * leg]);
          const auto knee = static_cast<Eigen::Index>(gait_dof_[2 * leg + 1]);
          mode_[static_cast<size_t>(hip)] = mode_[static_cast<size_t>(knee)] = Mode::kPosition;
          target_[hip] = std::clamp(-kGaitHip * sl, lower_[hip], upper_[hip]);
          target_[knee] = std::clamp(kGaitKnee * std::max(0.0, sl), lower_[knee], upper_[knee]);
        }
      }
    }
    if (base_mode_ == BaseMode::kIdle) {  // the GOTO just finished
      if (base_kind_ == BaseKind::kWheels) SetWheels(0, 0);
      world_->SetRootVelocity(Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero());
    }
  }
  const Eigen::Index n = q.size();
  for (Eigen::Index i = 0; i < n; ++i) {
    const auto u = static_cast<size_t>(i);
    if (walker_ && walker_->Owns(i)) continue;  // walking hook
    switch (mode_[u]) {
      case Mode::kPosition:
        world_->SetMotor(static_cast<int>(i),
                         std::clamp(options_.kp * (target_[i] - q[i]), -vmax_[i], vmax_[i]), fmax_[i]);
        break;
      case Mode::kVelocity:
        if ((q[i] >= upper_[i] && speed_[i] > 0) || (q[i] <= lower_[i] && speed_[i] < 0)) {
          mode_[u] = Mode::kPosition;  // a speed command stops and holds at a limit
          target_[i] = std::clamp(q[i], lower_[i], upper_[i]);
          speed_[i] = 0;
          --i;
          continue;
        }
        world_->SetMotor(static_cast<int>(i), speed_[i], fmax_[i]);
        break;
      case Mode::kForce:
        world_->SetEffort(static_cast<int>(i), force_[i]);
        break;
      case Mode::kPassive:
        world_->SetMotor(static_cast<int>(i), 0, 0);
        break;
      case Mode::kMimic: {
        const auto l = static_cast<Eigen::Index>(leader_[u]);
        const double want = mimic_k_[u] * q[l] + mimic_c_[u];
        world_->SetMotor(static_cast<int>(i),
                         std::clamp(mimic_k_[u] * qd[l] + options_.kp * (want - q[i]), -vmax_[i], vmax_[i]),
                         fmax_[i]);
        break;
      }
    }
  }
}

void OdeDriver::Impl::StopAll(const char* why, std::vector<Completion>& completed) {
  StopBase(why, completed);
  for (size_t i = 0; i < mode_.size(); ++i) HoldDof(static_cast<Eigen::Index>(i));
}

void OdeDriver::Impl::StopBase(const char* why, std::vector<Completion>& completed) {
  if (walker_) walker_->Stop(why, completed);  // walking hook: ends in double support within two steps
  if (base_mode_ == BaseMode::kGoto) {
    completed.push_back(
        Completion{.id = goto_id_, .signal = Signal::kInterrupted, .message = std::string("GOTO: ") + why});
  }
  base_mode_ = BaseMode::kIdle;
  cmd_vx_ = cmd_vy_ = cmd_omega_ = 0;
  world_->SetRootVelocity(Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero());
}

// The dof stops at once: its motor at zero velocity with its full force (a
// position hold would drive back over the braking distance). Mimic followers
// follow their leader; passive dofs have no motor.
void OdeDriver::Impl::HoldDof(Eigen::Index i) {
  const auto u = static_cast<size_t>(i);
  if (mode_[u] == Mode::kMimic || mode_[u] == Mode::kPassive) return;
  mode_[u] = Mode::kVelocity;
  target_[i] = std::clamp(world_->q()[i], lower_[i], upper_[i]);
  speed_[i] = 0;
  force_[i] = 0;
  world_->SetMotor(static_cast<int>(i), 0, fmax_[i]);
}

// ---------------------------------------------------------------- state

void OdeDriver::Impl::ReadState(RobotState& state) const {
  state.position = world_->q();
  state.velocity = world_->qd();
  state.effort = world_->effort();
  const auto roots = model_.roots();
  if (state.root_poses.size() != roots.size()) state.root_poses.resize(roots.size());
  for (size_t i = 0; i < roots.size(); ++i)
    state.root_poses[i] = Pose::FromIsometry(world_->LinkPose(roots[i].link));
  const int root = roots.front().link;
  const Eigen::Isometry3d p = world_->LinkPose(root);
  const Eigen::Vector3d v = world_->LinkLinearVelocity(root);
  state.base_v = base_kind_ == BaseKind::kFixed ? 0.0 : v.dot(p.linear().col(0));
  state.base_omega = base_kind_ == BaseKind::kFixed ? 0.0 : world_->LinkAngularVelocity(root).z();
  bool moving = (walker_ && walker_->status().stepping) || base_mode_ != BaseMode::kIdle ||
                std::abs(state.base_v) > kMovingSpeed || std::abs(state.base_omega) > kMovingSpeed;
  const Eigen::VectorXd& q = world_->q();
  const Eigen::VectorXd& qd = world_->qd();
  for (Eigen::Index i = 0; i < q.size() && !moving; ++i) {
    switch (mode_[static_cast<size_t>(i)]) {
      case Mode::kPosition:
        moving = std::abs(target_[i] - q[i]) > kTargetReached || std::abs(qd[i]) > kMovingSpeed;
        break;
      case Mode::kVelocity:
        moving = speed_[i] != 0 || std::abs(qd[i]) > kMovingSpeed;
        break;
      case Mode::kForce:
        moving = force_[i] != 0;
        break;
      case Mode::kPassive:
      case Mode::kMimic:
        break;
    }
  }
  state.moving = moving;
}

// ---------------------------------------------------------------- OdeDriver

OdeDriver::OdeDriver(RobotModel model, const OdeDriverOptions& options, std::vector<CollisionShape> shapes)
    : impl_(std::make_unique<Impl>(std::move(model), options, std::move(shapes))) {}
OdeDriver::~OdeDriver() = default;
const RobotModel& OdeDriver::model() const { return impl_->model_; }
Duration OdeDriver::period() const { return impl_->options_.period; }
DriverResult OdeDriver::Execute(const DriverCommand& command, TimePoint now,
                                std::vector<Completion>& completed) {
  return impl_->Execute(command, now, completed);
}
void OdeDriver::Update(TimePoint now, std::vector<Completion>& completed) {
  impl_->Advance(now, true, completed);
}
void OdeDriver::ReadState(RobotState& state) const { impl_->ReadState(state); }
void OdeDriver::Stop(TimePoint now, std::vector<Completion>& interrupted) { impl_->Stop(now, interrupted); }
void OdeDriver::StopOnly(const StopScope& scope, TimePoint now, std::vector<Completion>& interrupted) {
  impl_->StopOnly(scope, now, interrupted);
}
void OdeDriver::Halt(std::vector<Completion>& interrupted) { impl_->Halt(interrupted); }
void OdeDriver::Resume() { impl_->Resume(); }
void OdeDriver::Step(int n, std::vector<Completion>& completed) {
  if (!impl_->origin_) impl_->origin_ = TimePoint{};
  impl_->Step(n, completed);
}
void OdeDriver::AdvanceTo(TimePoint t, std::vector<Completion>& completed) {
  impl_->Advance(t, false, completed);
}
TimePoint OdeDriver::sim_time() const {
  return impl_->origin_.value_or(TimePoint{}) + impl_->dropped_ + impl_->steps_ * impl_->step_;
}
Duration OdeDriver::dropped_time() const { return impl_->dropped_; }
std::string_view OdeDriver::Fault() const {
  return impl_->walker_ ? std::string_view(impl_->walker_->fall()) : std::string_view();
}

std::optional<walking::WalkStatus> OdeDriver::walk_status() const {
  if (!impl_->walker_) return std::nullopt;
  return impl_->walker_->status();
}
Eigen::Isometry3d OdeDriver::LinkPose(int link) const { return impl_->world_->LinkPose(link); }
OdeDriver::Stats OdeDriver::stats() const {
  const OdeWorld& w = *impl_->world_;
  return Stats{.bodies = w.num_bodies(),
               .geoms = w.num_geoms(),
               .fused_links = w.num_fused_links(),
               .mesh_boxes = w.num_mesh_boxes(),
               .skipped_meshes = w.num_skipped_meshes(),
               .steps = w.steps()};
}

void RegisterOdeDriver(DriverRegistry& registry) {
  registry.Register("ode", [](const DriverConfig& config) -> std::unique_ptr<Driver> {
    const OdeDriverOptions options = OdeDriverOptions::FromMap(config.options);
    if (config.urdf_path.empty()) {
      throw Error("ode driver for robot '" + config.robot_name + "': no URDF file (DriverConfig::urdf_path)");
    }
    UrdfImportOptions import;
    import.merge_massless_chains = options.merge_chains;
    import.robot_name = config.robot_name;
    UrdfImportResult result = LoadUrdfFile(config.urdf_path, import);
    return std::make_unique<OdeDriver>(std::move(result.model), options,
                                       LoadCollisionShapes(config.urdf_path));
  });
}

}  // namespace robotalk
