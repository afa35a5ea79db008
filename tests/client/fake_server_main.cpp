// robotalk_fake_server URL MODEL.urdf SECONDS: runs FakeServer (fake_server.h)
// on a real LCM URL for SECONDS as robot "pioneer", announcing every 200 ms.
// For the CLI test.
#include "fake_server.h"
#include "robotalk/routed_lcm_transport.h"
#include "robotalk/urdf_import.h"

#include <chrono>
#include <cstdio>
#include <cstdlib>

int main(int argc, char** argv) {
  if (argc != 4) {
    std::fprintf(stderr, "usage: robotalk_fake_server URL MODEL.urdf SECONDS\n");
    return 2;
  }
  const std::unique_ptr<robotalk::Transport> transport = robotalk::OpenLcmTransport(argv[1]);
  robotalk::Transport& lcm = *transport;
  robotalk::testing::FakeServer server(lcm, robotalk::LoadUrdfFile(argv[2], {.robot_name = "pioneer"}).model);
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(std::atof(argv[3]));
  auto next_announce = std::chrono::steady_clock::now();
  while (std::chrono::steady_clock::now() < end) {
    if (std::chrono::steady_clock::now() >= next_announce) {
      server.Announce(42);
      next_announce += std::chrono::milliseconds(200);
    }
    lcm.HandleFor(std::chrono::milliseconds(20));
  }
  return 0;
}
