// Times Kinematics::Update() and FrameJacobian() on a 7-dof arm and a 31-dof
// humanoid built in code (so the bench needs no robot files), and prints
// microseconds per call. Usage: robotalk-kinematics-bench [iterations]
#include "robotalk/kinematics.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
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

// Best of 5 runs of `iterations` calls, in microseconds per call.
template <typename F>
double MicrosPerCall(int iterations, F call) {
  double best = 1e300;
  for (int run = 0; run < 5; ++run) {
    const auto start = std::chrono::steady_clock::now();
    for (int i = 0; i < iterations; ++i) call(i);
    const std::chrono::duration<double, std::micro> elapsed = std::chrono::steady_clock::now() - start;
    best = std::min(best, elapsed.count() / iterations);
  }
  return best;
}

void Bench(const RobotModel& model, int iterations) {
  // Distinct positions per call so nothing is hoisted out of the loop.
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> angle(-3, 3);
  std::vector<Eigen::VectorXd> qs(64, Eigen::VectorXd(model.num_dofs()));
  for (auto& q : qs) q = q.unaryExpr([&](double) { return angle(rng); });

  robotalk::Kinematics kin(model);
  double sink = 0;  // consumed below so the calls cannot be optimized away
  const double update = MicrosPerCall(iterations, [&](int i) {
    kin.Update(qs[static_cast<size_t>(i) % qs.size()]);
    sink += kin.frame_pose(0).translation().x();
  });
  const double jacobian = MicrosPerCall(iterations, [&](int) { sink += kin.FrameJacobian(0)(0, 0); });
  const double com = MicrosPerCall(iterations, [&](int) { sink += kin.CenterOfMass().x(); });
  volatile double keep = sink;
  (void)keep;
  std::printf("%-11s %3d dofs %3zu links  Update %7.3f us  FrameJacobian %7.3f us  CenterOfMass %7.3f us\n",
              model.name().c_str(), model.num_dofs(), model.links().size(), update, jacobian, com);
}

}  // namespace

int main(int argc, char** argv) {
  const int iterations = argc > 1 ? std::atoi(argv[1]) : 200000;
  if (iterations <= 0) {
    std::fprintf(stderr, "usage: %s [iterations > 0]\n", argv[0]);
    return 2;
  }
  Bench(Arm(), iterations);
  Bench(Humanoid(), iterations);
  return 0;
}
