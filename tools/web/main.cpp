// robotalk-web: shows every robot on the LCM bus in a browser (docs/web.md).
#include "robot_tracker.h"
#include "robotalk/error.h"
#include "web_install_dirs.h"
#include "web_options.h"
#include "web_server.h"

#include <cstdlib>
#include <filesystem>
#include <iostream>

int main(int argc, char** argv) {
  using namespace robotalk::web;
  WebOptions options;
  try {
    const char* ros_package_path = std::getenv("ROS_PACKAGE_PATH");
    const WebDirs dirs =
        DefaultWebDirs(RunningBinaryDir(), ROBOTALK_WEB_DATA_FROM_BIN, ROBOTALK_WEB_SOURCE_DIR);
    options = ParseWebOptions(std::vector<std::string>(argv + 1, argv + argc), dirs.www, dirs.node_modules,
                              ros_package_path ? ros_package_path : "");
  } catch (const robotalk::Error& e) {
    std::cerr << "robotalk-web: " << e.what() << "\n";
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
      std::cerr << "robotalk-web: " << options.node_modules_dir << "/" << module
                << " is missing: give --node-modules, or run scripts/setup.sh (npm ci in tools/web) "
                   "before building and installing\n";
      return 1;
    }
  }
  for (const auto& [name, path] : options.urdf) {
    if (!fs::is_regular_file(path)) {
      std::cerr << "robotalk-web: --urdf " << name << "=" << path << ": no such file\n";
      return 2;
    }
  }
  for (const std::string& dir : options.package_paths) {
    if (!fs::is_directory(dir))
      std::cerr << "robotalk-web: package path " << dir << ": no such folder (skipped)\n";
  }
  try {
    RobotTracker tracker(options);
    WebServer server(options, tracker);
    for (const auto& [name, catalog] : server.meshes()) {  // the page notes the same under the robot's view
      if (!catalog.error.empty())
        std::cerr << "robotalk-web: --urdf " << name << ": " << catalog.error << "\n";
      else if (!catalog.geometry_error.empty())
        std::cerr << "robotalk-web: --urdf " << name << ": " << catalog.geometry_error
                  << " (Foxglove's scene shows its inertia boxes)\n";
      std::size_t told = 0;
      for (const MeshEntry& m : catalog.meshes) {
        if (!m.error.empty() && ++told <= 5)
          std::cerr << "robotalk-web: " << name << ": link '" << m.link << "': mesh " << m.uri << ": "
                    << m.error << "\n";
      }
      if (told > 0)
        std::cerr << "robotalk-web: " << name << ": " << told << " of " << catalog.meshes.size()
                  << " meshes not resolved; the page draws their links from the configuration, Foxglove's "
                     "scene as inertia boxes\n";
    }
    std::cout << "robotalk-web: open http://" << (options.bind == "0.0.0.0" ? "127.0.0.1" : options.bind)
              << ":" << server.port() << "/" << std::endl;
    server.Run();
  } catch (const std::exception& e) {
    std::cerr << "robotalk-web: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
