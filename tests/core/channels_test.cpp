#include "robotalk/channels.h"

#include <gtest/gtest.h>

#include <limits>

#include <string>

namespace robotalk {
namespace {

TEST(Channels, BuildsTheDocumentedNames) {
  EXPECT_EQ(RequestChannel("pioneer"), "ROBOTALK/pioneer/REQUEST");
  EXPECT_EQ(ReplyChannel("pioneer", 0x2a), "ROBOTALK/pioneer/REPLY/000000000000002a");
  EXPECT_EQ(ReplyChannel("arm", -1), "ROBOTALK/arm/REPLY/ffffffffffffffff");
  EXPECT_EQ(ConfigChannel("pioneer"), "ROBOTALK/pioneer/CONFIG");
  EXPECT_EQ(StateChannel("pioneer"), "ROBOTALK/pioneer/STATE");
  EXPECT_STREQ(kAnnounceChannel, "ROBOTALK/ANNOUNCE");
}

TEST(Channels, ARobotNameIsLettersDigitsUnderscoreAndHyphen) {
  for (const char* good : {"pioneer", "a", "asimo_2", "arm-left", "_", "-", "ABC09"}) {
    EXPECT_TRUE(IsValidRobotName(good)) << good;
  }
  for (const char* bad : {"", "x.y", "a/b", "a b", "caf\xc3\xa9", "*", "a\n"}) {
    EXPECT_FALSE(IsValidRobotName(bad)) << bad;
  }
}

// LCM refuses a channel name over 63 characters (LCM_MAX_CHANNEL_NAME_LENGTH):
// a robot whose name made its reply channel longer was "served" and could
// never answer a hello (the client: "no answer to HELLO ... is a server
// offering it?"). Every channel of a valid name fits.
TEST(Channels, EveryChannelOfAValidRobotNameFitsLcmsChannelNameLimit) {
  const std::string longest(31, 'r');
  EXPECT_TRUE(IsValidRobotName(longest));
  EXPECT_FALSE(IsValidRobotName(longest + "r")) << "32 characters: its reply channel would be 64";
  EXPECT_FALSE(IsValidRobotName(std::string(1000, 'r')));
  constexpr std::int64_t kWidest = std::numeric_limits<std::int64_t>::min();
  for (const std::string& channel :
       {ReplyChannel(longest, kWidest), HelloAnswerChannel(longest, kWidest), HelloChannel(longest),
        RequestChannel(longest), ConfigChannel(longest), StateChannel(longest)}) {
    EXPECT_LE(channel.size(), 63u) << channel;
  }
}

TEST(Channels, ParsesWhatItBuilds) {
  for (const char* robot : {"pioneer", "a", "asimo_2", "x.y-z"}) {
    EXPECT_EQ(RobotOfRequestChannel(RequestChannel(robot)), robot);
    EXPECT_EQ(RobotOfConfigChannel(ConfigChannel(robot)), robot);
    EXPECT_EQ(RobotOfStateChannel(StateChannel(robot)), robot);
    for (std::int64_t id : {std::int64_t{1}, std::int64_t{0x7fffffffffffffff}, std::int64_t{-5}}) {
      EXPECT_EQ(ParseReplyChannel(ReplyChannel(robot, id)), (ReplyChannelParts{robot, id}));
    }
  }
}

TEST(Channels, ParseChannelNamesTheKindOfEveryChannelItBuilds) {
  EXPECT_EQ(ParseChannel(kAnnounceChannel), ChannelParts{});
  EXPECT_EQ(ParseChannel(HelloChannel("pioneer")), (ChannelParts{ChannelKind::kHello, "pioneer", 0}));
  EXPECT_EQ(ParseChannel(HelloAnswerChannel("pioneer", 0x4d2)),
            (ChannelParts{ChannelKind::kHelloAnswer, "pioneer", 0x4d2}));
  EXPECT_EQ(ParseChannel(RequestChannel("pioneer2")), (ChannelParts{ChannelKind::kRequest, "pioneer2", 0}));
  EXPECT_EQ(ParseChannel("ROBOTALK/pioneer2/REPLY/00000000000004d2"),
            (ChannelParts{ChannelKind::kReply, "pioneer2", 0x4d2}));
  EXPECT_EQ(ParseChannel(ConfigChannel("arm")), (ChannelParts{ChannelKind::kConfig, "arm", 0}));
  EXPECT_EQ(ParseChannel(StateChannel("arm")), (ChannelParts{ChannelKind::kState, "arm", 0}));
  for (const char* other : {"OTHER/x/REQUEST", "ROBOTALK/x/REQUEST/more", "ROBOTALK/x/REPLY/2a",
                            "ROBOTALK/x/NOISE", "ROBOTALK/ANNOUNCE/x", "LCM_SELF_TEST", ""}) {
    EXPECT_FALSE(ParseChannel(other)) << other;
  }
}

TEST(Channels, RefusesChannelsOfAnotherShape) {
  EXPECT_FALSE(RobotOfRequestChannel("ROBOTALK//REQUEST"));
  EXPECT_FALSE(RobotOfRequestChannel("ROBOTALK/a/b/REQUEST"));
  EXPECT_FALSE(RobotOfRequestChannel("ROBOTALK/REQUEST"));
  EXPECT_FALSE(RobotOfRequestChannel("ROBOTALK/a/REQUESTX"));
  EXPECT_FALSE(RobotOfRequestChannel("XROBOTALK/a/REQUEST"));
  EXPECT_FALSE(RobotOfRequestChannel("ROBOTALK/a/STATE"));
  EXPECT_FALSE(RobotOfStateChannel("ROBOTALK/a/REQUEST"));
  EXPECT_FALSE(RobotOfConfigChannel(kAnnounceChannel));
  EXPECT_FALSE(RobotOfStateChannel(""));
  EXPECT_FALSE(ParseReplyChannel("ROBOTALK/a/REPLY/2a"));                // not 16 digits
  EXPECT_FALSE(ParseReplyChannel("ROBOTALK/a/REPLY/000000000000002A"));  // upper case
  EXPECT_FALSE(ParseReplyChannel("ROBOTALK/a/REPLY/00000000000000g0"));
  EXPECT_FALSE(ParseReplyChannel("ROBOTALK//REPLY/000000000000002a"));
  EXPECT_FALSE(ParseReplyChannel("ROBOTALK/a/b/REPLY/000000000000002a"));
  EXPECT_FALSE(ParseReplyChannel("ROBOTALK/a/REPLY/0000000000000002a"));  // 17 digits
  EXPECT_FALSE(ParseReplyChannel("ROBOTALK/a/REQUEST"));
}

}  // namespace
}  // namespace robotalk
