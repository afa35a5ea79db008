// Command-line options of robotalk-web (docs/web.md, "Running it").
//
// Thread safety: pure functions. Errors: ParseWebOptions throws robotalk::Error
// naming the bad argument ("unknown option '--x'", "--port: 'abc' is not ...").
#pragma once

#include "robotalk/clock.h"

#include <map>
#include <string>
#include <utility>
#include <vector>

namespace robotalk::web {

struct WebOptions {
  /// Address the HTTP/WebSocket server listens on. Loopback by default: the
  /// page can PANIC a robot, so it is not offered to the network unless asked.
  std::string bind = "127.0.0.1";
  /// TCP port; 0 = any free port (printed on stdout).
  int port = 8080;
  /// LCM URL; "" = LCM's default (LCM_DEFAULT_URL or udpm://239.255.76.67:7667?ttl=0).
  std::string lcm_url;
  /// Frames per second pushed to each browser (state samples are decimated to this).
  double rate_hz = 30.0;
  /// 1 / rate_hz: the STATE stream's period and the page's frame period.
  /// Throws Error (FromSeconds) when rate_hz is 0 or not finite.
  Duration period() const { return FromSeconds(1.0 / rate_hz); }
  /// The page's files (index.html, app.js, ...).
  std::string www_dir;
  /// The npm modules folder holding three and urdf-loader.
  std::string node_modules_dir;
  /// Robot name -> URDF file: the page draws that robot with urdf-loader
  /// from this file (and the meshes beside it) instead of from its configuration.
  std::map<std::string, std::string> urdf;
  /// Folders searched for the packages of package:// mesh names (--package-path,
  /// colon-separated and repeatable, then $ROS_PACKAGE_PATH); meshes are served
  /// only from below these and the URDF's own folder (mesh_catalog.h).
  std::vector<std::string> package_paths;
  /// Keyed mode (docs/security.md): the bridge's own secret key (--key;
  /// empty: $ROBOTALK_KEY if set, else open mode) and the servers' public key
  /// (--server-key): with it, only robots that key announced are tracked and
  /// connected (others' names, forged or not, never reach the table).
  std::string key_file;
  std::string server_key_file;
  /// A robot is shown as gone when no announce named it for this long (s).
  double robot_timeout_s = 3.0;
  /// WebSocket clients open at once, the page's and Foxglove's together
  /// (each holds a descriptor and its queues); one more is refused with HTTP
  /// 503 naming this limit, unless its address holds fewer than the address
  /// holding the most (2 or more), whose oldest is then closed
  /// (--max-websockets).
  int max_websockets = 64;
  /// Plain HTTP connections waiting for a request (idle between requests, or
  /// a request not yet whole) or for their answer to be read, at once; each
  /// holds a descriptor for up to 30 s. One more closes the oldest of the
  /// address holding the most, so a flood of idle connections or slow
  /// readers never keeps a new client out (--max-http-waiting).
  int max_http_waiting = 64;
  bool help = false;
  bool version = false;
};

/// Parses argv[1..]. `default_www` and `default_modules` fill www_dir and
/// node_modules_dir when no option gives them; `ros_package_path` (the
/// environment's ROS_PACKAGE_PATH, colon-separated) is appended to the
/// --package-path folders.
WebOptions ParseWebOptions(const std::vector<std::string>& args, const std::string& default_www,
                           const std::string& default_modules, const std::string& ros_package_path = "");

/// The NAME and PATH of a --urdf NAME=PATH value (robotalk-web, and
/// robotalk-logplay export --mcap); throws Error naming a value that is not.
std::pair<std::string, std::string> ParseUrdfOption(const std::string& value);
/// Appends the folders of a --package-path value (colon-separated); throws
/// Error when it names none.
void AppendPackagePaths(const std::string& value, std::vector<std::string>& paths);

/// The --help text.
std::string WebUsage();

}  // namespace robotalk::web
