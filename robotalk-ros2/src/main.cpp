// robotalk-ros2: RoboTalk robots on ROS 2 over DDS (docs/interop.md, "ROS 2").
#include "robotalk/error.h"
#include "robotalk/log_writer.h"
#include "ros2_bridge.h"
#include "ros2_options.h"

#include <pthread.h>
#include <signal.h>

#include <cstdlib>
#include <iostream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

namespace robotalk::ros2 {
namespace {

// Its errors through the process's one writer of stderr (the bridge's log
// too), its --stats figures through a writer of stdout: a stdout or stderr
// that takes nothing (a full pipe, a terminal stopped with Ctrl-S) holds it
// LogWriter::kMaxWait at most, so an error still ends it with its status,
// and after its shutdown's STOPs it exits, its sessions with it.
void Say(const std::string& line) { LogWriter::Stderr().Write("robotalk-ros2: " + line); }

int Run(int argc, char** argv) {
  Ros2Options options;
  try {
    const char* domain = std::getenv("ROS_DOMAIN_ID");
    options = ParseRos2Options(std::vector<std::string>(argv + 1, argv + argc), domain ? domain : "");
  } catch (const robotalk::Error& e) {
    Say(e.what());
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
    if (options.stats) {
      std::vector<std::string> lines;
      std::istringstream text(bridge.StatsText());
      for (std::string line; std::getline(text, line);) lines.push_back(line);
      LogWriter out("", 1);
      out.Write(lines);
    }
    pthread_kill(waiter.native_handle(), SIGTERM);  // wakes sigwait if no signal came
    waiter.join();
  } catch (const std::exception& e) {
    Say(e.what());
    return 1;
  }
  return 0;
}

}  // namespace
}  // namespace robotalk::ros2

int main(int argc, char** argv) {
  robotalk::OpenStandardDescriptors();  // first: nothing of ours on descriptors 0-2
  const int status = robotalk::ros2::Run(argc, argv);
  robotalk::LogWriter::Stderr().Flush();  // the count of lines lost, if any is unsaid (within kMaxWait)
  return status;
}
