#include "web_server.h"

#include "foxglove_endpoint.h"
#include "json_text.h"
#include "mesh_catalog.h"
#include "robotalk/error.h"
#include "web_files.h"
#include "web_log.h"
#include "ws_connection.h"

#include <boost/asio.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/version.hpp>
#include <boost/beast/websocket.hpp>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdlib>
#include <deque>
#include <map>
#include <string>
#include <vector>

namespace robotalk::web {
namespace {

namespace asio = boost::asio;
namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
using tcp = asio::ip::tcp;
using Message = std::shared_ptr<const std::string>;

// A browser that cannot keep up loses state frames (never robots/models).
constexpr std::size_t kMaxQueuedFrames = 8;
// The page sends only {"type":"panic","robot":NAME}: anything longer is refused.
constexpr std::size_t kMaxPageMessage = 4096;

bool StartsWith(std::string_view s, std::string_view prefix) { return s.substr(0, prefix.size()) == prefix; }

// A request path that tries to leave the served folders: a "." or ".."
// segment, a backslash, or a percent escape (which could hide either).
// Browsers normalise "../" away before sending; what arrives is deliberate.
bool Traverses(std::string_view path) {
  if (path.find_first_of("\\%") != std::string_view::npos) return true;
  std::size_t start = 0;
  while (start < path.size()) {
    const std::size_t end = std::min(path.find('/', start), path.size());
    const std::string_view seg = path.substr(start, end - start);
    if (seg == "." || seg == "..") return true;
    start = end + 1;
  }
  return false;
}

}  // namespace

class WebServer::Impl {
 public:
  Impl(const WebOptions& o, RobotTracker& tracker)
      : options_(o), tracker_(tracker), acceptor_(*ioc_), tick_(*ioc_), signals_(*ioc_, SIGINT, SIGTERM) {
    beast::error_code ec;
    const auto address = asio::ip::make_address(o.bind, ec);
    if (ec) throw Error("robotalk-web: --bind '" + o.bind + "': " + ec.message());
    const tcp::endpoint ep(address, static_cast<unsigned short>(o.port));
    acceptor_.open(ep.protocol(), ec);
    if (!ec) acceptor_.set_option(asio::socket_base::reuse_address(true), ec);
    if (!ec) acceptor_.bind(ep, ec);
    if (!ec) acceptor_.listen(asio::socket_base::max_listen_connections, ec);
    if (ec)
      throw Error("robotalk-web: cannot listen on " + o.bind + ":" + std::to_string(o.port) + ": " +
                  ec.message());
    period_ = o.period();
    for (const auto& [robot, urdf] : o.urdf) meshes_[robot] = ResolveMeshes(robot, urdf, o.package_paths);
    // PANIC from Foxglove only when the bridge holds a key: a keyed server
    // then decides by the bridge's rights (docs/interop.md).
    FoxgloveEndpoint::PanicHandler panic;
    if (std::getenv("ROBOTALK_KEY") != nullptr)
      panic = [this](const std::string& robot, auto done) { tracker_.Panic(robot, std::move(done)); };
    foxglove_ = std::make_unique<FoxgloveEndpoint>(ioc_, std::move(panic), meshes_);
    // A sample is sent when it arrives, not at the next tick (a tick that
    // polls just before each sample would add a whole period); at most one
    // wake-up in flight. The listener may outlive this server: it holds the
    // io_context, which runs no handler once Run() has returned.
    tracker_.SetOnSample([ioc = ioc_, posted = sample_posted_, this] {
      if (!posted->exchange(true)) asio::post(*ioc, [this] { OnSample(); });
    });
  }

  const std::map<std::string, MeshCatalog>& meshes() const { return meshes_; }

  int port() const { return acceptor_.local_endpoint().port(); }

  void Run() {
    signals_.async_wait([this](beast::error_code, int) { Stop(); });
    Accept();
    Tick();
    ioc_->run();
  }

  void Stop() {
    asio::post(*ioc_, [ioc = ioc_] { ioc->stop(); });
  }

 private:
  void Accept() {
    acceptor_.async_accept([this](beast::error_code ec, tcp::socket socket) {
      if (ec == asio::error::operation_aborted) return;
      if (!ec) {
        while (waiting_.size() >= static_cast<std::size_t>(options_.max_http_waiting))
          CloseWaiting("the limit reached");
        ReadRequest(std::make_shared<beast::tcp_stream>(std::move(socket)));
        Accept();
        return;
      }
      // Out of descriptors (EMFILE, ENFILE; connections held open up to the
      // limit): a connection waiting for a request gives its descriptor to
      // the next one in the backlog (a flood of idle connections never keeps
      // the page and its PANIC button out); with none, the next try comes
      // after a pause (re-armed at once, this thread spun), the connections
      // waiting meanwhile stay in the listen backlog.
      if ((ec == asio::error::no_descriptors || ec == boost::system::errc::too_many_files_open_in_system) &&
          CloseWaiting("out of descriptors"))
        return Accept();
      accept_pause_.expires_after(std::chrono::milliseconds(100));
      accept_pause_.async_wait([this](beast::error_code wait) {
        if (!wait) Accept();
      });
    });
  }

  void ReadRequest(std::shared_ptr<beast::tcp_stream> stream) {
    auto buffer = std::make_shared<beast::flat_buffer>();
    auto req = std::make_shared<http::request<http::string_body>>();
    stream->expires_after(std::chrono::seconds(30));
    const std::uint64_t id = Hold(stream);
    http::async_read(
        *stream, *buffer, *req, [this, stream, buffer, req, id](beast::error_code ec, std::size_t) {
          waiting_.erase(id);
          if (ec) return;
          const asio::ip::address address = RemoteAddress(*stream);
          // Only an upgrade the bridge takes counts against the limit (another
          // path's gets 404 from Respond and must close nobody's).
          const bool foxglove = websocket::is_upgrade(*req) && FoxgloveEndpoint::Offered(*req);  // any path
          const bool page = websocket::is_upgrade(*req) && !foxglove &&
                            std::string_view(req->target().data(), req->target().size()) == "/ws";
          if ((foxglove || page) && OpenWebSockets() >= static_cast<std::size_t>(options_.max_websockets) &&
              !CloseWebSocketFor(address))
            return RefuseWebSocket(stream, std::move(*req));
          if (foxglove) {
            stream->expires_never();
            websockets_.push_back({foxglove_->Accept(stream->release_socket(), std::move(*req)), address});
            return;
          }
          if (page) {
            stream->expires_never();
            auto session = std::make_shared<WsConnection>(
                stream->release_socket(), kMaxPageMessage, kMaxQueuedFrames,
                [this](const std::shared_ptr<WsConnection>& s, const std::string& text, bool) {
                  OnPageMessage(s, text);
                });
            sessions_.push_back(session);
            websockets_.push_back({session, address});
            session->Start(std::move(*req), Greeting());
            return;
          }
          Respond(stream, std::move(*req));
        });
  }

  // The page's open WebSockets and Foxglove's: what --max-websockets bounds.
  std::size_t OpenWebSockets() {
    std::erase_if(websockets_, [](const WebSocket& w) {
      const auto c = w.connection.lock();
      return !c || !c->live();
    });
    return websockets_.size();
  }

  // At --max-websockets, a WebSocket asked for from `address`: closes the
  // oldest of the address holding the most when that address holds two or
  // more and `address` fewer (a flood from one address never keeps the
  // operator's page, and its PANIC button, out), and says so on stderr once a
  // second at most (an attacker with two addresses makes it close one of its
  // own per new one); false, refused, when `address` holds the most itself or
  // every address holds one: a lone WebSocket (an operator's open page) is
  // never closed for another's.
  bool CloseWebSocketFor(const asio::ip::address& address) {
    std::map<asio::ip::address, std::size_t> per_address;
    std::size_t most = 0;
    for (const WebSocket& w : websockets_) most = std::max(most, ++per_address[w.address]);
    if (most < 2 || per_address[address] >= most) return false;
    const auto oldest = std::find_if(websockets_.begin(), websockets_.end(),
                                     [&](const WebSocket& w) { return per_address[w.address] == most; });
    const asio::ip::address holder = oldest->address;
    if (closed_websockets_.Count())
      WebLog().Write("closed the oldest WebSocket of " + holder.to_string() + ", which held the most (" +
                     std::to_string(most) + "), for one from " + address.to_string() +
                     " at the --max-websockets limit (" + std::to_string(options_.max_websockets) + "; " +
                     std::to_string(closed_websockets_.count) + " closed so far)");
    if (const auto c = oldest->connection.lock()) c->Close("", /*say=*/false);
    websockets_.erase(oldest);
    return true;
  }

  // One WebSocket more than --max-websockets: 503, the limit named, the
  // connection closed; one line on stderr per second at most (a client
  // retrying in a loop would otherwise fill it).
  void RefuseWebSocket(std::shared_ptr<beast::tcp_stream> stream, http::request<http::string_body> req) {
    const std::string why = std::to_string(options_.max_websockets) +
                            " WebSocket clients (pages and Foxglove) are connected already, the "
                            "--max-websockets limit; close one or raise the limit";
    if (refused_websockets_.Count())
      WebLog().Write("refused a WebSocket from " + Peer(*stream) + ": " + why + " (" +
                     std::to_string(refused_websockets_.count) + " refused so far)");
    http::response<http::string_body> res{http::status::service_unavailable, req.version()};
    res.set(http::field::server, "robotalk-web");
    res.set(http::field::content_type, "text/plain; charset=utf-8");
    res.set(http::field::retry_after, "5");
    res.body() = "robotalk-web: " + why + "\n";
    res.keep_alive(false);
    res.prepare_payload();
    auto sp = std::make_shared<decltype(res)>(std::move(res));
    http::async_write(*stream, *sp, [stream, sp](beast::error_code, std::size_t) {
      beast::error_code ignored;
      stream->socket().shutdown(tcp::socket::shutdown_both, ignored);
    });
  }

  // Counts a plain HTTP connection among those --max-http-waiting bounds,
  // until its id is erased from waiting_: while it waits for a request, and
  // while its answer is written (a client that never reads a large answer
  // holds its descriptor as long as one that never finishes its request).
  std::uint64_t Hold(const std::shared_ptr<beast::tcp_stream>& stream) {
    const std::uint64_t id = next_waiting_++;
    waiting_[id] = {stream, RemoteAddress(*stream)};
    return id;
  }

  // Closes the oldest connection waiting for a request or for its answer to
  // be read, of the address that holds the most (a flood from one address never closes a connection of an
  // address holding fewer, the operator's); false when none waits.
  // One line on stderr per second at most, naming `why`.
  bool CloseWaiting(const char* why) {
    if (waiting_.empty()) return false;
    std::map<asio::ip::address, std::size_t> per_address;
    std::size_t most = 0;
    for (const auto& [id, w] : waiting_) most = std::max(most, ++per_address[w.address]);
    auto it = waiting_.begin();
    while (per_address[it->second.address] != most) ++it;
    const asio::ip::address address = it->second.address;
    if (const auto stream = it->second.stream.lock()) stream->close();
    waiting_.erase(it);
    if (closed_waiting_.Count()) {
      WebLog().Write(
          "closed the oldest HTTP connection waiting for a request or for its answer to be read from " +
          address.to_string() + ", which held " + std::to_string(most) + " of the " +
          std::to_string(waiting_.size() + 1) + " waiting: " + why + " (--max-http-waiting " +
          std::to_string(options_.max_http_waiting) + "; " + std::to_string(closed_waiting_.count) +
          " closed so far)");
    }
    return true;
  }

  static asio::ip::address RemoteAddress(beast::tcp_stream& stream) {
    beast::error_code ec;
    const tcp::endpoint ep = stream.socket().remote_endpoint(ec);
    return ec ? asio::ip::address() : ep.address();
  }

  static std::string Peer(beast::tcp_stream& stream) {
    beast::error_code ec;
    const tcp::endpoint ep = stream.socket().remote_endpoint(ec);
    return ec ? std::string("a client") : ep.address().to_string() + ":" + std::to_string(ep.port());
  }

  void Respond(std::shared_ptr<beast::tcp_stream> stream, http::request<http::string_body> req) {
    const bool keep_alive = req.keep_alive();
    auto send = [this, stream, keep_alive](auto res) {
      res.set(http::field::server, "robotalk-web");
      res.set(http::field::cache_control, "no-store");
      res.keep_alive(keep_alive);
      res.prepare_payload();
      auto sp = std::make_shared<decltype(res)>(std::move(res));
      const std::uint64_t id = Hold(stream);
      http::async_write(*stream, *sp, [this, stream, sp, keep_alive, id](beast::error_code ec, std::size_t) {
        waiting_.erase(id);
        if (!ec && keep_alive) ReadRequest(stream);
      });
    };
    auto error = [&](http::status status, const std::string& text) {
      http::response<http::string_body> res{status, req.version()};
      res.set(http::field::content_type, "text/plain; charset=utf-8");
      res.body() = text + "\n";
      send(std::move(res));
    };
    if (req.method() != http::verb::get && req.method() != http::verb::head)
      return error(http::status::method_not_allowed, "only GET and HEAD");
    const std::string target(req.target());
    const std::string_view path_part = std::string_view(target).substr(0, target.find('?'));
    if (Traverses(path_part)) {
      return error(http::status::forbidden,
                   "refused: '" + std::string(path_part) +
                       "' has a '.' or '..' segment, a backslash or a percent escape (path traversal); "
                       "robotalk-web serves only its page, its modules, the --urdf files and the meshes "
                       "they name");
    }
    if (StartsWith(path_part, "/meshes/")) {  // a robot's mesh catalog (mesh_catalog.h)
      const auto it = meshes_.find(std::string(path_part.substr(8)));
      if (it == meshes_.end()) return error(http::status::not_found, "no --urdf for robot: " + target);
      http::response<http::string_body> res{http::status::ok, req.version()};
      res.set(http::field::content_type, "application/json");
      res.body() = JsonText(it->second.Json());
      return send(std::move(res));
    }
    std::optional<std::filesystem::path> path;
    const bool mesh = StartsWith(path_part, "/mesh/");
    if (mesh) {  // only the files the catalog resolved
      const std::string_view rest = path_part.substr(6);
      const auto it = meshes_.find(std::string(rest.substr(0, rest.find('/'))));
      if (it != meshes_.end() && rest.find('/') != std::string_view::npos)
        path = it->second.File(rest.substr(rest.find('/') + 1));
    } else {
      path = ResolveWebPath(target, options_);
    }
    http::file_body::value_type body;
    beast::error_code ec;
    if (path && std::filesystem::is_regular_file(*path)) body.open(path->c_str(), beast::file_mode::scan, ec);
    if (!path || !body.is_open() || ec) return error(http::status::not_found, "not found: " + target);
    const auto size = body.size();
    if (req.method() == http::verb::head) {
      http::response<http::empty_body> res{http::status::ok, req.version()};
      res.set(http::field::content_type, ContentTypeFor(*path));
      res.content_length(size);
      return send(std::move(res));
    }
    http::response<http::file_body> res{std::piecewise_construct, std::make_tuple(std::move(body)),
                                        std::make_tuple(http::status::ok, req.version())};
    res.set(http::field::content_type, ContentTypeFor(*path));
    // Foxglove's 3D panel, a page of another origin, fetches the scene's meshes.
    if (mesh) res.set(http::field::access_control_allow_origin, "*");
    send(std::move(res));
  }

  std::vector<Message> Greeting() const {
    std::vector<Message> g;
    const nlohmann::json hello = {{"type", "hello"},
                                  {"server", "robotalk-web"},
                                  {"version", ROBOTALK_WEB_VERSION},
                                  {"rate", options_.rate_hz}};
    g.push_back(std::make_shared<const std::string>(JsonText(hello)));
    if (robots_) g.push_back(robots_);
    for (const auto& [name, m] : models_) g.push_back(m.second);
    return g;
  }

  // `supersedes`: WsConnection::Send's (the robots list, a robot's model: a
  // page behind holds the newest of each, however often they change).
  void Broadcast(const Message& m, bool droppable, const std::string& supersedes = "") {
    for (auto& s : sessions_) s->Send(m, false, droppable, supersedes);
  }

  void Tick() {
    const auto now = std::chrono::steady_clock::now();
    TrackerFrame f = tracker_.Poll();
    std::erase_if(sessions_,
                  [](const std::shared_ptr<WsConnection>& s) { return s.use_count() == 1 && !s->open(); });
    tracker_.SetWatching(foxglove_->connected() || std::any_of(sessions_.begin(), sessions_.end(),
                                                               [](const auto& s) { return s->open(); }));
    foxglove_->Update(f);
    const std::string robots = JsonText(f.robots);
    if (!robots_ || *robots_ != robots) {
      robots_ = std::make_shared<const std::string>(robots);
      Broadcast(robots_, false, "robots");
    }
    // Only the robots the tracker has (its table is bounded; a forgotten one
    // is not sent to the next page, nor kept).
    std::erase_if(models_,
                  [modelled = ModelledRobots(f)](const auto& m) { return !modelled.count(m.first); });
    for (const TrackerFrame::Model& m : f.models) {
      auto& known = models_[m.robot];
      if (known.second != m.message) {
        known = {m.generation, m.message};
        Broadcast(m.message, false, "model " + m.robot);
      }
    }
    for (std::string& s : f.states) Broadcast(std::make_shared<const std::string>(std::move(s)), true);
    Credit(now);
    if (!f.states.empty()) send_credit_ = std::max(0.0, send_credit_ - 1.0);
    Arm(now + period_, true);  // housekeeping (robots, models) goes on without samples
  }

  // The next tick at `at`; unless `force`, only when that is earlier than the one armed.
  void Arm(std::chrono::steady_clock::time_point at, bool force) {
    if (!force && armed_ && armed_at_ <= at) return;
    armed_ = true;
    armed_at_ = at;
    tick_.expires_at(at);
    tick_.async_wait([this](beast::error_code ec) {
      if (ec) return;  // re-armed
      armed_ = false;
      Tick();
    });
  }

  // States go out as they arrive, `rate` times a second on average: a token
  // bucket earns a send per period and holds at most kMaxCredit. A sample
  // with a whole send of credit goes out at once; one without waits for the
  // tick at which the credit is earned. A stream at the rate itself keeps
  // about one send in hand, so a sample arriving late and the next one on
  // time are both sent as they arrive (with a cap of 1, credit lost to a
  // late sample would never come back, and every later sample would wait
  // for it); faster streams are decimated to the rate, two sends at most at once.
  static constexpr double kMaxCredit = 2.0;

  double Credit(std::chrono::steady_clock::time_point now) {
    const double earned = std::chrono::duration<double>(now - credit_at_).count() * options_.rate_hz;
    send_credit_ = std::min(kMaxCredit, send_credit_ + earned);
    credit_at_ = now;
    return send_credit_;
  }

  void OnSample() {
    sample_posted_->store(false);
    const auto now = std::chrono::steady_clock::now();
    const double credit = Credit(now);
    if (credit >= 1.0)
      Tick();
    else
      Arm(now + std::chrono::duration_cast<std::chrono::steady_clock::duration>((1.0 - credit) * period_),
          false);
  }

  // The page sends only {"type":"panic","robot":NAME}; anything else is ignored.
  void OnPageMessage(const std::shared_ptr<WsConnection>& session, const std::string& text) {
    const nlohmann::json msg = nlohmann::json::parse(text, nullptr, false);
    if (msg.is_object() && msg.value("type", "") == "panic" && msg.contains("robot") &&
        msg["robot"].is_string())
      OnPanic(session, msg["robot"].get<std::string>());
  }

  void OnPanic(std::weak_ptr<WsConnection> session, const std::string& robot) {
    // The callback runs on a tracker thread that may outlive this server: it
    // keeps the io_context alive itself and reaches the session weakly.
    tracker_.Panic(robot, [ioc = ioc_, session, robot](const std::string& error) {
      const nlohmann::json r = {
          {"type", "panic_result"}, {"robot", robot}, {"ok", error.empty()}, {"message", error}};
      auto msg = std::make_shared<const std::string>(JsonText(r));
      asio::post(*ioc, [session, msg] {
        if (auto s = session.lock()) s->Send(msg, false, false);
      });
    });
  }

  const WebOptions options_;
  RobotTracker& tracker_;
  std::shared_ptr<asio::io_context> ioc_ = std::make_shared<asio::io_context>(1);
  tcp::acceptor acceptor_;
  asio::steady_timer tick_;
  asio::steady_timer accept_pause_{*ioc_};  // after a failed accept (Accept)
  asio::signal_set signals_;
  std::chrono::steady_clock::duration period_{};
  std::chrono::steady_clock::time_point credit_at_{}, armed_at_{};  // of send_credit_; of the armed tick
  double send_credit_ = kMaxCredit;
  bool armed_ = false;
  std::shared_ptr<std::atomic<bool>> sample_posted_ = std::make_shared<std::atomic<bool>>(false);
  std::vector<std::shared_ptr<WsConnection>> sessions_;
  // Every WebSocket, page and Foxglove, by age: what --max-websockets bounds.
  struct WebSocket {
    std::weak_ptr<WsConnection> connection;
    asio::ip::address address;
  };
  std::vector<WebSocket> websockets_;
  // An event counted, its stderr line (with the count so far) at most once a second.
  struct CountedLine {
    std::uint64_t count = 0;
    std::chrono::steady_clock::time_point next{};
    bool Count() {  // true: write its line now
      ++count;
      const auto now = std::chrono::steady_clock::now();
      if (now < next) return false;
      next = now + std::chrono::seconds(1);
      return true;
    }
  };
  CountedLine refused_websockets_;  // past --max-websockets
  CountedLine closed_websockets_;   // by CloseWebSocketFor
  // Connections waiting for a request (ReadRequest) or for their answer to be
  // read (Respond), by age (Hold): what --max-http-waiting bounds.
  struct Waiting {
    std::weak_ptr<beast::tcp_stream> stream;
    asio::ip::address address;
  };
  std::map<std::uint64_t, Waiting> waiting_;
  std::uint64_t next_waiting_ = 0;
  CountedLine closed_waiting_;  // by CloseWaiting
  Message robots_;
  std::map<std::string, std::pair<std::uint64_t, Message>> models_;
  std::map<std::string, MeshCatalog> meshes_;  // by robot, resolved once at start
  std::unique_ptr<FoxgloveEndpoint> foxglove_;
};

WebServer::WebServer(const WebOptions& options, RobotTracker& tracker)
    : impl_(std::make_unique<Impl>(options, tracker)) {}
WebServer::~WebServer() = default;
int WebServer::port() const { return impl_->port(); }
const std::map<std::string, MeshCatalog>& WebServer::meshes() const { return impl_->meshes(); }
void WebServer::Run() { impl_->Run(); }
void WebServer::Stop() { impl_->Stop(); }

}  // namespace robotalk::web
