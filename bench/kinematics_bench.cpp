// Google Benchmark of Kinematics::Update(), FrameJacobian() and
// CenterOfMass() on a 7-dof arm and a 31-dof humanoid built in code (so the
// bench needs no robot files). Figures: docs/performance.md, "In-process".
//   robotalk-kinematics-bench [--benchmark_format=json ...]
#include "robotalk/kinematics.h"

#include <benchmark/benchmark.h>

#include <random>
#include <string>
#include <vector>

namespace {

using Eigen::Vector3d;
using robotalk::ControlFrame;
using robotalk::Dof;
using robotalk::DofType;
using robotalk::Joint;
using robotalk::Link;
using robotalk::RobotModel;
using robotalk::RobotModelBuilder;

Link Body(const std::string& name, const Vector3d& com) {
  Link link{.name = name, .mass = 1.0, .com = com};
  link.inertia = Eigen::Matrix3d::Identity() * 0.01;
  return link;
}

// Appends a serial chain of 1-dof revolute joints below `parent`, one link per
// joint, alternating axes like a real arm or leg; returns the last link's name.
std::string AddChain(RobotModelBuilder& b, const std::string& parent, const std::string& prefix,
                     const std::vector<Vector3d>& axes, const Vector3d& step) {
  std::string previous = parent;
  for (size_t i = 0; i < axes.size(); ++i) {
    const std::string name = prefix + std::to_string(i + 1);
    b.AddLink(Body(name, step / 2));
    Joint joint{.name = name + "_joint", .inboard = step / 2, .outboard = -step / 2};
    joint.dofs.push_back(Dof{.type = DofType::kRevolute, .axis = axes[i]});
    b.AddJoint(joint, previous, name);
    previous = name;
  }
  return previous;
}

RobotModel Arm() {
  const Vector3d y = Vector3d::UnitY(), z = Vector3d::UnitZ();
  RobotModelBuilder b("arm7");
  b.AddLink(Body("base", Vector3d::Zero()));
  const std::string tip = AddChain(b, "base", "link", {z, y, z, y, z, y, z}, Vector3d(0, 0, 0.2));
  b.AddControlFrame(ControlFrame{.name = "tool", .pose_in_link = {.translation = {0, 0, 0.1}}}, tip);
  return b.Build();
}

// Pelvis (floating root) with two 6-dof legs, a 3-dof torso chain, two 7-dof
// arms on the chest and a 2-dof neck: 31 dofs.
RobotModel Humanoid() {
  const Vector3d x = Vector3d::UnitX(), y = Vector3d::UnitY(), z = Vector3d::UnitZ();
  RobotModelBuilder b("humanoid31");
  b.AddLink(Body("pelvis", Vector3d::Zero()));
  const std::vector<Vector3d> leg = {z, x, y, y, y, x}, arm = {y, x, z, y, z, y, x};
  AddChain(b, "pelvis", "l_leg", leg, Vector3d(0, 0, -0.2));
  AddChain(b, "pelvis", "r_leg", leg, Vector3d(0, 0, -0.2));
  const std::string chest = AddChain(b, "pelvis", "torso", {z, y, x}, Vector3d(0, 0, 0.15));
  AddChain(b, chest, "l_arm", arm, Vector3d(0, 0.1, -0.1));
  const std::string hand = AddChain(b, chest, "r_arm", arm, Vector3d(0, -0.1, -0.1));
  AddChain(b, chest, "neck", {z, y}, Vector3d(0, 0, 0.05));
  b.AddControlFrame(ControlFrame{.name = "r_hand", .pose_in_link = {.translation = {0, 0, -0.05}}}, hand);
  b.SetRoot("pelvis", robotalk::Pose{.translation = {0, 0, 1}}, robotalk::BaseType::kFloating);
  return b.Build();
}

// Distinct positions per call so nothing is hoisted out of the loop.
std::vector<Eigen::VectorXd> Positions(const RobotModel& model) {
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> angle(-3, 3);
  std::vector<Eigen::VectorXd> qs(64, Eigen::VectorXd(model.num_dofs()));
  for (auto& q : qs) q = q.unaryExpr([&](double) { return angle(rng); });
  return qs;
}

const RobotModel& Model(int which) {
  static const RobotModel arm = Arm(), humanoid = Humanoid();
  return which == 0 ? arm : humanoid;
}

void Label(benchmark::State& state, const RobotModel& model) {
  state.SetLabel(model.name() + ", " + std::to_string(model.num_dofs()) + " dofs, " +
                 std::to_string(model.links().size()) + " links");
}

void BM_KinematicsUpdate(benchmark::State& state) {
  const RobotModel& model = Model(static_cast<int>(state.range(0)));
  const auto qs = Positions(model);
  robotalk::Kinematics kin(model);
  std::size_t i = 0;
  for (auto _ : state) {
    kin.Update(qs[i++ % qs.size()]);
    benchmark::DoNotOptimize(kin.frame_pose(0).translation().x());
  }
  Label(state, model);
}

void BM_FrameJacobian(benchmark::State& state) {
  const RobotModel& model = Model(static_cast<int>(state.range(0)));
  robotalk::Kinematics kin(model);
  kin.Update(Positions(model)[0]);
  for (auto _ : state) benchmark::DoNotOptimize(kin.FrameJacobian(0)(0, 0));
  Label(state, model);
}

void BM_CenterOfMass(benchmark::State& state) {
  const RobotModel& model = Model(static_cast<int>(state.range(0)));
  robotalk::Kinematics kin(model);
  kin.Update(Positions(model)[0]);
  for (auto _ : state) benchmark::DoNotOptimize(kin.CenterOfMass().x());
  Label(state, model);
}

}  // namespace

// Argument 0 = arm7, 1 = humanoid31.
BENCHMARK(BM_KinematicsUpdate)->Arg(0)->Arg(1);
BENCHMARK(BM_FrameJacobian)->Arg(0)->Arg(1);
BENCHMARK(BM_CenterOfMass)->Arg(0)->Arg(1);
BENCHMARK_MAIN();
