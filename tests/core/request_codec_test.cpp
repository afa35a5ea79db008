#include "protocol_codec.h"
#include "robotalk/error.h"
#include "robotalk/request.h"
#include "robotalk_msgs/announce_t.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstring>

namespace robotalk {
namespace {

using ::testing::HasSubstr;
using Header = robotalk_msgs::package_header_t;
// Copies of LCM's in-class constants (binding those to a reference needs a definition).
constexpr std::int8_t kQueries = Header::PAYLOAD_QUERIES, kCommands = Header::PAYLOAD_COMMANDS;
constexpr std::int8_t kDirect = Header::MODE_DIRECT, kDelay = Header::MODE_DELAY;

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

// Review 12: an ANNOUNCE is anyone's datagram, and its robot names reached
// every reader as they came: `robotalk robots` printed a name carrying
// terminal escapes to the operator's terminal, robotalk-ros2 logged it, and
// robotalk-web's and robotalk-ros2's tables took names no server can serve
// (longer than kMaxRobotNameLength, or not letters, digits, '_', '-'). The
// decoder they all share refuses such an announcement naming the rule.
TEST(RequestCodec, RefusesAnAnnouncedRobotNameOutsideTheRobotNameRule) {
  for (const std::string& name : {std::string("pioneer\x1b]0;owned\x07"), std::string(32, 'a'), std::string(),
                                  std::string("arm one"), std::string("arm\nrobotalk: fake line")}) {
    Announcement a{.server_id = 9, .url_hint = "u"};
    a.robots.push_back({"pioneer", "ode"});
    a.robots.push_back({name, "ode"});
    try {
      DecodeAnnouncement(EncodeAnnouncement(a));
      ADD_FAILURE() << "the robot name of " << name.size() << " characters was accepted";
    } catch (const ProtocolError& e) {
      EXPECT_THAT(e.what(), HasSubstr("robot.name"));
      EXPECT_THAT(e.what(), HasSubstr("a robot name"));
    }
  }
  // Its other texts are printed beside the name: no control characters.
  Announcement driver{.server_id = 9, .url_hint = "u"};
  driver.robots.push_back({"pioneer", "ode\x1b[2J"});
  EXPECT_THROW(DecodeAnnouncement(EncodeAnnouncement(driver)), ProtocolError) << "a driver with an escape";
  driver.robots[0].driver =
      "ode\xc2\x9b"
      "2J";  // U+009B, CSI: a terminal that takes C1 controls clears its screen
  EXPECT_THROW(DecodeAnnouncement(EncodeAnnouncement(driver)), ProtocolError) << "a driver with a C1 CSI";
  Announcement url{.server_id = 9, .url_hint = "udpm://x\r\x1b[1A"};
  EXPECT_THROW(DecodeAnnouncement(EncodeAnnouncement(url)), ProtocolError) << "a url hint with an escape";
  Announcement ok{.server_id = 9, .url_hint = "udpm://239.255.76.67:7667?ttl=0"};
  ok.robots.push_back({std::string(31, 'a'), "ode"});
  EXPECT_EQ(DecodeAnnouncement(EncodeAnnouncement(ok)).robots.at(0).name, std::string(31, 'a'));
}

// Every reader of ANNOUNCE (the client, robotalk-web, robotalk-logplay) uses
// this decoder: a hostile robot count must not reach LCM's, which would
// allocate the array from it. (These were robotalk-web's tests of its own
// guard, tests/web/announce_check_test.cpp, before the web used the codec.)
std::vector<std::uint8_t> AnnouncementOf(int robots, const std::string& url = "udpm://x") {
  Announcement a{.server_id = 42, .url_hint = url};
  for (int i = 0; i < robots; ++i) a.robots.push_back({"robot" + std::to_string(i), "ode"});
  return EncodeAnnouncement(a);
}

// Offset of num_robots: fingerprint, version, server id, time, uptime, url
// (length + text + NUL), traffic_layout, keyed.
std::size_t RobotCountOffset(const std::string& url) {
  return 8 + 2 + 8 + 8 + 8 + 4 + url.size() + 1 + 1 + 1;
}

TEST(RequestCodec, DecodesAnnouncementsOfNoneOrSeveralRobots) {
  for (int n : {0, 1, 3})
    EXPECT_EQ(DecodeAnnouncement(AnnouncementOf(n)).robots.size(), static_cast<std::size_t>(n));
}

TEST(RequestCodec, RefusesAnAnnouncedRobotCountTheDatagramCannotHold) {
  auto bytes = AnnouncementOf(1);
  const std::size_t at = RobotCountOffset("udpm://x");
  ASSERT_EQ(bytes[at + 3], 1);
  bytes[at] = 0x10;  // 268 million robots in a datagram of ~80 bytes
  EXPECT_THROW(DecodeAnnouncement(bytes), ProtocolError);
  bytes[at] = 0xff;  // negative
  EXPECT_THROW(DecodeAnnouncement(bytes), ProtocolError);
}

TEST(RequestCodec, RefusesATruncatedAnnouncementOrAnOverlongUrl) {
  const auto bytes = AnnouncementOf(2);
  for (std::size_t n : {std::size_t{0}, std::size_t{10}, std::size_t{37}, RobotCountOffset("udpm://x") + 2})
    EXPECT_THROW(DecodeAnnouncement(std::span(bytes.data(), n)), ProtocolError) << n;
  auto long_url = AnnouncementOf(1);
  long_url[34] = 0x7f;  // url length far beyond the datagram
  EXPECT_THROW(DecodeAnnouncement(long_url), ProtocolError);
}

// The C++ client sends every package through EncodeRequest: a heartbeat and
// a panic are empty packages, which docs/protocol.md documents as
// PAYLOAD_QUERIES of size 0, and the server's own header check accepts.
TEST(RequestCodec, AnEmptyRequestIsTheDocumentedHeartbeatAQueriesPackageOfSizeZero) {
  for (const bool panic : {false, true}) {
    const Request empty{.client_id = 42, .session_id = 3, .sequence = 9, .panic = panic};
    const auto p = DecodePackage(EncodeRequest(empty));
    EXPECT_EQ(p.header.payload_type, kQueries);
    EXPECT_EQ(p.header.payload_size, 0);
    EXPECT_EQ(p.header.panic, panic);
    EXPECT_EQ(CheckPackageHeader(p), "");
  }
  Request commands{.client_id = 42, .sequence = 10};
  commands.commands.push_back(Command{1, CommandType::kStop, StartTime::Now(), "", {}});
  const auto p = DecodePackage(EncodeRequest(commands));
  EXPECT_EQ(p.header.payload_type, kCommands);
  EXPECT_EQ(p.header.payload_size, 1);
}

TEST(RequestCodec, EachModeTravelsAsTheProtocolPageNamesIt) {
  const TimePoint at(std::chrono::seconds(9));
  for (const auto& [mode, wire] :
       {std::pair{RequestMode::kDirect, kDirect}, std::pair{RequestMode::kDelay, kDelay}}) {
    Request r{.client_id = 42, .sequence = 1, .mode = mode};
    r.commands.push_back(Command{1, CommandType::kGoto, StartTime::At(at), "", {1, 2, 3}});
    const auto bytes = EncodeRequest(r);
    EXPECT_EQ(DecodePackage(bytes).header.mode, wire);
    const Request back = DecodeRequest(bytes);
    EXPECT_EQ(back.mode, mode);
    EXPECT_EQ(back.commands.at(0).start_time, StartTime::At(at));
  }
  // Offsets belong in PLAYBACK only: refused before anything is sent.
  Request delay{.client_id = 42, .sequence = 2, .mode = RequestMode::kDelay};
  delay.commands.push_back(Command{1, CommandType::kStop, StartTime::After(std::chrono::seconds(1)), "", {}});
  EXPECT_THROW(EncodeRequest(delay), ProtocolError);
}

TEST(RequestCodec, TheMacIsTheLastBytesOfTheEncodingAndCoversEveryByteBeforeIt) {
  Request r{.client_id = 42, .session_id = 5, .sequence = 1};
  r.queries.push_back(Query{.id = 1, .type = QueryType::kClock});
  std::vector<std::uint8_t> bytes = EncodeRequest(r);
  EXPECT_EQ(MacCoveredBytes(bytes).size(), bytes.size() - kMacBytes);
  Mac mac{};
  mac.fill(0xab);
  WriteMacField(bytes, mac);
  EXPECT_EQ(DecodeRequest(bytes).mac, mac);
  r.mac = mac;
  EXPECT_EQ(EncodeRequest(r), bytes) << "sealing the bytes and encoding the MAC agree";
}

// Everything the client reads from a reply package comes through DecodeReplyBatch.
TEST(RequestCodec, AReplyBatchRoundTripsEveryFieldTheClientReads) {
  ReplyBatch b{.client_id = 42,
               .server_id = 7,
               .session_id = 5,
               .session_status = SessionStatus::kUnknown,
               .ack_sequence = 11,
               .panic = PanicStatus::kRefused,
               .panic_refusal = "key 'viewer' has no panic right",
               .server_receive = TimePoint(std::chrono::seconds(20)),
               .server_send = TimePoint(std::chrono::seconds(21))};
  b.replies.push_back(Reply{.id = 3, .signal = Signal::kModified, .message = "clamped", .values = {0.5}});
  b.mac.fill(0x5a);
  const ReplyBatch back = DecodeReplyBatch(EncodeReplyBatch(b));
  EXPECT_EQ(back.client_id, 42);
  EXPECT_EQ(back.server_id, 7);
  EXPECT_EQ(back.session_id, 5);
  EXPECT_EQ(back.session_status, SessionStatus::kUnknown);
  EXPECT_EQ(back.ack_sequence, 11);
  EXPECT_EQ(back.panic, PanicStatus::kRefused);
  EXPECT_EQ(back.panic_refusal, b.panic_refusal);
  EXPECT_EQ(back.server_receive, b.server_receive);
  EXPECT_EQ(back.server_send, b.server_send);
  ASSERT_EQ(back.replies.size(), 1u);
  EXPECT_EQ(back.replies[0].signal, Signal::kModified);
  EXPECT_EQ(back.replies[0].values, std::vector<double>{0.5});
  EXPECT_TRUE(back.malformed.empty());
  EXPECT_EQ(back.mac, b.mac);
}

// A reply the client cannot read (a newer signal) must not cost the batch's
// ack and its other replies: it is reported, the rest stands.
TEST(RequestCodec, AnUndecodableReplyIsReportedAndTheRestOfTheBatchStands) {
  ReplyBatch b{.client_id = 42, .session_id = 5, .ack_sequence = 11};
  b.replies.push_back(Reply{.id = 3, .signal = Signal::kSuccess});
  b.replies.push_back(Reply{.id = 4, .signal = static_cast<Signal>(99)});
  const ReplyBatch back = DecodeReplyBatch(EncodeReplyBatch(b));
  EXPECT_EQ(back.ack_sequence, 11);
  ASSERT_EQ(back.replies.size(), 1u);
  EXPECT_EQ(back.replies[0].id, 3);
  ASSERT_EQ(back.malformed.size(), 1u);
  EXPECT_EQ(back.malformed[0].id, 4);
  EXPECT_THAT(back.malformed[0].reason, HasSubstr("signal"));
}

TEST(RequestCodec, AReplyBatchOfAnotherProtocolVersionIsRefusedNamingBothVersions) {
  std::vector<std::uint8_t> bytes = EncodeReplyBatch(ReplyBatch{.client_id = 42});
  bytes[8] = 0;  // protocol_version (int16, big-endian) follows the 8-byte fingerprint
  bytes[9] = 1;
  try {
    DecodeReplyBatch(bytes);
    FAIL() << "a version-1 reply package was accepted";
  } catch (const ProtocolError& e) {
    EXPECT_THAT(e.what(), HasSubstr("protocol version 1"));
    EXPECT_THAT(e.what(), HasSubstr(std::to_string(kProtocolVersion)));
  }
}

// Issue 22/23 (protocol 4): the package's interpolation and max_late, and a waypoint's rates, travel.
TEST(RequestCodec, CarriesTheInterpolationTheMaxLateAndAWaypointsRates) {
  Request r{.client_id = 42, .sequence = 7, .mode = RequestMode::kDelay};
  r.interpolation = Interpolation::kQuintic;
  r.max_late = std::chrono::milliseconds(100);
  r.commands.push_back(Command{1,
                               CommandType::kJointSetPoint,
                               StartTime::At(TimePoint(std::chrono::seconds(9))),
                               "pan",
                               {0.5},
                               {0.25},
                               {-1.0}});
  const Request back = DecodeRequest(EncodeRequest(r));
  EXPECT_TRUE(back.header_error.empty()) << back.header_error;
  EXPECT_EQ(back.interpolation, Interpolation::kQuintic);
  EXPECT_EQ(back.max_late, std::chrono::milliseconds(100));
  ASSERT_EQ(back.commands.size(), 1u);
  EXPECT_EQ(back.commands[0].velocities, std::vector<double>{0.25});
  EXPECT_EQ(back.commands[0].accelerations, std::vector<double>{-1.0});

  r.max_late = kMaxLateNever;
  EXPECT_EQ(DecodeRequest(EncodeRequest(r)).max_late, kMaxLateNever);
  r.max_late = kMaxLateServerDefault;
  r.interpolation = Interpolation::kStep;
  const Request old_style = DecodeRequest(EncodeRequest(r));
  EXPECT_EQ(old_style.max_late, kMaxLateServerDefault);
  EXPECT_EQ(old_style.interpolation, Interpolation::kStep);
  r.max_late = -std::chrono::seconds(1);
  EXPECT_THROW(EncodeRequest(r), ProtocolError);
}

// A positive max_late below the wire's resolution (1 µs) travels as 1 µs:
// 0 on the wire is "the robot's default" (0.1 s unless --max-late), so a
// limit of 400 ns, truncated to 0, became a limit 250,000 times looser
// (review 10; the CLI's --max-late 1e-7 did the same).
TEST(RequestCodec, APositiveMaxLateBelowAMicrosecondIsNeverTheRobotsDefault) {
  Request r{.client_id = 42, .sequence = 7, .mode = RequestMode::kDelay};
  r.max_late = std::chrono::nanoseconds(400);
  EXPECT_EQ(DecodeRequest(EncodeRequest(r)).max_late, std::chrono::microseconds(1));
  r.max_late = std::chrono::nanoseconds(1500);
  EXPECT_EQ(DecodeRequest(EncodeRequest(r)).max_late, std::chrono::microseconds(1)) << "truncated as before";
}

TEST(RequestCodec, AnUnknownInterpolationOrANegativeMaxLateIsAHeaderError) {
  robotalk_msgs::package_t p{};
  p.header.protocol_version = kProtocolVersion;
  p.header.client_id = 9;
  p.header.sequence = 1;
  p.header.payload_type = kQueries;
  p.header.interpolation = 7;
  EXPECT_EQ(DecodeRequest(EncodeMessage(p)).header_error,
            "package: unknown interpolation 7 (0 step, 1 linear, 2 cubic, 3 quintic)");
  p.header.interpolation = Header::INTERPOLATION_CUBIC;
  p.header.max_late_us = -5;
  EXPECT_EQ(DecodeRequest(EncodeMessage(p)).header_error,
            "package: max_late_us -5 is negative (0 = the server's default, -1 = never)");
  p.header.max_late_us = 0;
  EXPECT_EQ(DecodeRequest(EncodeMessage(p)).header_error, "");
  p.header.round_trip_us = -3;
  EXPECT_EQ(DecodeRequest(EncodeMessage(p)).header_error,
            "package: round_trip_us -3 is negative or out of range");
}

// Issue 23: the client's smoothed round trip travels (the server's link health reports it).
TEST(RequestCodec, CarriesTheClientsRoundTrip) {
  Request r{.client_id = 42, .sequence = 7};
  r.round_trip = std::chrono::microseconds(40'250);
  EXPECT_EQ(DecodeRequest(EncodeRequest(r)).round_trip, std::chrono::microseconds(40'250));
  r.round_trip = Duration(0);
  EXPECT_EQ(DecodeRequest(EncodeRequest(r)).round_trip, Duration(0));
}

}  // namespace
}  // namespace robotalk
