#include "web_options.h"

#include "robotalk/channels.h"  // kAnnounceHeardWithin
#include "robotalk/error.h"
#include "robotalk/option_reader.h"
#include "robotalk/sequence_file.h"  // ParseNumberIn, ParseSeconds

#include <algorithm>
#include <cstdio>

namespace robotalk::web {
namespace {

void AppendPaths(const std::string& list, std::vector<std::string>& paths) {
  std::size_t start = 0;
  while (start <= list.size()) {
    const std::size_t end = std::min(list.find(':', start), list.size());
    if (end > start) paths.push_back(list.substr(start, end - start));
    start = end + 1;
  }
}

}  // namespace

std::pair<std::string, std::string> ParseUrdfOption(const std::string& v) {
  const auto eq = v.find('=');
  if (eq == std::string::npos || eq == 0 || eq + 1 == v.size())
    throw Error("--urdf: '" + v + "' is not NAME=PATH");
  return {v.substr(0, eq), v.substr(eq + 1)};
}

void AppendPackagePaths(const std::string& v, std::vector<std::string>& paths) {
  const std::size_t before = paths.size();
  AppendPaths(v, paths);
  if (paths.size() == before) throw Error("--package-path: '" + v + "' names no folder");
}

std::string WebUsage() {
  return "usage: robotalk-web [options]\n"
         "Shows every robot announced on the LCM bus in a browser: a 3D view moving with\n"
         "the state stream, the base path, joint plots, panic state and a PANIC button.\n"
         "  --bind ADDR        listen address (default 127.0.0.1; 0.0.0.0 offers the page,\n"
         "                     and its PANIC button, to the whole network)\n"
         "  --port N           TCP port (default 8080; 0 = any free port)\n"
         "  --lcm-url URL      LCM URL (default: LCM_DEFAULT_URL or LCM's default)\n"
         "  --rate HZ          state frames per second sent to the page (default 30)\n"
         "  --urdf NAME=PATH   draw robot NAME from this URDF with urdf-loader (repeatable)\n"
         "  --package-path DIRS folders holding the packages of package:// meshes\n"
         "                     (colon-separated, repeatable; then $ROS_PACKAGE_PATH)\n"
         "  --key FILE         keyed mode: this bridge's secret key (default: $ROBOTALK_KEY)\n"
         "  --server-key FILE  keyed mode: track only robots this server key announced\n"
         "  --robot-timeout S  a robot not announced for S seconds is shown as gone (default 3)\n"
         "  --max-websockets N WebSocket clients (pages and Foxglove) open at once; one more\n"
         "                     is refused with HTTP 503, unless its address holds fewer\n"
         "                     than the address holding most (2 or more), whose oldest\n"
         "                     is then closed (default 64, 1-4096)\n"
         "  --max-http-waiting N HTTP connections waiting for a request (idle, or a request\n"
         "                     not yet whole) or for their answer to be read, at once; one\n"
         "                     more closes the oldest of the address holding most\n"
         "                     (default 64, 1-4096)\n"
         "  --www DIR          the page's files (default: share/robotalk/web/www of this\n"
         "                     installation, else tools/web/www of the sources)\n"
         "  --node-modules DIR npm modules holding three and urdf-loader (default:\n"
         "                     node_modules beside the default www)\n"
         "  --version          print the version and exit\n"
         "  -h, --help         print this help and exit\n"
         "It sends queries (CONFIG, CLOCK, STATE_STREAM) and heartbeats, and a package\n"
         "with the panic flag when the page's PANIC button is pressed; never a command.\n";
}

WebOptions ParseWebOptions(const std::vector<std::string>& args, const std::string& default_www,
                           const std::string& default_modules, const std::string& ros_package_path) {
  WebOptions o;
  o.www_dir = default_www;
  o.node_modules_dir = default_modules;
  OptionReader r(args);
  while (r.Next()) {
    const std::string& a = r.word();
    if (r.IsHelp()) {
      o.help = true;
    } else if (r.IsVersion()) {
      o.version = true;
    } else if (a == "--bind") {
      o.bind = r.Value();
      if (o.bind.empty()) throw Error("--bind: empty address");
    } else if (a == "--port") {
      o.port = static_cast<int>(ParseNumberIn(r.Value(), a, {.min = 0, .max = 65535, .whole = true}));
    } else if (a == "--lcm-url") {
      o.lcm_url = r.Value();
    } else if (a == "--rate") {
      o.rate_hz = ParseNumberIn(r.Value(), a, {.min = 1, .max = 240});
    } else if (a == "--robot-timeout") {
      const std::string& text = r.Value();
      o.robot_timeout_s = ParseSeconds(text, a);  // within what every time given as text may be
      if (o.robot_timeout_s < ToSeconds(kAnnounceHeardWithin)) {
        char shortest[32];
        std::snprintf(shortest, sizeof shortest, "%g", ToSeconds(kAnnounceHeardWithin));
        throw Error("--robot-timeout: " + text + " s is shorter than " + shortest +
                    " s (servers announce every second)");
      }
    } else if (a == "--max-websockets" || a == "--max-http-waiting") {
      (a == "--max-websockets" ? o.max_websockets : o.max_http_waiting) =
          static_cast<int>(ParseNumberIn(r.Value(), a, {.min = 1, .max = 4096, .whole = true}));
    } else if (a == "--key") {
      o.key_file = r.Value();
      if (o.key_file.empty()) throw Error("--key: the file name is empty");
    } else if (a == "--server-key") {
      o.server_key_file = r.Value();
      if (o.server_key_file.empty()) throw Error("--server-key: the file name is empty");
    } else if (a == "--urdf") {
      auto [name, path] = ParseUrdfOption(r.Value());
      o.urdf[name] = path;
    } else if (a == "--package-path") {
      AppendPackagePaths(r.Value(), o.package_paths);
    } else if (a == "--www") {
      o.www_dir = r.Value();
    } else if (a == "--node-modules") {
      o.node_modules_dir = r.Value();
    } else {
      r.Unknown();
    }
  }
  AppendPaths(ros_package_path, o.package_paths);
  return o;
}

}  // namespace robotalk::web
