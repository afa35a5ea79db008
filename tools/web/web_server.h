// WebServer: robotalk-web's HTTP and WebSocket side, on Boost.Beast
// (docs/web.md). It serves the page's files, the three / urdf-loader modules
// from node_modules, the URDF files given with --urdf (and files beside
// them), each such robot's mesh catalog at /meshes/NAME and the mesh files
// it resolved at /mesh/NAME/... (mesh_catalog.h; a request path with a "."
// or ".." segment, a backslash or a percent escape is refused 403, naming
// it), and one WebSocket at /ws that carries JSON: it polls the RobotTracker
// when a state sample arrives (at most `rate` times a second) and every
// `1/rate` s without samples, and pushes the robots list when it changed,
// each new model, and each robot's newest state. It reads one kind of
// message from the page: {"type":"panic","robot":NAME}. Upgrades offering
// the foxglove.websocket.v1 subprotocol go to the FoxgloveEndpoint
// (foxglove_endpoint.h), fed by the same polls.
//
// Thread safety: everything runs on the thread that calls Run(); Stop() may
// be called from any thread (or a signal handler's strand via asio).
// Errors: the constructor throws robotalk::Error when it cannot listen
// (address in use, bad address). Per-connection failures close that
// connection only.
#pragma once

#include "mesh_catalog.h"
#include "robot_tracker.h"
#include "web_options.h"

#include <map>
#include <memory>
#include <string>

namespace robotalk::web {

class WebServer {
 public:
  WebServer(const WebOptions& options, RobotTracker& tracker);
  ~WebServer();
  WebServer(const WebServer&) = delete;
  WebServer& operator=(const WebServer&) = delete;

  /// The TCP port listened on (the chosen one when options.port was 0).
  int port() const;
  /// The mesh catalog of every --urdf robot, by name (resolved in the constructor).
  const std::map<std::string, MeshCatalog>& meshes() const;
  /// Serves until Stop() or SIGINT / SIGTERM.
  void Run();
  void Stop();

 private:
  class Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace robotalk::web
