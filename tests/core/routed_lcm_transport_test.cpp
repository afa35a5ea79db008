// RoutedLcmTransport over real UDP multicast. Runs only inside a private
// network namespace (tests/core/CMakeLists.txt starts it through
// scripts/netns_run.sh), where every port is ours.
#include "robotalk/routed_lcm_transport.h"

#include "robotalk/channels.h"
#include "robotalk/error.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <poll.h>

#include <chrono>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace robotalk {
namespace {

using ::testing::ElementsAre;
using ::testing::UnorderedElementsAre;
using Bytes = std::vector<std::uint8_t>;

constexpr int kPort = 7667;
const std::string kUrl = "udpm://239.255.76.67:7667?ttl=0";
constexpr Duration kWait = std::chrono::milliseconds(200);  // an upper bound only

// UDP ports bound in this namespace (/proc/net/udp, local_address column).
std::set<int> BoundUdpPorts() {
  std::ifstream in("/proc/net/udp");
  std::string line;
  std::getline(in, line);  // header
  std::set<int> ports;
  while (std::getline(in, line)) {
    std::istringstream fields(line);
    std::string slot, local;
    fields >> slot >> local;
    const auto colon = local.find(':');
    if (colon != std::string::npos) ports.insert(std::stoi(local.substr(colon + 1), nullptr, 16));
  }
  return ports;
}

// Every lane of kUrl heard by a plain LcmTransport subscribed to ".*": which
// lane carried which channel.
class LaneSpy {
 public:
  LaneSpy() {
    for (int lane = 0; lane < kLaneCount; ++lane) {
      lanes_.push_back(std::make_unique<LcmTransport>(LcmTransportOptions{.url = LaneUrl(kUrl, lane)}));
      subs_.push_back(
          lanes_.back()->Subscribe(".*", [this, lane](const std::string& ch, std::span<const std::uint8_t>) {
            if (ch != "LCM_SELF_TEST") heard_.emplace_back(lane, ch);
          }));
    }
  }
  // Dispatches every lane until `n` messages were heard (bounded), then what
  // else is waiting.
  std::vector<std::pair<int, std::string>> HeardAfter(std::size_t n) {
    for (int round = 0; round < 20 && heard_.size() < n; ++round) {
      for (auto& lane : lanes_) lane->HandleFor(kWait / kLaneCount);
    }
    for (auto& lane : lanes_) lane->HandleFor(std::chrono::milliseconds(1));
    return heard_;
  }

 private:
  std::vector<std::unique_ptr<LcmTransport>> lanes_;
  std::vector<std::unique_ptr<Subscription>> subs_;
  std::vector<std::pair<int, std::string>> heard_;
};

int HandleUpTo(Transport& t, int n) {
  int total = 0;
  for (int i = 0; i < 20 && total < n; ++i) total += t.HandleFor(kWait);
  return total;
}

TEST(RoutedLcmTransport, PublishesEachChannelOnItsLaneOnly) {
  LaneSpy spy;
  RoutedLcmTransport server(kUrl);
  server.Publish(ReplyChannel("pioneer", 5), Bytes{1});
  server.Publish(ReplyChannel("pioneer", 6), Bytes{2});
  server.Publish(HelloAnswerChannel("pioneer", 5), Bytes{3});
  server.Publish(RequestChannel("pioneer"), Bytes{4});
  server.Publish(StateChannel("pioneer"), Bytes{5});
  server.Publish(kAnnounceChannel, Bytes{6});
  EXPECT_THAT(spy.HeardAfter(6),
              UnorderedElementsAre(std::pair(ReplyLaneOf(5), ReplyChannel("pioneer", 5)),
                                   std::pair(ReplyLaneOf(6), ReplyChannel("pioneer", 6)),
                                   std::pair(ReplyLaneOf(5), HelloAnswerChannel("pioneer", 5)),
                                   std::pair(kRequestLane, RequestChannel("pioneer")),
                                   std::pair(kMainLane, StateChannel("pioneer")),
                                   std::pair(kMainLane, std::string(kAnnounceChannel))));
}

TEST(RoutedLcmTransport, AClientDoesNotReceiveAnotherClientsReplies) {
  RoutedLcmTransport server(kUrl);
  RoutedLcmTransport client5(kUrl);
  std::vector<std::string> got;
  // A regex over every client's replies: only the lane it is placed on is heard.
  auto sub =
      client5.Subscribe(ReplyChannel("pioneer", 5),
                        [&](const std::string& ch, std::span<const std::uint8_t>) { got.push_back(ch); });
  auto wide = client5.Subscribe(
      "ROBOTALK/pioneer/REPLY/.*",
      [&](const std::string& ch, std::span<const std::uint8_t>) { got.push_back("wide " + ch); });
  server.Publish(ReplyChannel("pioneer", 6), Bytes{1});
  server.Publish(ReplyChannel("pioneer", 5), Bytes{2});
  EXPECT_EQ(HandleUpTo(client5, 1), 1);
  client5.HandleFor(std::chrono::milliseconds(20));  // anything wrongly delivered would show now
  EXPECT_THAT(got, ElementsAre(ReplyChannel("pioneer", 5)));
  EXPECT_TRUE(client5.Receives(ReplyLaneOf(5)));
  EXPECT_TRUE(client5.Receives(kMainLane));  // the wide regex went there
  EXPECT_FALSE(client5.Receives(ReplyLaneOf(6)));
}

TEST(RoutedLcmTransport, OpensNoReceiveSocketOnALaneItOnlyPublishesOn) {
  RoutedLcmTransport client(kUrl);
  auto sub =
      client.Subscribe(ReplyChannel("pioneer", 9), [](const std::string&, std::span<const std::uint8_t>) {});
  client.Publish(RequestChannel("pioneer"), Bytes{1});
  const std::set<int> ports = BoundUdpPorts();
  EXPECT_TRUE(ports.count(kPort + ReplyLaneOf(9))) << "the reply lane listens";
  EXPECT_FALSE(ports.count(kPort + kRequestLane)) << "the request lane is publish-only";
  EXPECT_FALSE(ports.count(kPort)) << "nothing subscribed on the main lane";
  EXPECT_FALSE(client.Receives(kRequestLane));
}

TEST(RoutedLcmTransport, CarriesARequestToTheServerAndTheReplyBack) {
  RoutedLcmTransport server(kUrl);
  RoutedLcmTransport client(kUrl);
  std::vector<std::string> server_got, client_got;
  auto requests =
      server.Subscribe(kAnyRequestChannelRegex, [&](const std::string& ch, std::span<const std::uint8_t> b) {
        server_got.push_back(ch);
        server.Publish(ReplyChannel("arm", b[0]), Bytes{b[0]});
      });
  auto replies = client.Subscribe(
      ReplyChannel("arm", 3),
      [&](const std::string& ch, std::span<const std::uint8_t>) { client_got.push_back(ch); });
  client.Publish(RequestChannel("arm"), Bytes{3});
  EXPECT_EQ(HandleUpTo(server, 1), 1);
  pollfd pfd{client.fileno(), POLLIN, 0};
  EXPECT_EQ(::poll(&pfd, 1, 1000), 1) << "fileno() polls readable while a reply waits";
  EXPECT_EQ(client.HandleFor(Duration(0)), 1);
  EXPECT_THAT(server_got, ElementsAre(RequestChannel("arm")));
  EXPECT_THAT(client_got, ElementsAre(ReplyChannel("arm", 3)));
}

TEST(RoutedLcmTransport, AnAllLanesTransportHearsEveryLane) {
  RoutedLcmTransport recorder(kUrl, OpenLcmOptions{.all_lanes = true});
  RoutedLcmTransport server(kUrl);
  std::multiset<std::string> got;
  auto sub = recorder.Subscribe(".*", [&](const std::string& ch, std::span<const std::uint8_t>) {
    if (ch != "LCM_SELF_TEST") got.insert(ch);
  });
  for (int lane = 0; lane < kLaneCount; ++lane) EXPECT_TRUE(recorder.Receives(lane)) << lane;
  server.Publish(kAnnounceChannel, Bytes{1});
  server.Publish(RequestChannel("r"), Bytes{1});
  server.Publish(ReplyChannel("r", 63), Bytes{1});
  HandleUpTo(recorder, 3);
  recorder.HandleFor(std::chrono::milliseconds(20));
  EXPECT_THAT(
      got, UnorderedElementsAre(std::string(kAnnounceChannel), RequestChannel("r"), ReplyChannel("r", 63)));
}

TEST(RoutedLcmTransport, RethrowsAHandlersExceptionFromHandleFor) {
  RoutedLcmTransport t(kUrl);
  auto sub = t.Subscribe(RequestChannel("r"), [](const std::string&, std::span<const std::uint8_t>) {
    throw std::logic_error("handler failed");
  });
  t.Publish(RequestChannel("r"), Bytes{1});
  EXPECT_THROW(HandleUpTo(t, 1), std::logic_error);
}

TEST(OpenLcmTransport, RoutesUdpmAndKeepsSingleLayoutsOnOneLcm) {
  auto split = OpenLcmTransport(kUrl);
  EXPECT_NE(dynamic_cast<RoutedLcmTransport*>(split.get()), nullptr);
  EXPECT_EQ(split->url(), kUrl);
  auto single = OpenLcmTransport("udpm://239.255.76.67:7667?traffic=single&ttl=0");
  EXPECT_EQ(dynamic_cast<RoutedLcmTransport*>(single.get()), nullptr);
  // A URL a client can use as is: the layout stays in it.
  EXPECT_EQ(single->url(), "udpm://239.255.76.67:7667?ttl=0&recv_buf_size=2097152&traffic=single");
  EXPECT_NE(dynamic_cast<LcmTransport*>(OpenLcmTransport("memq://").get()), nullptr);
  EXPECT_THROW(OpenLcmTransport("udpm://239.255.76.67:7667?traffic=maybe"), TransportError);
}

TEST(OpenLcmTransport, ASingleLayoutUdpmTransportCarriesRepliesOnTheMainUrl) {
  auto single = OpenLcmTransport(kUrl + "&traffic=single");
  LaneSpy spy;
  single->Publish(ReplyChannel("pioneer", 5), Bytes{1});
  EXPECT_THAT(spy.HeardAfter(1), ElementsAre(std::pair(kMainLane, ReplyChannel("pioneer", 5))));
}

}  // namespace
}  // namespace robotalk
