#include "robotalk/error.h"
#include "robotalk/request.h"
#include "robotalk_msgs/announce_t.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstring>

namespace robotalk {
namespace {

using ::testing::HasSubstr;

TEST(RequestCodec, RoundTripsARequestWithEveryStartKind) {
  Request r{.client_id = 42, .sequence = 7, .send_time = TimePoint(std::chrono::seconds(5))};
  r.commands.push_back(
      Command{1, CommandType::kGoto, StartTime::At(TimePoint(std::chrono::seconds(9))), "", {1, 2, 3}});
  r.commands.push_back(Command{2, CommandType::kStop, StartTime::Now(), "", {}});
  const Request back = DecodeRequest(EncodeRequest(r));
  EXPECT_EQ(back.client_id, 42);
  EXPECT_EQ(back.sequence, 7);
  EXPECT_TRUE(back.header_error.empty());
  ASSERT_EQ(back.commands.size(), 2u);
  EXPECT_EQ(back.commands[0].start_time, r.commands[0].start_time);
  EXPECT_EQ(back.commands[0].values, r.commands[0].values);
  EXPECT_TRUE(back.commands[1].start_time.is_now());

  Request playback{.client_id = 42, .sequence = 8, .mode = RequestMode::kPlayback};
  playback.playback = {5, 2, std::chrono::seconds(1)};
  playback.commands.push_back(
      Command{3, CommandType::kStop, StartTime::After(std::chrono::milliseconds(500)), "", {}});
  const Request p = DecodeRequest(EncodeRequest(playback));
  EXPECT_EQ(p.playback.frames, 2);
  EXPECT_EQ(p.playback.duration, std::chrono::seconds(1));
  EXPECT_EQ(p.commands[0].start_time, StartTime::After(std::chrono::milliseconds(500)));
}

TEST(RequestCodec, RoundTripsAnAnnouncement) {
  Announcement a{.server_id = 9,
                 .server_time = TimePoint(std::chrono::seconds(3)),
                 .uptime = std::chrono::seconds(2),
                 .url_hint = "memory://"};
  a.robots.push_back({"pioneer", "ode", 0xabcdef, 4, BaseType::kDifferential, true, 3});
  const Announcement back = DecodeAnnouncement(EncodeAnnouncement(a));
  EXPECT_EQ(back.server_id, 9);
  EXPECT_EQ(back.uptime, std::chrono::seconds(2));
  ASSERT_EQ(back.robots.size(), 1u);
  EXPECT_EQ(back.robots[0].name, "pioneer");
  EXPECT_EQ(back.robots[0].config_hash, 0xabcdefu);
  EXPECT_TRUE(back.robots[0].panic);
  EXPECT_EQ(back.robots[0].base_type, BaseType::kDifferential);
}

TEST(RequestCodec, RefusesAnAnnouncedRobotWhoseBaseTypeIsNoBaseType) {
  Announcement a{.server_id = 9, .url_hint = "u"};
  a.robots.push_back({"r", "d", 1, 1, BaseType::kFloating, false, 0});
  std::vector<std::uint8_t> bytes = EncodeAnnouncement(a);
  // The robot's base_type byte: after config_hash (8) and total_dofs (4), 1 + 4 bytes before the end.
  ASSERT_EQ(bytes[bytes.size() - 6], 3);
  bytes[bytes.size() - 6] = 4;
  try {
    DecodeAnnouncement(bytes);
    FAIL() << "base_type 4 was accepted";
  } catch (const ProtocolError& e) {
    EXPECT_THAT(e.what(), HasSubstr("base_type"));
  }
}

// tests/fuzz: a zero-length string made LCM's generated decoder throw
// std::length_error through its C callback (std::terminate in the client).
TEST(RequestCodec, RefusesAnAnnouncementWithAZeroLengthStringOrAHostileCount) {
  Announcement a{.server_id = 9, .url_hint = "u"};
  a.robots.push_back({"r", "d", 1, 1, BaseType::kFixed, false, 0});
  std::vector<std::uint8_t> bytes = EncodeAnnouncement(a);
  // The url_hint's length field sits after the fingerprint and 2+8+8+8 header bytes.
  std::vector<std::uint8_t> zero = bytes;
  std::memset(zero.data() + 8 + 26, 0, 4);
  EXPECT_THROW(DecodeAnnouncement(zero), ProtocolError);
  // num_robots follows the 2-byte url string ("u\0") and its 4-byte length.
  std::vector<std::uint8_t> hostile = bytes;
  std::memset(hostile.data() + 8 + 26 + 4 + 2, 0xff, 4);
  try {
    DecodeAnnouncement(hostile);
    FAIL() << "a count of -1 was accepted";
  } catch (const ProtocolError& e) {
    EXPECT_THAT(e.what(), HasSubstr("num_robots"));
  }
  bytes.pop_back();
  EXPECT_THROW(DecodeAnnouncement(bytes), ProtocolError) << "truncated";
}

}  // namespace
}  // namespace robotalk
