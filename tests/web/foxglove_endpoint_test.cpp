// FoxgloveEndpoint (robotalk-web's Foxglove WebSocket side) against a real
// WebSocket client on the loopback: what the robots the bridge has heard
// make it keep and advertise.
#include "foxglove_endpoint.h"
#include "foxglove_messages.h"
#include "robotalk/urdf_import.h"
#include "test_paths.h"

#include <gtest/gtest.h>

#include <boost/asio.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>
#include <nlohmann/json.hpp>

#include <atomic>
#include <chrono>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include <sys/socket.h>

namespace robotalk::web {
namespace {

namespace asio = boost::asio;
namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
using tcp = asio::ip::tcp;
using nlohmann::json;

// A frame naming these robots, each with the same model.
TrackerFrame Modelled(const std::vector<std::string>& robots,
                      const std::shared_ptr<const RobotModel>& model) {
  TrackerFrame f;
  for (const std::string& r : robots)
    f.models.push_back({r, 1, std::make_shared<const std::string>("{}"), model});
  return f;
}

// One Foxglove client of `endpoint`: it connects, then files every text
// message it reads.
struct Client {
  std::shared_ptr<asio::io_context> ioc;
  tcp::acceptor acceptor;
  std::mutex mu;
  std::vector<json> texts;  // GUARDED_BY(mu)
  std::atomic<int> fd{-1};
  std::thread thread;

  Client(std::shared_ptr<asio::io_context> io, FoxgloveEndpoint& endpoint)
      : ioc(std::move(io)), acceptor(*ioc, {asio::ip::make_address("127.0.0.1"), 0}) {
    const tcp::endpoint at = acceptor.local_endpoint();
    thread = std::thread([this, at] {
      asio::io_context cio;
      websocket::stream<tcp::socket> ws(cio);
      beast::error_code ec;
      ws.next_layer().connect(at, ec);
      if (ec) return;
      fd = ws.next_layer().native_handle();
      ws.set_option(websocket::stream_base::decorator([](websocket::request_type& req) {
        req.set(http::field::sec_websocket_protocol, FoxgloveEndpoint::kSubprotocol);
      }));
      ws.handshake("127.0.0.1", "/", ec);
      for (beast::flat_buffer in; !ec; in.consume(in.size())) {
        ws.read(in, ec);
        if (ec || !ws.got_text()) continue;
        std::lock_guard lock(mu);
        texts.push_back(json::parse(beast::buffers_to_string(in.data()), nullptr, false));
      }
    });
    tcp::socket socket = acceptor.accept();
    beast::flat_buffer buffer;
    http::request<http::string_body> req;
    http::read(socket, buffer, req);
    endpoint.Accept(std::move(socket), std::move(req));
  }
  ~Client() {
    if (fd >= 0) ::shutdown(fd, SHUT_RDWR);
    ioc->stop();
    if (thread.joinable()) thread.join();
  }
  // The first text message with this op, running the io_context up to 10 s.
  std::optional<json> Await(const std::string& op) {
    for (int i = 0; i < 1000; ++i) {
      ioc->restart();
      ioc->run_for(std::chrono::milliseconds(10));
      std::lock_guard lock(mu);
      for (const json& t : texts)
        if (t.is_object() && t.value("op", "") == op) return t;
    }
    return std::nullopt;
  }
};

std::vector<std::string> AdvertisedTopics(const json& advertise) {
  std::vector<std::string> topics;
  for (const json& c : advertise["channels"]) topics.push_back(c["topic"].get<std::string>());
  return topics;
}

// The tracker keeps a bounded table of the robots it heard (256 names; a
// silent one is forgotten, a new name takes a silent one's place), and
// anyone on the bus may announce names. The endpoint kept a robot's channels
// and messages for every name it ever had a model of, and advertised them all
// to each new client: a stream of made-up robots grew it without a bound.
// A robot the tracker no longer lists is now unadvertised and forgotten.
TEST(FoxgloveEndpointRobots, ARobotTheTrackerForgotIsUnadvertisedAndNoLongerKept) {
  const auto model = std::make_shared<const RobotModel>(
      LoadUrdfFile(testing::ProjectModel("pioneer2dx_pantilt.urdf")).model);
  auto ioc = std::make_shared<asio::io_context>();
  FoxgloveEndpoint endpoint(ioc, {});
  // 300 robots heard one after another, each forgotten when the next came.
  for (int i = 0; i < 300; ++i) endpoint.Update(Modelled({"made_up_" + std::to_string(i)}, model));
  endpoint.Update(Modelled({"pioneer"}, model));

  Client client(ioc, endpoint);
  const std::optional<json> info = client.Await("serverInfo");
  ASSERT_TRUE(info);
  EXPECT_EQ((*info)["metadata"]["robots"], "1") << info->dump();
  const std::optional<json> advertise = client.Await("advertise");
  ASSERT_TRUE(advertise);
  std::vector<std::string> expected;
  for (foxglove::Topic t : foxglove::kRobotTopics) expected.push_back(foxglove::TopicName("pioneer", t));
  EXPECT_EQ(AdvertisedTopics(*advertise), expected);

  // The robot forgotten while the client is connected: its channels unadvertised.
  endpoint.Update(Modelled({}, model));
  const std::optional<json> unadvertise = client.Await("unadvertise");
  ASSERT_TRUE(unadvertise);
  std::vector<std::uint32_t> advertised, gone;
  for (const json& c : (*advertise)["channels"]) advertised.push_back(c["id"].get<std::uint32_t>());
  for (const json& id : (*unadvertise)["channelIds"]) gone.push_back(id.get<std::uint32_t>());
  EXPECT_EQ(gone, advertised);
}

}  // namespace
}  // namespace robotalk::web
