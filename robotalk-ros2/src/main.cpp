// robotalk-ros2: RoboTalk robots on ROS 2 over DDS (docs/interop.md, "ROS 2").
#include "robotalk/error.h"
#include "ros2_bridge.h"
#include "ros2_options.h"

#include <pthread.h>
#include <signal.h>

#include <cstdlib>
#include <iostream>
#include <thread>

int main(int argc, char** argv) {
  using namespace robotalk::ros2;
  Ros2Options options;
  try {
    const char* domain = std::getenv("ROS_DOMAIN_ID");
    options = ParseRos2Options(std::vector<std::string>(argv + 1, argv + argc), domain ? domain : "");
  } catch (const robotalk::Error& e) {
    std::cerr << "robotalk-ros2: " << e.what() << "\n";
    return 2;
  }
  if (options.help) {
    std::cout << Ros2Usage();
    return 0;
  }
  if (options.version) {
    std::cout << "robotalk-ros2 " << ROBOTALK_ROS2_VERSION << "\n";
    return 0;
  }
  // SIGINT and SIGTERM are taken by one thread (sigwait), which asks the
  // bridge to stop: the bridge then sends STOP to what it set moving.
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGINT);
  sigaddset(&signals, SIGTERM);
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);
  try {
    Ros2Bridge bridge(options);
    std::thread waiter([&] {
      int sig = 0;
      sigwait(&signals, &sig);
      bridge.Stop();
    });
    bridge.Run();
    if (options.stats) std::cout << bridge.StatsText() << std::flush;
    pthread_kill(waiter.native_handle(), SIGTERM);  // wakes sigwait if no signal came
    waiter.join();
  } catch (const std::exception& e) {
    std::cerr << "robotalk-ros2: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
