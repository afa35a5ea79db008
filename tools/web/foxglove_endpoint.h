// FoxgloveEndpoint: robotalk-web's side of the Foxglove WebSocket protocol
// (subprotocol "foxglove.websocket.v1", JSON messages with JSON Schemas;
// docs/interop.md). A WebSocket upgrade on any path that offers that
// subprotocol is handed here by WebServer; the page's /ws stays as it was.
//
// Per connection it sends serverInfo, advertises the channels of every robot
// with a model (foxglove_messages.h; more as robots appear; unadvertised
// when the tracker forgets them, so it keeps only the robots of the
// tracker's bounded table) and, when the bridge was given a panic handler,
// one service "/robotalk/panic" (request {"robot": NAME}). It reads subscribe / unsubscribe and service
// calls; anything else gets a status message naming it. Each robot's state
// reaches a subscriber at the web loop's rate (--rate, decimated by the
// tracker); a subscriber of /ROBOT/scene gets the current scene at once, and
// again only when the robot's model changes (never with a state). A robot
// the bridge has a URDF for (--urdf) is drawn from it; its meshes' URLs are
// http://HOST/mesh/..., HOST as the client's upgrade request named the
// bridge (its Host header), where WebServer serves them.
// A client that cannot keep up loses state messages, never an advertisement,
// a scene or a service answer.
//
// Thread safety: everything on the io_context's thread (Update, Accept);
// the panic handler's `done` may be called from any thread.
// Errors: nothing thrown to the caller; a bad client message closes nothing,
// it is answered with a status (level 2) naming what was wrong.
#pragma once

#include "mesh_catalog.h"
#include "robot_tracker.h"

#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/beast/http/message.hpp>
#include <boost/beast/http/string_body.hpp>

#include <cstddef>
#include <functional>
#include <map>
#include <memory>
#include <string>

namespace robotalk::web {

class WsConnection;

class FoxgloveEndpoint {
 public:
  /// Sends a panic to `robot` and calls `done` (any thread) with "" or why it failed.
  using PanicHandler =
      std::function<void(const std::string& robot, std::function<void(const std::string& error)> done)>;
  /// The subprotocol this endpoint speaks.
  static constexpr const char* kSubprotocol = "foxglove.websocket.v1";

  /// `panic` empty: no services are offered (the endpoint is read-only).
  /// `geometry`: each --urdf robot's URDF as read at start (by robot name).
  FoxgloveEndpoint(std::shared_ptr<boost::asio::io_context> ioc, PanicHandler panic,
                   std::map<std::string, MeshCatalog> geometry = {});
  ~FoxgloveEndpoint();
  FoxgloveEndpoint(const FoxgloveEndpoint&) = delete;
  FoxgloveEndpoint& operator=(const FoxgloveEndpoint&) = delete;

  /// Whether an upgrade request offers kSubprotocol (Sec-WebSocket-Protocol).
  static bool Offered(const boost::beast::http::request<boost::beast::http::string_body>& request);
  /// Takes a connection whose upgrade request offered kSubprotocol; returns
  /// its WebSocket (for WebOptions::max_websockets' count and closing).
  std::shared_ptr<WsConnection> Accept(boost::asio::ip::tcp::socket socket,
                                       boost::beast::http::request<boost::beast::http::string_body> request);
  /// One web-loop tick: new models (advertised, scenes sent) and the newest
  /// state of each robot (to the subscribers of its channels).
  void Update(const TrackerFrame& frame);
  /// Whether any Foxglove client is connected (the tracker streams while one is).
  bool connected() const { return connections() > 0; }
  /// How many Foxglove clients are connected (WebOptions::max_websockets counts them).
  std::size_t connections() const;

 private:
  class Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace robotalk::web
