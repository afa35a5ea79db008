// WsConnection: one server-side WebSocket of robotalk-web, on Boost.Beast:
// the page's /ws (web_server.cpp) and each Foxglove client
// (foxglove_endpoint.cpp). It accepts the upgrade (answering with a
// subprotocol when given), sends a greeting, keeps a write queue and hands
// every message it reads to a callback. A client that cannot keep up loses
// droppable messages once `max_droppable` are queued, never the others; a
// client more than 64 MiB or 4096 messages behind on the others (it asks
// and does not read the answers) is closed, the reason on stderr.
//
// Thread safety: everything on the io_context's thread.
// Errors: none thrown; a failed accept, read or write closes the connection
// (open() turns false) and the owner drops it.
#pragma once

#include <boost/asio/ip/tcp.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>

#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace robotalk::web {

class WsConnection : public std::enable_shared_from_this<WsConnection> {
 public:
  using Message = std::shared_ptr<const std::string>;
  /// Called with each message read: its bytes and whether it was text.
  using OnMessage =
      std::function<void(const std::shared_ptr<WsConnection>&, const std::string& data, bool text)>;

  /// Messages longer than `max_message` bytes close the connection.
  WsConnection(boost::asio::ip::tcp::socket socket, std::size_t max_message, std::size_t max_droppable,
               OnMessage on_message);

  /// Accepts the upgrade `request`; then sends `greeting` (text) and reads.
  /// A non-empty `subprotocol` is named in the answer (Sec-WebSocket-Protocol).
  void Start(boost::beast::http::request<boost::beast::http::string_body> request,
             std::vector<Message> greeting, const std::string& subprotocol = "");
  bool open() const { return open_; }
  /// Open, or its upgrade being answered (what WebOptions::max_websockets counts).
  bool live() const { return accepting_ || open_; }
  /// Queues one message (text or binary); a droppable one is dropped when the
  /// queue is full. A non-empty `supersedes` names what the message is the
  /// newest of (the robots list, one robot's model): a queued one of the same
  /// name not yet being written is dropped and this one queued last, so a
  /// client behind holds one of each, whatever the rate they change at
  /// (anyone announcing made-up robots changes the list), and gets every
  /// message in the order sent.
  void Send(const Message& m, bool binary, bool droppable, const std::string& supersedes = "");
  std::uint64_t dropped() const { return dropped_; }
  /// Closes it, saying so on stderr with `why` unless `say` is false (the
  /// caller says it); the write and read in flight end with an error and its
  /// owner drops it.
  void Close(const std::string& why, bool say = true);

 private:
  void Write();
  void Read();

  boost::beast::websocket::stream<boost::beast::tcp_stream> ws_;
  std::size_t max_message_, max_droppable_;
  OnMessage on_message_;
  boost::beast::flat_buffer in_;
  struct Queued {
    Message message;
    bool binary = false;
    std::string supersedes;  // Send's: "" for none
  };
  std::deque<Queued> queue_;      // the front is being written
  std::size_t queued_bytes_ = 0;  // of queue_'s messages
  bool open_ = false;
  bool accepting_ = false;  // Start() until the upgrade's answer is written (or failed)
  std::uint64_t dropped_ = 0;
};

}  // namespace robotalk::web
