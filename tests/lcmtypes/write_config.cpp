// Writes the encoded configuration of a small hand-built robot to a file and
// prints what a client decoding that file must print (see DecodeConfig.java and
// decode_config.lua):
//   robot=<name> links=<n> joints=<n> frames=<n> roots=<n> dofs=<n> hash=0x<16 hex> verified=yes
#include "robotalk/config_message.h"
#include "robotalk/robot_model.h"

#include <cinttypes>
#include <cstdio>
#include <fstream>
#include <iostream>

namespace {

robotalk::RobotModel BindingBot() {
  using namespace robotalk;
  Link body{.name = "body", .mass = 9.0, .com = {0.0, 0.0, 0.1}};
  body.inertia = Eigen::Vector3d(0.1, 0.2, 0.3).asDiagonal();
  Link head{.name = "head", .mass = 0.5};
  head.inertia = Eigen::Matrix3d::Identity() * 0.001;
  Link finger_a{.name = "finger_a", .mass = 0.01};
  finger_a.inertia = Eigen::Matrix3d::Identity() * 1e-6;
  Link finger_b = finger_a;
  finger_b.name = "finger_b";

  Joint pan_tilt{.name = "pan_tilt", .inboard = {0.0, 0.0, 0.3}, .servo_types = ServoTypes::All()};
  pan_tilt.dofs = {
      Dof{.type = DofType::kRevolute, .axis = Eigen::Vector3d::UnitZ()},
      Dof{.type = DofType::kRevolute, .axis = Eigen::Vector3d::UnitY(), .limits = {-0.5, 0.5, 1.0, 2.0}}};
  Joint grip_a{.name = "grip_a", .servo_types = ServoType::kForce};
  grip_a.dofs = {
      Dof{.type = DofType::kPrismatic, .axis = Eigen::Vector3d::UnitY(), .limits = {0.0, 0.04, 0.1, 20.0}}};
  Joint grip_b = grip_a;
  grip_b.name = "grip_b";

  RobotModelBuilder b("binding_bot");
  b.AddLink(body).AddLink(head).AddLink(finger_a).AddLink(finger_b);
  b.AddJoint(pan_tilt, "body", "head")
      .AddJoint(grip_a, "head", "finger_a")
      .AddJoint(grip_b, "head", "finger_b");
  b.SetMimic("grip_b", "grip_a", 1.0, 0.0);
  b.AddControlFrame(ControlFrame{.name = "camera",
                                 .pose_in_link = {{0.05, 0.0, 0.0}, Eigen::Quaterniond(0.5, -0.5, 0.5, -0.5)},
                                 .servo_types = ServoType::kSetPoint},
                    "head");
  b.SetRoot("body", Pose{{1.0, 2.0, 0.0}, Eigen::Quaterniond::Identity()}, BaseType::kDifferential);
  return b.Build();
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::cerr << "usage: " << argv[0] << " OUTPUT_FILE\n";
    return 2;
  }
  const robotalk::RobotModel model = BindingBot();
  const std::vector<std::uint8_t> bytes = robotalk::EncodeConfig(model);
  std::ofstream out(argv[1], std::ios::binary);
  out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  if (!out) {
    std::cerr << argv[0] << ": cannot write " << argv[1] << "\n";
    return 1;
  }
  std::printf("robot=%s links=%zu joints=%zu frames=%zu roots=%zu dofs=%d hash=0x%016" PRIx64
              " verified=yes\n",
              model.name().c_str(), model.links().size(), model.joints().size(), model.frames().size(),
              model.roots().size(), model.num_dofs(), robotalk::ConfigHash(model));
  return 0;
}
