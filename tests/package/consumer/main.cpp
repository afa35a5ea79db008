// A program outside the RoboTalk tree, built against the installed package:
// proves find_package(robotalk) gives working robotalk::core and ::client.
#include <robotalk/robot_client.h>
#include <robotalk/urdf_import.h>

#include <iostream>

int main(int argc, char** argv) {
  if (argc != 2) return 2;
  const robotalk::UrdfImportResult r = robotalk::LoadUrdfFile(argv[1]);
  std::cout << r.model.name() << " " << r.model.num_dofs() << " dofs, modes "
            << robotalk::ToString(robotalk::CommandMode::kPlayback) << "\n";
  return r.model.num_dofs() > 0 ? 0 : 1;
}
