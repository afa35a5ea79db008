// The C++ figures the Python spec tests compare with (test_spec.py): loads a
// URDF, runs Kinematics at the given joint positions and prints every link's
// world pose (4x4, row-major) and the point Jacobian of the last link's
// origin, one number per token, full precision.
//   fk_reference URDF [q0 q1 ...]      (missing q: zero)
#include "robotalk/kinematics.h"
#include "robotalk/urdf_import.h"

#include <cstdio>
#include <cstdlib>

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: fk_reference URDF [q...]\n");
    return 2;
  }
  try {
    const robotalk::RobotModel model = robotalk::LoadUrdfFile(argv[1]).model;
    Eigen::VectorXd q = Eigen::VectorXd::Zero(model.num_dofs());
    for (int i = 2; i < argc && i - 2 < q.size(); ++i) q[i - 2] = std::strtod(argv[i], nullptr);
    robotalk::Kinematics kin(model);
    kin.Update(q);
    for (int l = 0; l < static_cast<int>(model.links().size()); ++l) {
      std::printf("link %s", model.link(l).name.c_str());
      const Eigen::Matrix4d x = kin.link_pose(l).matrix();
      for (int r = 0; r < 4; ++r)
        for (int c = 0; c < 4; ++c) std::printf(" %.17g", x(r, c));
      std::printf("\n");
    }
    const int last = static_cast<int>(model.links().size()) - 1;
    const robotalk::Jacobian j = kin.PointJacobian(last, Eigen::Vector3d::Zero());
    std::printf("jacobian %d", static_cast<int>(j.cols()));
    for (int r = 0; r < 6; ++r)
      for (int c = 0; c < j.cols(); ++c) std::printf(" %.17g", j(r, c));
    std::printf("\ncom");
    const Eigen::Vector3d com = kin.CenterOfMass();
    for (int i = 0; i < 3; ++i) std::printf(" %.17g", com[i]);
    std::printf("\n");
  } catch (const std::exception& e) {
    std::fprintf(stderr, "fk_reference: %s\n", e.what());
    return 1;
  }
  return 0;
}
