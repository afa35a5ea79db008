#include "foxglove_endpoint.h"

#include "foxglove_messages.h"
#include "json_text.h"
#include "ws_connection.h"

#include <boost/asio.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>

#include <algorithm>
#include <chrono>
#include <cstring>
#include <deque>
#include <map>
#include <set>
#include <vector>

namespace robotalk::web {
namespace {

namespace asio = boost::asio;
namespace beast = boost::beast;
namespace http = beast::http;
using tcp = asio::ip::tcp;
using nlohmann::json;
namespace fg = foxglove;

// Binary opcodes of foxglove.websocket.v1 (little-endian integers).
constexpr std::uint8_t kMessageData = 0x01;  // server: sub id u32, time u64, payload
constexpr std::uint8_t kServiceCallResponse =
    0x03;  // server: service u32, call u32, enc len u32, enc, payload
constexpr std::uint8_t kServiceCallRequest = 0x02;  // client: the same layout as the response
constexpr std::uint32_t kPanicServiceId = 1;
// State messages queued per client beyond which new ones are dropped (5
// channels per robot per tick: a few ticks of a few robots).
constexpr std::size_t kMaxQueuedStates = 64;
// Scene texts kept per robot, one per Host clients named (a client may send
// any Host header: the cache is bounded, a scene is rebuilt when it must be).
constexpr std::size_t kMaxCachedScenes = 8;
// Client messages are small JSON ops and service calls.
constexpr std::size_t kMaxClientMessage = 64 * 1024;

void PutLe(std::string& out, std::uint64_t v, int bytes) {
  for (int i = 0; i < bytes; ++i) out.push_back(static_cast<char>((v >> (8 * i)) & 0xff));
}
std::uint64_t GetLe(std::string_view in, std::size_t at, int bytes) {
  std::uint64_t v = 0;
  for (int i = 0; i < bytes; ++i) v |= std::uint64_t{static_cast<std::uint8_t>(in[at + i])} << (8 * i);
  return v;
}

json Status(int level, const std::string& message) {
  return {{"op", "status"}, {"level", level}, {"message", message}};
}

const json& PanicRequestSchema() {
  static const json s = {{"type", "object"},
                         {"properties", {{"robot", {{"type", "string"}}}}},
                         {"required", json::array({"robot"})}};
  return s;
}
const json& PanicResponseSchema() {
  static const json s = {{"type", "object"},
                         {"properties", {{"ok", {{"type", "boolean"}}}, {"message", {{"type", "string"}}}}}};
  return s;
}

// One Foxglove client: its connection and its subscriptions.
struct Session {
  std::shared_ptr<WsConnection> connection;
  std::string url_base;  // "http://" + the Host the client connected to: where meshes are served
  std::map<std::uint32_t, std::uint32_t> subscriptions;            // client's id -> channel id
  std::map<std::uint32_t, std::uint32_t> subscription_of_channel;  // the reverse

  void SendText(const std::string& text) const {
    connection->Send(std::make_shared<const std::string>(text), false, false);
  }
  void SendBinary(std::string bytes, bool droppable) const {
    connection->Send(std::make_shared<const std::string>(std::move(bytes)), true, droppable);
  }
};

struct RobotChannels {
  std::uint32_t first_id = 0;  // channel of kRobotTopics[i] is first_id + i
  std::uint64_t generation = 0;
  std::unique_ptr<fg::RobotMessages> messages;
  std::map<std::string, std::string> scenes;  // the SceneUpdate as JSON text, by url_base (mesh URLs)
  std::int64_t scene_time_ns = 0;
};

}  // namespace

class FoxgloveEndpoint::Impl {
 public:
  Impl(std::shared_ptr<asio::io_context> ioc, PanicHandler panic, std::map<std::string, MeshCatalog> geometry)
      : ioc_(std::move(ioc)), panic_(std::move(panic)), geometry_(std::move(geometry)) {}

  std::shared_ptr<WsConnection> Accept(tcp::socket socket, http::request<http::string_body> req) {
    auto connection = std::make_shared<WsConnection>(
        std::move(socket), kMaxClientMessage, kMaxQueuedStates,
        [this](const std::shared_ptr<WsConnection>& c, const std::string& data, bool text) {
          for (const auto& s : sessions_) {
            if (s->connection != c) continue;
            if (text)
              OnText(s, data);
            else
              OnBinary(s, data);
            return;
          }
        });
    const auto host = req.find(http::field::host);
    const std::string url_base = host == req.end()
                                     ? std::string()
                                     : "http://" + std::string(host->value().data(), host->value().size());
    sessions_.push_back(std::make_shared<Session>(Session{connection, url_base, {}, {}}));
    std::vector<WsConnection::Message> greeting;
    for (std::string& g : Greeting()) greeting.push_back(std::make_shared<const std::string>(std::move(g)));
    connection->Start(std::move(req), std::move(greeting), kSubprotocol);
    return connection;
  }

  void Update(const TrackerFrame& frame) {
    std::erase_if(sessions_, [](const std::shared_ptr<Session>& s) {
      return !s->connection->open() && s->connection.use_count() == 1;  // no operation pending on it
    });
    for (const TrackerFrame::Model& m : frame.models) {
      if (!m.model) continue;
      auto [it, added] = robots_.try_emplace(m.robot);
      RobotChannels& r = it->second;
      if (!added && r.generation == m.generation) continue;
      if (added) {
        r.first_id = next_channel_id_;
        next_channel_id_ += static_cast<std::uint32_t>(fg::kRobotTopics.size());
      }
      r.generation = m.generation;
      const auto urdf = geometry_.find(m.robot);
      r.messages = std::make_unique<fg::RobotMessages>(
          m.model, urdf == geometry_.end() ? std::nullopt : std::optional<MeshCatalog>(urdf->second));
      r.scene_time_ns = std::chrono::duration_cast<std::chrono::nanoseconds>(
                            std::chrono::system_clock::now().time_since_epoch())
                            .count();
      r.scenes.clear();
      if (added) {
        const std::string advertise = JsonText(Advertise({m.robot}));
        for (auto& s : sessions_) s->SendText(advertise);
      }
      for (auto& s : sessions_) SendScene(*s, r);
    }
    Forget(frame);
    for (const json& pose : frame.poses) {
      const auto it = robots_.find(pose.value("robot", ""));
      if (it == robots_.end() || it->second.generation != pose.value("generation", std::uint64_t{0}))
        continue;
      const RobotChannels& r = it->second;
      fg::RobotMessages::State st;
      try {
        st = r.messages->FromPose(pose);
      } catch (const std::exception&) {
        continue;  // a sample of another model: the tracker reports it on the robot's card
      }
      const std::pair<fg::Topic, const json*> out[] = {{fg::Topic::kTransforms, &st.transforms},
                                                       {fg::Topic::kJointStates, &st.joint_states},
                                                       {fg::Topic::kBasePose, &st.base_pose},
                                                       {fg::Topic::kStatus, &st.status}};
      for (const auto& [topic, msg] : out) {
        const std::uint32_t channel = r.first_id + static_cast<std::uint32_t>(topic);
        std::string text;  // written once, only when someone subscribed
        for (auto& s : sessions_) {
          const auto sub = s->subscription_of_channel.find(channel);
          if (sub == s->subscription_of_channel.end()) continue;
          if (text.empty()) text = JsonText(*msg);
          s->SendBinary(MessageData(sub->second, st.time_ns, text), true);
        }
      }
    }
  }

  std::size_t connections() const {
    return static_cast<std::size_t>(std::count_if(sessions_.begin(), sessions_.end(),
                                                  [](const auto& s) { return s->connection->live(); }));
  }

 private:
  static std::string MessageData(std::uint32_t subscription, std::int64_t time_ns,
                                 const std::string& payload) {
    std::string b;
    b.reserve(13 + payload.size());
    b.push_back(static_cast<char>(kMessageData));
    PutLe(b, subscription, 4);
    PutLe(b, static_cast<std::uint64_t>(std::max<std::int64_t>(0, time_ns)), 8);
    b += payload;
    return b;
  }

  // A robot the tracker no longer has (forgotten: silent long enough, or its
  // place taken by a new name) is unadvertised, its subscriptions dropped and
  // its messages freed: the robots kept follow the tracker's bounded table
  // (before: every name ever modelled, a stream of made-up robots grew it).
  void Forget(const TrackerFrame& frame) {
    const std::set<std::string> modelled = ModelledRobots(frame);
    json gone = json::array();
    for (auto it = robots_.begin(); it != robots_.end();) {
      if (modelled.count(it->first)) {
        ++it;
        continue;
      }
      for (std::size_t i = 0; i < fg::kRobotTopics.size(); ++i) {
        const std::uint32_t channel = it->second.first_id + static_cast<std::uint32_t>(i);
        gone.push_back(channel);
        for (auto& s : sessions_) {
          const auto sub = s->subscription_of_channel.find(channel);
          if (sub == s->subscription_of_channel.end()) continue;
          s->subscriptions.erase(sub->second);
          s->subscription_of_channel.erase(sub);
        }
      }
      it = robots_.erase(it);
    }
    if (gone.empty()) return;
    const std::string unadvertise = JsonText(json{{"op", "unadvertise"}, {"channelIds", gone}});
    for (auto& s : sessions_) s->SendText(unadvertise);
  }

  // Written once per model and mesh URL base, sent to each subscriber once.
  static void SendScene(Session& s, RobotChannels& r) {
    const auto sub =
        s.subscription_of_channel.find(r.first_id + static_cast<std::uint32_t>(fg::Topic::kScene));
    if (sub == s.subscription_of_channel.end()) return;
    if (r.scenes.size() >= kMaxCachedScenes && !r.scenes.count(s.url_base)) r.scenes.clear();
    auto [scene, added] = r.scenes.try_emplace(s.url_base);
    if (added) scene->second = JsonText(r.messages->Scene(r.scene_time_ns, {.url_base = s.url_base}));
    s.SendBinary(MessageData(sub->second, r.scene_time_ns, scene->second), false);
  }

  json Advertise(const std::vector<std::string>& robots) const {
    json channels = json::array();
    for (const std::string& robot : robots) {
      const RobotChannels& r = robots_.at(robot);
      for (std::size_t i = 0; i < fg::kRobotTopics.size(); ++i) {
        const fg::SchemaInfo& schema = fg::SchemaOf(fg::kRobotTopics[i]);
        channels.push_back({{"id", r.first_id + i},
                            {"topic", fg::TopicName(robot, fg::kRobotTopics[i])},
                            {"encoding", "json"},
                            {"schemaName", schema.name},
                            {"schema", schema.schema},
                            {"schemaEncoding", "jsonschema"}});
      }
    }
    return {{"op", "advertise"}, {"channels", channels}};
  }

  std::vector<std::string> Greeting() const {
    json capabilities = json::array();
    if (panic_) capabilities.push_back("services");
    json info = {{"op", "serverInfo"},
                 {"name", std::string("robotalk-web ") + ROBOTALK_WEB_VERSION},
                 {"capabilities", capabilities},
                 {"metadata", {{"robots", std::to_string(robots_.size())}}},
                 {"sessionId", session_id_}};
    if (panic_) info["supportedEncodings"] = json::array({"json"});
    std::vector<std::string> g{JsonText(info)};
    std::vector<std::string> names;
    for (const auto& [name, r] : robots_) names.push_back(name);
    g.push_back(JsonText(Advertise(names)));  // at least one advertise, as the protocol asks
    if (panic_) {
      const json service = {{"id", kPanicServiceId},
                            {"name", "/robotalk/panic"},
                            {"type", "robotalk.Panic"},
                            {"request",
                             {{"encoding", "json"},
                              {"schemaName", "robotalk.Panic_Request"},
                              {"schemaEncoding", "jsonschema"},
                              {"schema", PanicRequestSchema().dump()}}},
                            {"response",
                             {{"encoding", "json"},
                              {"schemaName", "robotalk.Panic_Response"},
                              {"schemaEncoding", "jsonschema"},
                              {"schema", PanicResponseSchema().dump()}}}};
      g.push_back(JsonText(json{{"op", "advertiseServices"}, {"services", json::array({service})}}));
    }
    return g;
  }

  void OnText(const std::shared_ptr<Session>& s, const std::string& text) {
    const json msg = json::parse(text, nullptr, false);
    const std::string op =
        msg.is_object() && msg.contains("op") && msg["op"].is_string() ? msg["op"].get<std::string>() : "";
    if (op == "subscribe" && msg.contains("subscriptions") && msg["subscriptions"].is_array()) {
      for (const json& sub : msg["subscriptions"]) Subscribe(s, sub);
    } else if (op == "unsubscribe" && msg.contains("subscriptionIds") && msg["subscriptionIds"].is_array()) {
      for (const json& id : msg["subscriptionIds"]) {
        if (!id.is_number_unsigned()) continue;
        const auto it = s->subscriptions.find(id.get<std::uint32_t>());
        if (it == s->subscriptions.end()) continue;
        s->subscription_of_channel.erase(it->second);
        s->subscriptions.erase(it);
      }
    } else {
      s->SendText(JsonText(
          Status(2, op.empty() ? "robotalk-web: not a foxglove.websocket.v1 JSON op: " + text.substr(0, 80)
                               : "robotalk-web: op '" + op + "' is not supported (subscribe, unsubscribe" +
                                     (panic_ ? ", service calls)" : ")"))));
    }
  }

  void Subscribe(const std::shared_ptr<Session>& s, const json& sub) {
    if (!sub.is_object() || !sub.contains("id") || !sub["id"].is_number_unsigned() ||
        !sub.contains("channelId") || !sub["channelId"].is_number_unsigned()) {
      s->SendText(JsonText(Status(
          2, "robotalk-web: subscribe: a subscription needs unsigned 'id' and 'channelId': " + sub.dump())));
      return;
    }
    const auto id = sub["id"].get<std::uint32_t>();
    const auto channel = sub["channelId"].get<std::uint32_t>();
    RobotChannels* robot = nullptr;
    for (auto& [name, r] : robots_)
      if (channel >= r.first_id && channel < r.first_id + fg::kRobotTopics.size()) robot = &r;
    if (!robot) {
      s->SendText(JsonText(Status(2, "robotalk-web: subscribe: no channel " + std::to_string(channel))));
      return;
    }
    if (s->subscriptions.count(id) || s->subscription_of_channel.count(channel)) {
      s->SendText(JsonText(Status(2, "robotalk-web: subscribe: subscription " + std::to_string(id) +
                                         " or channel " + std::to_string(channel) + " already subscribed")));
      return;
    }
    s->subscriptions[id] = channel;
    s->subscription_of_channel[channel] = id;
    if (channel == robot->first_id + static_cast<std::uint32_t>(fg::Topic::kScene)) SendScene(*s, *robot);
  }

  void OnBinary(const std::shared_ptr<Session>& s, const std::string& b) {
    if (b.empty() || static_cast<std::uint8_t>(b[0]) != kServiceCallRequest || b.size() < 13) {
      s->SendText(JsonText(
          Status(2, "robotalk-web: binary message is not a service call request (opcode 0x02, 13+ bytes)")));
      return;
    }
    const auto service = static_cast<std::uint32_t>(GetLe(b, 1, 4));
    const auto call = static_cast<std::uint32_t>(GetLe(b, 5, 4));
    const auto enc_len = GetLe(b, 9, 4);
    auto failure = [&](const std::string& why) {
      s->SendText(JsonText(
          json{{"op", "serviceCallFailure"}, {"serviceId", service}, {"callId", call}, {"message", why}}));
    };
    if (!panic_ || service != kPanicServiceId)
      return failure(
          "robotalk-web: no service " + std::to_string(service) +
          (panic_ ? "" : " (this bridge offers PANIC only when it was given a key: ROBOTALK_KEY)"));
    if (13 + enc_len > b.size())
      return failure("robotalk-web: service call: encoding length past the message");
    const std::string encoding = b.substr(13, enc_len);
    if (encoding != "json")
      return failure("robotalk-web: service call: encoding '" + encoding + "', expected json");
    const json req = json::parse(b.substr(13 + enc_len), nullptr, false);
    if (!req.is_object() || !req.contains("robot") || !req["robot"].is_string())
      return failure("robotalk-web: /robotalk/panic: the request must be {\"robot\": NAME}");
    const std::string robot = req["robot"].get<std::string>();
    std::weak_ptr<WsConnection> weak = s->connection;
    panic_(robot, [ioc = ioc_, weak, service, call, robot](const std::string& error) {
      asio::post(*ioc, [weak, service, call, robot, error] {
        auto connection = weak.lock();
        if (!connection) return;
        Session session{connection, {}, {}, {}};
        if (!error.empty()) {
          session.SendText(JsonText(json{{"op", "serviceCallFailure"},
                                         {"serviceId", service},
                                         {"callId", call},
                                         {"message", "PANIC " + robot + ": " + error}}));
          return;
        }
        std::string r;
        r.push_back(static_cast<char>(kServiceCallResponse));
        PutLe(r, service, 4);
        PutLe(r, call, 4);
        PutLe(r, 4, 4);
        r += "json";
        r += JsonText(json{{"ok", true}, {"message", "robot '" + robot + "' is in panic"}});
        session.SendBinary(std::move(r), false);
      });
    });
  }

  std::shared_ptr<asio::io_context> ioc_;
  PanicHandler panic_;
  const std::map<std::string, MeshCatalog> geometry_;
  std::vector<std::shared_ptr<Session>> sessions_;
  std::map<std::string, RobotChannels> robots_;
  std::uint32_t next_channel_id_ = 1;
  const std::string session_id_ = std::to_string(std::chrono::duration_cast<std::chrono::milliseconds>(
                                                     std::chrono::system_clock::now().time_since_epoch())
                                                     .count());
};

FoxgloveEndpoint::FoxgloveEndpoint(std::shared_ptr<asio::io_context> ioc, PanicHandler panic,
                                   std::map<std::string, MeshCatalog> geometry)
    : impl_(std::make_unique<Impl>(std::move(ioc), std::move(panic), std::move(geometry))) {}
FoxgloveEndpoint::~FoxgloveEndpoint() = default;

bool FoxgloveEndpoint::Offered(const http::request<http::string_body>& request) {
  const auto it = request.find(http::field::sec_websocket_protocol);
  if (it == request.end()) return false;
  const std::string_view offered(it->value().data(), it->value().size());
  std::size_t start = 0;
  while (start <= offered.size()) {  // a comma-separated list
    std::size_t end = offered.find(',', start);
    if (end == std::string_view::npos) end = offered.size();
    std::string_view token = offered.substr(start, end - start);
    while (!token.empty() && token.front() == ' ') token.remove_prefix(1);
    while (!token.empty() && token.back() == ' ') token.remove_suffix(1);
    if (token == kSubprotocol) return true;
    start = end + 1;
  }
  return false;
}

std::shared_ptr<WsConnection> FoxgloveEndpoint::Accept(tcp::socket socket,
                                                       http::request<http::string_body> request) {
  return impl_->Accept(std::move(socket), std::move(request));
}
void FoxgloveEndpoint::Update(const TrackerFrame& frame) { impl_->Update(frame); }
std::size_t FoxgloveEndpoint::connections() const { return impl_->connections(); }

}  // namespace robotalk::web
