#include "robotalk/traffic_layout.h"

#include "robotalk/channels.h"
#include "robotalk/error.h"
#include "robotalk/memory_transport.h"
#include "robotalk/routed_lcm_transport.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace robotalk {
namespace {

using ::testing::HasSubstr;

TEST(TrafficLayout, PutsAnnounceConfigStateAndForeignChannelsOnTheMainLane) {
  EXPECT_EQ(LaneOfChannel(kAnnounceChannel), kMainLane);
  EXPECT_EQ(LaneOfChannel(ConfigChannel("pioneer")), kMainLane);
  EXPECT_EQ(LaneOfChannel(StateChannel("pioneer")), kMainLane);
  EXPECT_EQ(LaneOfChannel("LCM_SELF_TEST"), kMainLane);
  EXPECT_EQ(LaneOfChannel("ROBOTALK/a/b/REQUEST"), kMainLane);  // not a RoboTalk channel
  EXPECT_EQ(LaneOfChannel("ROBOTALK/a/REPLY/2a"), kMainLane);
}

TEST(TrafficLayout, PutsRequestsAndHellosOnTheRequestLane) {
  EXPECT_EQ(LaneOfChannel(RequestChannel("pioneer")), kRequestLane);
  EXPECT_EQ(LaneOfChannel(HelloChannel("x.y-z")), kRequestLane);
}

TEST(TrafficLayout, PutsAClientsRepliesAndHelloAnswersOnItsReplyLane) {
  for (std::int64_t id : {std::int64_t{0}, std::int64_t{1}, std::int64_t{63}, std::int64_t{64},
                          std::int64_t{0x7fffffffffffffff}, std::int64_t{-1}}) {
    const int lane = 2 + static_cast<int>(static_cast<std::uint64_t>(id) % 64);
    EXPECT_EQ(ReplyLaneOf(id), lane) << id;
    EXPECT_EQ(LaneOfChannel(ReplyChannel("pioneer", id)), lane) << id;
    EXPECT_EQ(LaneOfChannel(HelloAnswerChannel("arm", id)), lane) << id;
  }
  EXPECT_EQ(ReplyLaneOf(-1), 2 + 63);  // 0xffff...ffff % 64
  EXPECT_NE(ReplyLaneOf(1), ReplyLaneOf(2));
  EXPECT_EQ(ReplyLaneOf(1), ReplyLaneOf(65));
}

TEST(TrafficLayout, PlacesTheSubscriptionsServersAndClientsMake) {
  EXPECT_EQ(LaneOfSubscription(kAnyRequestChannelRegex), kRequestLane);
  EXPECT_EQ(LaneOfSubscription(kAnyHelloChannelRegex), kRequestLane);
  EXPECT_EQ(LaneOfSubscription(ReplyChannel("pioneer", 0x42)), ReplyLaneOf(0x42));
  EXPECT_EQ(LaneOfSubscription(ReplyChannel("x.y-z", 0x42)), ReplyLaneOf(0x42));  // '.' is a pattern
  EXPECT_EQ(LaneOfSubscription(HelloAnswerChannel("pioneer", 7)), ReplyLaneOf(7));
  EXPECT_EQ(LaneOfSubscription("ROBOTALK/.*/REPLY/0000000000000007"), ReplyLaneOf(7));
  EXPECT_EQ(LaneOfSubscription(kAnnounceChannel), kMainLane);
  EXPECT_EQ(LaneOfSubscription(ConfigChannel("pioneer")), kMainLane);
  EXPECT_EQ(LaneOfSubscription(StateChannel("pioneer")), kMainLane);
}

TEST(TrafficLayout, CannotPlaceARegexThatMayMatchSeveralLanes) {
  EXPECT_FALSE(LaneOfSubscription(".*"));
  EXPECT_FALSE(LaneOfSubscription("ROBOTALK/.*"));
  EXPECT_FALSE(LaneOfSubscription("ROBOTALK/pioneer/REPLY/.*"));
  EXPECT_FALSE(LaneOfSubscription(StateChannel("x.y-z")));   // the '.' could match '/'
  EXPECT_FALSE(LaneOfSubscription("ROBOTALK/a|b/REQUEST"));  // "ROBOTALK/a" or "b/REQUEST"
  EXPECT_FALSE(LaneOfSubscription("ROBOTALK/a/REQUEST|FOO"));
}

TEST(TrafficLayout, SplitsUdpmByDefaultAndStripsTheTrafficOption) {
  EXPECT_EQ(ParseTrafficUrl("udpm://239.255.76.67:7667?ttl=0"),
            (TrafficUrl{"udpm://239.255.76.67:7667?ttl=0", TrafficLayout::kSplit}));
  EXPECT_EQ(ParseTrafficUrl("udpm://239.255.76.67:7667?ttl=0&traffic=split"),
            (TrafficUrl{"udpm://239.255.76.67:7667?ttl=0", TrafficLayout::kSplit}));
  EXPECT_EQ(ParseTrafficUrl("udpm://239.255.76.67:7667?traffic=single&ttl=0&recv_buf_size=4096"),
            (TrafficUrl{"udpm://239.255.76.67:7667?ttl=0&recv_buf_size=4096", TrafficLayout::kSingle}));
  EXPECT_EQ(ParseTrafficUrl("udpm://239.255.76.67:7667?traffic=single"),
            (TrafficUrl{"udpm://239.255.76.67:7667", TrafficLayout::kSingle}));
  EXPECT_EQ(ParseTrafficUrl("udpm://239.255.76.67:7667"),
            (TrafficUrl{"udpm://239.255.76.67:7667", TrafficLayout::kSplit}));
}

TEST(TrafficLayout, KeepsMemqAndFileOnOneUrl) {
  EXPECT_EQ(ParseTrafficUrl("memq://"), (TrafficUrl{"memq://", TrafficLayout::kSingle}));
  EXPECT_EQ(ParseTrafficUrl("memq://?traffic=single"), (TrafficUrl{"memq://", TrafficLayout::kSingle}));
  EXPECT_EQ(ParseTrafficUrl("file:///tmp/x.lcmlog?speed=0"),
            (TrafficUrl{"file:///tmp/x.lcmlog?speed=0", TrafficLayout::kSingle}));
}

TEST(TrafficLayout, RefusesBadTrafficOptionsNamingTheUrl) {
  EXPECT_THAT([] { ParseTrafficUrl("udpm://239.255.76.67:7667?traffic=both"); },
              ::testing::ThrowsMessage<TransportError>(HasSubstr("traffic=both")));
  EXPECT_THAT([] { ParseTrafficUrl("memq://?traffic=split"); },
              ::testing::ThrowsMessage<TransportError>(HasSubstr("needs a udpm:// URL")));
  EXPECT_THAT([] { ParseTrafficUrl("udpm://239.255.76.67:65500"); },
              ::testing::ThrowsMessage<TransportError>(HasSubstr("65500..65565")));
  EXPECT_THAT([] { ParseTrafficUrl("udpm://239.255.76.67:port"); },
              ::testing::ThrowsMessage<TransportError>(HasSubstr("udpm://GROUP:PORT")));
  EXPECT_THAT([] { ParseTrafficUrl(""); }, ::testing::ThrowsMessage<TransportError>(HasSubstr("empty URL")));
  // traffic=single needs no port: LCM decides what it accepts.
  EXPECT_EQ(ParseTrafficUrl("udpm://239.255.76.67?traffic=single").layout, TrafficLayout::kSingle);
}

TEST(TrafficLayout, DerivesEachLaneUrlFromTheMainUrlByPort) {
  const std::string main = "udpm://239.255.76.67:7667?ttl=0&recv_buf_size=4096";
  EXPECT_EQ(LaneUrl(main, kMainLane), main);
  EXPECT_EQ(LaneUrl(main, kRequestLane), "udpm://239.255.76.67:7668?ttl=0&recv_buf_size=4096");
  EXPECT_EQ(LaneUrl(main, ReplyLaneOf(0)), "udpm://239.255.76.67:7669?ttl=0&recv_buf_size=4096");
  EXPECT_EQ(LaneUrl(main, kLaneCount - 1), "udpm://239.255.76.67:7732?ttl=0&recv_buf_size=4096");
  EXPECT_EQ(LaneUrl("udpm://239.255.76.67:7667", 1), "udpm://239.255.76.67:7668");
  EXPECT_EQ(LaneUrl("udpm://239.255.76.67?ttl=0", 1), "udpm://239.255.76.67:7668?ttl=0");  // LCM's port
  EXPECT_THROW(LaneUrl(main, kLaneCount), TransportError);
  EXPECT_THROW(LaneUrl(main, -1), TransportError);
  EXPECT_THROW(LaneUrl("memq://", 1), TransportError);
  EXPECT_THROW(LaneUrl("udpm://239.255.76.67:x?ttl=0", 1), TransportError);
}

// A server announces the layout its transport reports (no cast to the class).
TEST(TrafficLayout, EachTransportReportsTheLayoutItsTrafficTravelsIn) {
  // A RoutedLcmTransport opens no socket before its first Publish/Subscribe.
  EXPECT_EQ(OpenLcmTransport("udpm://239.255.76.67:7667?ttl=0")->traffic_layout(), TrafficLayout::kSplit);
  EXPECT_EQ(OpenLcmTransport("memq://")->traffic_layout(), TrafficLayout::kSingle);
  MemoryTransport memory(std::make_shared<MemoryBus>());
  EXPECT_EQ(memory.traffic_layout(), TrafficLayout::kSingle);
}

}  // namespace
}  // namespace robotalk
