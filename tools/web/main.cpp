// robotalk-web: shows every robot on the LCM bus in a browser (docs/web.md).
#include "robot_tracker.h"
#include "robotalk/error.h"
#include "robotalk/log_writer.h"  // OpenStandardDescriptors
#include "web_install_dirs.h"
#include "web_log.h"
#include "web_options.h"
#include "web_server.h"

#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <string>

namespace robotalk::web {
namespace {

// Its lines go through WebLog() (stderr) and, for "open http://...", a
// writer of stdout: a stdout or stderr that takes nothing (a full pipe, a
// terminal stopped with Ctrl-S) holds it LogWriter::kMaxWait at most, so it
// serves (and forwards the page's PANIC) all the same, and a start-up error
// still ends it with its status.
int Run(int argc, char** argv) {
  WebOptions options;
  try {
    const char* ros_package_path = std::getenv("ROS_PACKAGE_PATH");
    const WebDirs dirs =
        DefaultWebDirs(RunningBinaryDir(), ROBOTALK_WEB_DATA_FROM_BIN, ROBOTALK_WEB_SOURCE_DIR);
    options = ParseWebOptions(std::vector<std::string>(argv + 1, argv + argc), dirs.www, dirs.node_modules,
                              ros_package_path ? ros_package_path : "");
  } catch (const robotalk::Error& e) {
    WebLog().Write(e.what());
    return 2;
  }
  if (options.help) {
    std::cout << WebUsage();
    return 0;
  }
  if (options.version) {
    std::cout << "robotalk-web " << ROBOTALK_WEB_VERSION << "\n";
    return 0;
  }
  namespace fs = std::filesystem;
  for (const char* module : {"three", "urdf-loader"}) {
    if (!fs::is_directory(fs::path(options.node_modules_dir) / module)) {
      WebLog().Write(options.node_modules_dir + "/" + module +
                     " is missing: give --node-modules, or run scripts/setup.sh (npm ci in tools/web) "
                     "before building and installing");
      return 1;
    }
  }
  for (const auto& [name, path] : options.urdf) {
    if (!fs::is_regular_file(path)) {
      WebLog().Write("--urdf " + name + "=" + path + ": no such file");
      return 2;
    }
  }
  for (const std::string& dir : options.package_paths) {
    if (!fs::is_directory(dir)) WebLog().Write("package path " + dir + ": no such folder (skipped)");
  }
  try {
    RobotTracker tracker(options);
    WebServer server(options, tracker);
    for (const auto& [name, catalog] : server.meshes()) {  // the page notes the same under the robot's view
      if (!catalog.error.empty())
        WebLog().Write("--urdf " + name + ": " + catalog.error);
      else if (!catalog.geometry_error.empty())
        WebLog().Write("--urdf " + name + ": " + catalog.geometry_error +
                       " (Foxglove's scene shows its inertia boxes)");
      std::size_t told = 0;
      for (const MeshEntry& m : catalog.meshes) {
        if (!m.error.empty() && ++told <= 5)
          WebLog().Write(name + ": link '" + m.link + "': mesh " + m.uri + ": " + m.error);
      }
      if (told > 0)
        WebLog().Write(name + ": " + std::to_string(told) + " of " + std::to_string(catalog.meshes.size()) +
                       " meshes not resolved; the page draws their links from the configuration, Foxglove's "
                       "scene as inertia boxes");
    }
    {
      LogWriter out("robotalk-web: ", 1);  // stdout's one line
      out.Write("open http://" + (options.bind == "0.0.0.0" ? std::string("127.0.0.1") : options.bind) + ":" +
                std::to_string(server.port()) + "/");
    }
    server.Run();
  } catch (const std::exception& e) {
    WebLog().Write(e.what());
    return 1;
  }
  return 0;
}

}  // namespace
}  // namespace robotalk::web

int main(int argc, char** argv) {
  robotalk::OpenStandardDescriptors();  // first: nothing of ours on descriptors 0-2
  const int status = robotalk::web::Run(argc, argv);
  robotalk::LogWriter::Stderr().Flush();  // the count of lines lost, if any is unsaid (within kMaxWait)
  return status;
}
