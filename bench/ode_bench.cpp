// Benchmark of the ode driver (not a test): real-time factor of each robot at
// 1 kHz, the driver's overhead against a bare loop of the same ODE world,
// set-point tracking error on the iiwa14 arm, GOTO end-pose error on the
// Pioneer. Figures go to docs/ode_sim.md.
//   robotalk-ode-bench [MODELS_DIR] [SHARED_ROBOTS_DIR]
#include "collision_shapes.h"
#include "joint_servos.h"
#include "ode_driver.h"
#include "ode_driver_impl.h"
#include "ode_world.h"
#include "robotalk/urdf_import.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <numbers>
#include <string>

using namespace robotalk;
using WallClock = std::chrono::steady_clock;

namespace {

struct Robot {
  std::string label, path;
  std::map<std::string, std::string> options;
};

double WallSeconds(WallClock::duration d) { return std::chrono::duration<double>(d).count(); }

DriverCommand Cmd(const RobotModel& m, CommandType type, const std::string& target, std::vector<double> v) {
  static CommandId id = 0;
  DriverCommand c;
  c.id = ++id;
  c.type = type;
  if (!target.empty()) c.target = m.JointIndex(target);
  c.num_values = static_cast<int>(v.size());
  for (size_t i = 0; i < v.size(); ++i) c.values[i] = v[i];
  return c;
}

std::unique_ptr<OdeDriver> Make(const Robot& r) {
  DriverRegistry reg;
  RegisterOdeDriver(reg);
  auto d = reg.Create("ode", DriverConfig{.robot_name = "", .urdf_path = r.path, .options = r.options});
  return std::unique_ptr<OdeDriver>(static_cast<OdeDriver*>(d.release()));
}

// "Bare ODE" is the world the ode driver builds for `r`, built by the
// driver's own code (ode_detail::BuildDriverWorld: the same import options,
// base type, world options, shapes as the base controller prepares them, a
// walking humanoid's root left dynamic) and stepped with a 5-line servo (the
// servo law of a holding driver, Step()). The overhead is everything else the
// driver does per step (its command state, limits, base, state read-out).
// Comparing against a world that differs (e.g. cylinder wheels: more contact
// points, a costlier LCP) measured the difference of the worlds, not the
// driver: the Pioneer read -25 %.
RobotModel DriverModel(const Robot& r, const OdeDriverOptions& o) {
  UrdfImportOptions import;
  import.merge_massless_chains = o.merge_chains;
  return ode_detail::DriverModel(LoadUrdfFile(r.path, import).model, o);
}

OdeDriverOptions ValidOptions(const Robot& r) {
  OdeDriverOptions o = OdeDriverOptions::FromMap(r.options);
  o.Validate();
  return o;
}

struct BareWorld {
  RobotModel model;
  std::unique_ptr<ode_detail::OdeWorld> world;

  explicit BareWorld(const Robot& r) : model(DriverModel(r, ValidOptions(r))) {
    const OdeDriverOptions o = ValidOptions(r);
    const Eigen::VectorXd q0 = ode_detail::JointServos(model, o).q0();
    world = ode_detail::BuildDriverWorld(model, o, q0, LoadCollisionShapes(r.path)).world;
    target = q0;
    kp = o.kp;
    for (int j = 0; j < static_cast<int>(model.joints().size()); ++j) {
      const Joint& joint = model.joint(j);
      const bool passive = joint.servo_types.empty() && !joint.mimic;
      for (size_t k = 0; k < joint.dofs.size(); ++k) {
        const DofLimits& l = joint.dofs[k].limits;
        fmax.push_back(passive ? 0.0 : (std::isfinite(l.effort) ? l.effort : o.default_effort));
        vmax.push_back(passive ? 0.0 : (std::isfinite(l.velocity) ? l.velocity : o.default_velocity));
      }
    }
  }

  // One step with the minimal servo a holding driver runs: every dof's motor
  // towards its start position, kp * (target - q) within the velocity limit
  // (passive joints free), so both worlds follow the same trajectory.
  void Step() {
    const Eigen::VectorXd& q = world->q();
    for (Eigen::Index i = 0; i < q.size(); ++i) {
      const auto u = static_cast<size_t>(i);
      world->SetMotor(static_cast<int>(i), std::clamp(kp * (target[i] - q[i]), -vmax[u], vmax[u]), fmax[u]);
    }
    world->Step();
  }

  Eigen::VectorXd target;
  std::vector<double> fmax, vmax;
  double kp = 0;
};

// Real-time factor with the robot in motion, and the bare world's step cost.
void RealTimeFactor(const Robot& r) {
  auto d = Make(r);
  const RobotModel& m = d->model();
  std::vector<Completion> done;
  d->Step(1, done);
  const TimePoint t = d->sim_time();
  // Some motion: every set-point joint to 0.3 (clamped), a moving base.
  for (int j = 0; j < static_cast<int>(m.joints().size()); ++j) {
    const Joint& joint = m.joint(j);
    if (joint.dofs.size() != 1 || joint.mimic || !joint.servo_types.Has(ServoType::kSetPoint)) continue;
    d->Execute(Cmd(m, CommandType::kJointSetPoint, joint.name, {0.3}), t, done);
  }
  if (m.roots().front().base != BaseType::kFixed)
    d->Execute(Cmd(m, CommandType::kSetSpeed, "", {0.3, 0.3}), t, done);
  constexpr int kSteps = 3000;
  const auto a = WallClock::now();
  d->Step(kSteps, done);
  const double moving_s = WallSeconds(WallClock::now() - a) / kSteps;
  // Overhead: the driver holding still against the same world under the
  // same servo law (BareWorld), on the same trajectory.
  auto idle = Make(r);
  idle->Step(1, done);

  // The bare loop: the ODE world the driver builds, built the same way
  // (BareWorld), stepped with the minimal servo and nothing else.
  BareWorld bare(r);
  // Alternate the two in 30 rounds of 100 steps and keep each one's fastest
  // round: the machine is shared, so the minimum is the cost. Both have
  // stepped once before (the driver's first Step), and both step 3001 times.
  bare.Step();
  double driver_s = 1e9, bare_s = 1e9;
  for (int round = 0; round < 30; ++round) {
    const auto i0 = WallClock::now();
    idle->Step(100, done);
    driver_s = std::min(driver_s, WallSeconds(WallClock::now() - i0) / 100);
    const auto b0 = WallClock::now();
    for (int s = 0; s < 100; ++s) bare.Step();
    bare_s = std::min(bare_s, WallSeconds(WallClock::now() - b0) / 100);
  }
  // Like for like: the same world under the same servo law ends in the same
  // joint positions (up to a mimic joint's offset).
  RobotState held;
  idle->ReadState(held);
  const double q_diff = (held.position - bare.world->q()).cwiseAbs().maxCoeff();
  const OdeDriver::Stats st = d->stats();
  std::printf("| %-27s | %3d | %3d | %3d | %7.1f | %6.1f | %7.1f | %7.1f | %+5.1f %% | %.1e |\n",
              r.label.c_str(), m.num_dofs(), st.bodies, st.geoms, 1e6 * moving_s, 1e-3 / moving_s,
              1e6 * driver_s, 1e6 * bare_s, 100 * (driver_s - bare_s) / bare_s, q_diff);
}

// iiwa14: step set-points every second, and a 0.5 Hz sine streamed at 100 Hz.
void ArmTracking(const std::string& path) {
  auto d = Make({"iiwa14", path, {}});
  const RobotModel& m = d->model();
  std::vector<Completion> done;
  RobotState st;
  d->Step(1, done);
  TimePoint t = d->sim_time();
  const double goals[3][7] = {{0.5, 0.7, -0.4, -1.2, 0.3, 0.8, -0.6},
                              {-0.8, 0.3, 0.6, -0.5, -0.7, -0.4, 1.0},
                              {0.0, -0.6, 0.0, 1.0, 0.0, -1.0, 0.0}};
  double worst = 0, sum2 = 0;
  int n = 0;
  for (const auto& g : goals) {
    for (int j = 0; j < 7; ++j)
      d->Execute(Cmd(m, CommandType::kJointSetPoint, "iiwa_joint_" + std::to_string(j + 1), {g[j]}), t, done);
    t += std::chrono::seconds(2);
    d->AdvanceTo(t, done);
    d->ReadState(st);
    for (int j = 0; j < 7; ++j) {
      const double e = std::abs(st.position[j] - g[j]);
      worst = std::max(worst, e);
      sum2 += e * e;
      ++n;
    }
  }
  std::printf("iiwa14 step set-points, 2 s after each of 3 steps: max error %.2e rad, RMS %.2e rad\n", worst,
              std::sqrt(sum2 / n));
  worst = 0;
  sum2 = 0;
  n = 0;
  for (int k = 0; k < 500; ++k) {  // 5 s at 100 Hz, amplitude 0.5 rad, 0.5 Hz
    const double time = 0.01 * k;
    for (int j = 0; j < 7; ++j) {
      const double want = 0.5 * std::sin(std::numbers::pi * time + j);
      d->Execute(Cmd(m, CommandType::kJointSetPoint, "iiwa_joint_" + std::to_string(j + 1), {want}), t, done);
    }
    t += std::chrono::milliseconds(10);
    d->AdvanceTo(t, done);
    if (k < 100) continue;  // after the first second
    d->ReadState(st);
    for (int j = 0; j < 7; ++j) {
      const double e = std::abs(st.position[j] - 0.5 * std::sin(std::numbers::pi * (time + 0.01) + j));
      worst = std::max(worst, e);
      sum2 += e * e;
      ++n;
    }
  }
  std::printf(
      "iiwa14 0.5 Hz, 0.5 rad sine streamed at 100 Hz: max lag error %.3f rad, RMS %.3f rad (kp = 20/s)\n",
      worst, std::sqrt(sum2 / n));
}

void PioneerGoto(const std::string& path) {
  auto d = Make({"pioneer", path, {}});
  const RobotModel& m = d->model();
  std::vector<Completion> done;
  RobotState st;
  d->Step(1, done);
  const double goals[4][3] = {{1, 0, 1.5708}, {1, 1, 3.1416}, {0, 1, -1.5708}, {0, 0, 0}};
  double worst_p = 0, worst_h = 0, total = 0;
  for (const auto& g : goals) {
    done.clear();
    const TimePoint start = d->sim_time();
    d->Execute(Cmd(m, CommandType::kGoto, "", {g[0], g[1], g[2]}), start, done);
    while (done.empty() && d->sim_time() - start < std::chrono::seconds(30)) d->Step(10, done);
    total += ToSeconds(d->sim_time() - start);
    d->Step(500, done);  // settle 0.5 s
    d->ReadState(st);
    const Pose& p = st.root_poses.front();
    const Eigen::Vector3d fwd = p.rotation.toRotationMatrix().col(0);
    worst_p = std::max(worst_p, std::hypot(p.translation.x() - g[0], p.translation.y() - g[1]));
    worst_h = std::max(worst_h,
                       std::abs(std::remainder(std::atan2(fwd.y(), fwd.x()) - g[2], 2 * std::numbers::pi)));
    std::printf("  GOTO %g %g %g: %s\n", g[0], g[1], g[2],
                done.empty() ? "timeout" : std::string(ToString(done[0].signal)).c_str());
  }
  std::printf(
      "Pioneer 1 m square of GOTOs: %.1f s, worst end-pose error 0.5 s after SUCCESS %.4f m, %.4f rad\n",
      total, worst_p, worst_h);
}

}  // namespace

int main(int argc, char** argv) {
  const std::string models = argc > 1 ? argv[1] : "models";
  const std::string shared = argc > 2 ? argv[2] : "../shared/robots";
  std::printf(
      "| robot | dofs | bodies | geoms | moving: us/step | real-time factor | holding: driver us/step | bare "
      "ODE us/step | overhead | max \\|q driver - q bare\\| after 3,001 steps |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|---|\n");
  RealTimeFactor({"pioneer2dx_pantilt", models + "/pioneer2dx_pantilt.urdf", {}});
  RealTimeFactor({"simple_humanoid", models + "/simple_humanoid.urdf", {}});
  if (std::filesystem::exists(shared + "/iiwa14.urdf")) {
    RealTimeFactor({"iiwa14", shared + "/iiwa14.urdf", {}});
    RealTimeFactor({"atlas (base=floating)", shared + "/atlas.urdf", {{"base", "floating"}}});
    RealTimeFactor({"atlas (floating, quickstep)",
                    shared + "/atlas.urdf",
                    {{"base", "floating"}, {"solver", "quickstep"}}});
  }
  std::printf("\n");
  if (std::filesystem::exists(shared + "/iiwa14.urdf")) ArmTracking(shared + "/iiwa14.urdf");
  PioneerGoto(models + "/pioneer2dx_pantilt.urdf");
  return 0;
}
