// OdeDriver: construction, stepping and state; the command handlers are in
// ode_commands.cpp, the base in base_controllers.cpp and walking_humanoid.cpp.
#include "ode_driver.h"

#include "ode_driver_impl.h"
#include "robotalk/driver_support.h"
#include "robotalk/error.h"
#include "robotalk/urdf_import.h"

#include <cmath>
#include <utility>

namespace robotalk {

using driver_support::Num;
using ode_detail::OdeWorld;

namespace {

// Validated first: the servos' defaults come from the options.
const OdeDriverOptions& Validated(const OdeDriverOptions& options) {
  options.Validate();
  return options;
}

}  // namespace

namespace ode_detail {

RobotModel DriverModel(RobotModel model, const OdeDriverOptions& options) {
  if (options.base.empty()) return model;
  std::vector<RootLink> roots(model.roots().begin(), model.roots().end());
  roots.front().base = ParseBaseType(options.base);
  return RobotModel(model.name(), {model.links().begin(), model.links().end()},
                    {model.joints().begin(), model.joints().end()},
                    {model.frames().begin(), model.frames().end()}, std::move(roots));
}

DriverWorld BuildDriverWorld(const RobotModel& model, const OdeDriverOptions& options,
                             const Eigen::VectorXd& q0, std::vector<CollisionShape> shapes) {
  const double step = ToSeconds(FromSeconds(1.0 / options.step_hz));
  DriverWorld built;
  built.base = MakeBaseController(model, options, shapes, step);
  OdeWorldOptions wo;
  wo.step = step;
  wo.gravity = options.gravity;
  wo.friction = options.friction;
  wo.quickstep = options.solver == "quickstep";
  wo.virtual_mass = options.virtual_mass;
  wo.caster_links = options.casters;
  wo.seed = options.seed;
  built.base->Prepare(wo, shapes);
  built.world = std::make_unique<OdeWorld>(model, shapes, wo, q0);
  built.shapes = std::move(shapes);
  return built;
}

}  // namespace ode_detail

OdeDriver::Impl::Impl(RobotModel model, const OdeDriverOptions& options, std::vector<CollisionShape> shapes)
    : model_(ode_detail::DriverModel(std::move(model), options)),
      options_(Validated(options)),
      servos_(model_, options_),
      ik_(model_) {
  step_ = FromSeconds(1.0 / options_.step_hz);
  if (step_ <= Duration::zero()) throw Error("OdeDriver: step_hz " + Num(options_.step_hz) + " is too high");
  root_poses_.assign(model_.roots().size(), Eigen::Isometry3d::Identity());
  ode_detail::DriverWorld built =
      ode_detail::BuildDriverWorld(model_, options_, servos_.q0(), std::move(shapes));
  base_ = std::move(built.base);
  world_ = std::move(built.world);
  base_->Attach(*world_, servos_, built.shapes);
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
  if (!origin_) origin_ = TimePoint{};
  for (int s = 0; s < n; ++s) {
    base_->Control(completed);  // the base first: it may set the wheels' or the gait's servos
    servos_.Apply(*world_);
    if (push_steps_ > 0) {
      world_->AddRootForce(push_);
      --push_steps_;
    }
    world_->Step();
    ++steps_;
  }
}

void OdeDriver::Impl::StopAll(const char* why, std::vector<Completion>& completed) {
  base_->Stop(why, completed);
  for (Eigen::Index i = 0; i < model_.num_dofs(); ++i) servos_.Hold(i, *world_);
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
  const ode_detail::Twist2 t = base_->twist();
  state.base_v = t.v;
  state.base_omega = t.omega;
  if (const BaseType b = model_.roots().front().base; b == BaseType::kHolonomic || b == BaseType::kFloating) {
    // The lateral part of a root that can move sideways.
    const int root = model_.roots().front().link;
    state.base_vy = world_->LinkLinearVelocity(root).dot(world_->LinkPose(root).linear().col(1));
  }
  // A walker's pelvis sways while it balances: its base moves when it walks
  // (WalkingHumanoid::moving()); the other bases also when their root does.
  const bool root_moves = !base_->walk_status() && (std::abs(t.v) > ode_detail::kMovingSpeed ||
                                                    std::abs(t.omega) > ode_detail::kMovingSpeed);
  state.moving = base_->moving() || root_moves || servos_.Moving(world_->q(), world_->qd());
}

// ---------------------------------------------------------------- OdeDriver

OdeDriver::OdeDriver(RobotModel model, const OdeDriverOptions& options, std::vector<CollisionShape> shapes)
    : impl_(std::make_unique<Impl>(std::move(model), options, std::move(shapes))) {}
OdeDriver::~OdeDriver() = default;
const RobotModel& OdeDriver::model() const { return impl_->model(); }
Duration OdeDriver::period() const { return impl_->period(); }
DriverResult OdeDriver::Execute(const DriverCommand& command, TimePoint now,
                                std::vector<Completion>& completed) {
  return impl_->Execute(command, now, completed);
}
DriverResult OdeDriver::TrackBase(const BaseReference& reference, TimePoint now,
                                  std::vector<Completion>& completed) {
  return impl_->TrackBase(reference, now, completed);
}

DriverResult OdeDriver::Track(const JointReference& reference, TimePoint now,
                              std::vector<Completion>& completed) {
  return impl_->Track(reference, now, completed);
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
void OdeDriver::Resume() {}
void OdeDriver::Step(int n, std::vector<Completion>& completed) { impl_->Step(n, completed); }
void OdeDriver::AdvanceTo(TimePoint t, std::vector<Completion>& completed) {
  impl_->Advance(t, false, completed);
}
TimePoint OdeDriver::sim_time() const { return impl_->sim_time(); }
Duration OdeDriver::dropped_time() const { return impl_->dropped_time(); }
std::string_view OdeDriver::Fault() const { return impl_->fault(); }
std::optional<walking::WalkStatus> OdeDriver::walk_status() const { return impl_->walk_status(); }
Eigen::Isometry3d OdeDriver::LinkPose(int link) const { return impl_->world().LinkPose(link); }
void OdeDriver::PushForTesting(const Eigen::Vector3d& force, Duration duration) {
  impl_->Push(force, duration);
}
OdeDriver::Stats OdeDriver::stats() const {
  const OdeWorld& w = impl_->world();
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
