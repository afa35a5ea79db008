#include "ws_connection.h"

#include "web_log.h"

#include <boost/asio.hpp>

#include <algorithm>
#include <iterator>

namespace robotalk::web {
namespace {

// What a client may be behind on among the messages it must receive (not
// droppable): beyond it, the client does not read what it asked for, and is
// closed rather than queued for without bound.
constexpr std::size_t kMaxBacklogBytes = 64u << 20;
constexpr std::size_t kMaxBacklogMessages = 4096;

}  // namespace

namespace asio = boost::asio;
namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;

WsConnection::WsConnection(asio::ip::tcp::socket socket, std::size_t max_message, std::size_t max_droppable,
                           OnMessage on_message)
    : ws_(std::move(socket)),
      max_message_(max_message),
      max_droppable_(max_droppable),
      on_message_(std::move(on_message)) {}

void WsConnection::Start(http::request<http::string_body> request, std::vector<Message> greeting,
                         const std::string& subprotocol) {
  ws_.set_option(websocket::stream_base::timeout::suggested(beast::role_type::server));
  ws_.set_option(websocket::stream_base::decorator([subprotocol](websocket::response_type& res) {
    res.set(http::field::server, "robotalk-web");
    if (!subprotocol.empty()) res.set(http::field::sec_websocket_protocol, subprotocol);
  }));
  ws_.read_message_max(max_message_);
  accepting_ = true;
  ws_.async_accept(request,
                   [self = shared_from_this(), greeting = std::move(greeting)](beast::error_code ec) {
                     self->accepting_ = false;
                     if (ec) return;
                     self->open_ = true;
                     for (const Message& m : greeting) self->Send(m, false, false);
                     self->Read();
                   });
}

void WsConnection::Send(const Message& m, bool binary, bool droppable, const std::string& supersedes) {
  if (!open_) return;
  if (!supersedes.empty()) {
    const auto older = std::find_if(std::next(queue_.begin(), queue_.empty() ? 0 : 1), queue_.end(),
                                    [&](const Queued& q) { return q.supersedes == supersedes; });
    if (older != queue_.end()) {
      // The older goes; the newer is queued last like any message, so it
      // never arrives before what was queued after the older one.
      queued_bytes_ -= older->message->size();
      queue_.erase(older);
      queue_.push_back({m, binary, supersedes});
      queued_bytes_ += m->size();
      return;
    }
  }
  if (droppable && queue_.size() >= max_droppable_) {
    ++dropped_;
    return;
  }
  if (!droppable && (queue_.size() >= kMaxBacklogMessages || queued_bytes_ + m->size() > kMaxBacklogBytes)) {
    Close("it has not read " + std::to_string(queue_.size()) + " messages (" +
          std::to_string(queued_bytes_ >> 20) + " MiB) it must receive; the limit is " +
          std::to_string(kMaxBacklogMessages) + " messages or " + std::to_string(kMaxBacklogBytes >> 20) +
          " MiB");
    return;
  }
  queue_.push_back({m, binary, supersedes});
  queued_bytes_ += m->size();
  if (queue_.size() == 1) Write();
}

void WsConnection::Close(const std::string& why, bool say) {
  open_ = false;
  beast::error_code ec;
  auto& socket = beast::get_lowest_layer(ws_).socket();
  if (!say) {
    socket.close(ec);
    return;
  }
  const auto peer = socket.remote_endpoint(ec);
  // Through WebLog(): a stderr whose reader went away loses the line (EPIPE,
  // not SIGPIPE: robotalk-web died here), and one that takes nothing holds
  // this thread at most LogWriter::kMaxWait.
  WebLog().Write(
      "closing the WebSocket of " +
      (ec ? std::string("a client") : peer.address().to_string() + ":" + std::to_string(peer.port())) + ": " +
      why);
  socket.close(ec);  // the write and read in flight end with an error; the owner drops it
}

void WsConnection::Write() {
  ws_.binary(queue_.front().binary);
  ws_.async_write(asio::buffer(*queue_.front().message),
                  [self = shared_from_this()](beast::error_code ec, std::size_t) {
                    if (ec) {
                      self->open_ = false;
                      return;
                    }
                    self->queued_bytes_ -= self->queue_.front().message->size();
                    self->queue_.pop_front();
                    if (!self->queue_.empty()) self->Write();
                  });
}

void WsConnection::Read() {
  ws_.async_read(in_, [self = shared_from_this()](beast::error_code ec, std::size_t) {
    if (ec) {
      self->open_ = false;
      return;
    }
    const std::string data = beast::buffers_to_string(self->in_.data());
    self->in_.consume(self->in_.size());
    self->on_message_(self, data, self->ws_.got_text());
    self->Read();
  });
}

}  // namespace robotalk::web
