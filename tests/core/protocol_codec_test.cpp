#include "robotalk/protocol_codec.h"
#include "robotalk/error.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <random>

namespace robotalk {
namespace {

using ::testing::HasSubstr;

robotalk_msgs::package_t SamplePackage() {
  robotalk_msgs::package_t p{};
  p.header.protocol_version = kProtocolVersion;
  p.header.client_id = 42;
  p.header.sequence = 7;
  p.header.payload_type = robotalk_msgs::package_header_t::PAYLOAD_COMMANDS;
  p.commands.push_back(
      ToWire(Command{1, CommandType::kJointSetPoint, std::nullopt, "pan_tilt", {0.5, -0.25}}));
  p.commands.push_back(
      ToWire(Command{2, CommandType::kGoto, TimePoint(std::chrono::seconds(12)), "", {1, 2, 3}}));
  p.num_commands = 2;
  p.header.payload_size = 2;
  return p;
}

std::vector<std::uint8_t> Encode(const robotalk_msgs::package_t& p) {
  std::vector<std::uint8_t> bytes(static_cast<size_t>(p.getEncodedSize()));
  p.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
  return bytes;
}

TEST(ProtocolCodec, RoundTripsCommandsQueriesAndReplies) {
  const Command c{9,
                  CommandType::kFrameSetPoint,
                  TimePoint(std::chrono::microseconds(123456789)),
                  "camera",
                  {1, 2, 3, 1, 0, 0, 0}};
  const Command back = FromWire(ToWire(c));
  EXPECT_EQ(back.id, c.id);
  EXPECT_EQ(back.type, c.type);
  EXPECT_EQ(back.start_time, c.start_time);
  EXPECT_EQ(back.target, c.target);
  EXPECT_EQ(back.values, c.values);
  EXPECT_FALSE(FromWire(ToWire(Command{1, CommandType::kStop, std::nullopt, "", {}})).start_time.has_value());

  const Query q{3, QueryType::kLinkPoses, "head"};
  EXPECT_EQ(FromWire(ToWire(q)).target, "head");
  EXPECT_EQ(FromWire(ToWire(q)).type, QueryType::kLinkPoses);

  Reply r{
      4,    Signal::kModified, "clamped", TimePoint(std::chrono::seconds(5)), std::chrono::milliseconds(7),
      {1.5}};
  const Reply rb = FromWire(ToWire(r));
  EXPECT_EQ(rb.signal, Signal::kModified);
  EXPECT_EQ(rb.message, "clamped");
  EXPECT_EQ(rb.exec_time, r.exec_time);
  EXPECT_EQ(rb.lateness, r.lateness);
  EXPECT_EQ(rb.values, r.values);
}

TEST(ProtocolCodec, RefusesUnknownTypesAndSignals) {
  auto c = ToWire(Command{1, CommandType::kStop, std::nullopt, "", {}});
  c.type = 99;
  EXPECT_THROW(FromWire(c), ProtocolError);
  auto q = ToWire(Query{1, QueryType::kClock, ""});
  q.type = 0;
  EXPECT_THROW(FromWire(q), ProtocolError);
  auto r = ToWire(Reply{});
  r.signal = 7;
  EXPECT_THROW(FromWire(r), ProtocolError);
}

TEST(ProtocolCodec, DecodesAWellFormedPackage) {
  const auto p = DecodePackage(Encode(SamplePackage()));
  EXPECT_EQ(p.header.sequence, 7);
  ASSERT_EQ(p.commands.size(), 2u);
  EXPECT_EQ(p.commands[0].target, "pan_tilt");
}

TEST(ProtocolCodec, RefusesEveryTruncationOfAPackage) {
  const auto bytes = Encode(SamplePackage());
  for (size_t n = 0; n < bytes.size(); ++n) {
    EXPECT_THROW(DecodePackage({bytes.data(), n}), ProtocolError) << "length " << n;
  }
  auto longer = bytes;
  longer.push_back(0);
  EXPECT_THROW(DecodePackage(longer), ProtocolError);
}

TEST(ProtocolCodec, RefusesHostileCountsWithoutAllocating) {
  const auto bytes = Encode(SamplePackage());
  const size_t num_commands_at = 8 + 53 + 4;  // fingerprint, header, num_queries
  for (std::uint32_t hostile : {0x7fffffffu, 0x80000000u, 0xffffffffu, 100000u}) {
    auto bad = bytes;
    for (int i = 0; i < 4; ++i)
      bad[num_commands_at + static_cast<size_t>(i)] = static_cast<std::uint8_t>(hostile >> (24 - 8 * i));
    try {
      DecodePackage(bad);
      ADD_FAILURE() << "accepted num_commands " << hostile;
    } catch (const ProtocolError& e) {
      EXPECT_THAT(e.what(), HasSubstr("num_commands"));
    }
  }
}

TEST(ProtocolCodec, SurvivesRandomCorruption) {
  const auto bytes = Encode(SamplePackage());
  std::mt19937 rng(1234);
  int decoded = 0;
  for (int trial = 0; trial < 5000; ++trial) {
    auto bad = bytes;
    for (int k = 0; k < 3; ++k) bad[rng() % bad.size()] = static_cast<std::uint8_t>(rng());
    try {
      DecodePackage(bad);
      ++decoded;
    } catch (const ProtocolError&) {
    }
  }
  EXPECT_GT(decoded, 0) << "some corruptions only change values";
}

TEST(ProtocolCodec, RefusesAMessageOfAnotherType) {
  robotalk_msgs::reply_package_t r{};
  std::vector<std::uint8_t> bytes(static_cast<size_t>(r.getEncodedSize()));
  r.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
  try {
    DecodePackage(bytes);
    ADD_FAILURE();
  } catch (const ProtocolError& e) {
    EXPECT_THAT(e.what(), HasSubstr("fingerprint"));
  }
  EXPECT_NO_THROW(DecodeReplyPackage(bytes));
}

TEST(ProtocolCodec, ChecksTheHeaderAgainstThePayload) {
  EXPECT_EQ(CheckPackageHeader(SamplePackage()), "");
  auto p = SamplePackage();
  p.header.payload_size = 3;
  EXPECT_THAT(CheckPackageHeader(p), HasSubstr("payload size 3"));
  p = SamplePackage();
  p.queries.push_back(ToWire(Query{5, QueryType::kClock, ""}));
  p.num_queries = 1;
  EXPECT_THAT(CheckPackageHeader(p), HasSubstr("mixes"));
  p = SamplePackage();
  p.header.payload_type = robotalk_msgs::package_header_t::PAYLOAD_QUERIES;
  EXPECT_THAT(CheckPackageHeader(p), HasSubstr("QUERIES but it carries commands"));
  p = SamplePackage();
  p.header.protocol_version = 9;
  EXPECT_THAT(CheckPackageHeader(p), HasSubstr("protocol version 9"));
  p = SamplePackage();
  p.header.client_id = 0;
  EXPECT_THAT(CheckPackageHeader(p), HasSubstr("client id 0"));
  p = SamplePackage();
  p.header.sequence = -1;
  EXPECT_THAT(CheckPackageHeader(p), HasSubstr("sequence"));
}

RobotModel TestRobot(BaseType base) {
  RobotModelBuilder b("bot");
  b.AddLink(Link{.name = "base"}).AddLink(Link{.name = "head"});
  Joint pt{.name = "pan_tilt", .servo_types = ServoType::kSetPoint | ServoType::kSpeed};
  pt.dofs = {Dof{.axis = Eigen::Vector3d::UnitZ()}, Dof{.axis = Eigen::Vector3d::UnitY()}};
  b.AddJoint(pt, "base", "head").AddJoint(Joint{.name = "weld"}, "head", "base_plate");
  b.AddLink(Link{.name = "base_plate"});
  b.AddControlFrame(ControlFrame{.name = "camera", .servo_types = ServoType::kSetPoint}, "head");
  b.SetRoot("base", Pose{}, base);
  return b.Build();
}

std::pair<Signal, std::string> Check(const RobotModel& m, const Command& c) {
  Signal s = Signal::kSuccess;
  auto msg = CheckCommand(m, c, &s);
  return {msg ? s : Signal::kSuccess, msg.value_or("")};
}

TEST(CheckCommand, AcceptsWellFormedCommandsAndNamesWhatIsWrongOtherwise) {
  const RobotModel m = TestRobot(BaseType::kDifferential);
  EXPECT_EQ(Check(m, {1, CommandType::kJointSetPoint, {}, "pan_tilt", {0.1, 0.2}}).first, Signal::kSuccess);
  EXPECT_EQ(Check(m, {1, CommandType::kGoto, {}, "", {1, 2, 0}}).first, Signal::kSuccess);
  EXPECT_EQ(Check(m, {1, CommandType::kSetSpeed, {}, "", {0.1, 0.0, 0.2}}).first, Signal::kSuccess);
  EXPECT_EQ(Check(m, {1, CommandType::kFrameSetPoint, {}, "camera", {0, 0, 1, 1, 0, 0, 0}}).first,
            Signal::kSuccess);

  auto [s1, m1] = Check(m, {1, CommandType::kJointSetPoint, {}, "pan_tilt", {0.1}});
  EXPECT_EQ(s1, Signal::kError);
  EXPECT_THAT(m1, HasSubstr("expected 2 values"));
  auto [s2, m2] = Check(m, {1, CommandType::kJointForce, {}, "pan_tilt", {0.1, 0.1}});
  EXPECT_EQ(s2, Signal::kNa);
  EXPECT_THAT(m2, HasSubstr("accepts only setpoint speed"));
  auto [s3, m3] = Check(m, {1, CommandType::kJointSetPoint, {}, "weld", {}});
  EXPECT_EQ(s3, Signal::kError);
  EXPECT_THAT(m3, HasSubstr("fixed"));
  auto [s4, m4] = Check(m, {1, CommandType::kFrameSetPoint, {}, "camera", {0, 0, 1, 2, 0, 0, 0}});
  EXPECT_EQ(s4, Signal::kError);
  EXPECT_THAT(m4, HasSubstr("norm"));
  auto [s5, m5] = Check(m, {1, CommandType::kGoto, {}, "", {1, std::numeric_limits<double>::infinity(), 0}});
  EXPECT_EQ(s5, Signal::kError);
  EXPECT_THAT(m5, HasSubstr("infinite"));
  EXPECT_EQ(Check(m, {1, CommandType::kStop, {}, "", {1}}).first, Signal::kError);
  EXPECT_EQ(Check(m, {1, CommandType::kGoto, {}, "pan_tilt", {1, 2, 3}}).first, Signal::kError);

  const RobotModel arm = TestRobot(BaseType::kFixed);
  auto [s6, m6] = Check(arm, {1, CommandType::kSetSpeed, {}, "", {0.1, 0.1}});
  EXPECT_EQ(s6, Signal::kNa);
  EXPECT_THAT(m6, HasSubstr("fixed base"));
}

TEST(CheckCommand, ChecksQueryTargets) {
  const RobotModel m = TestRobot(BaseType::kDifferential);
  EXPECT_FALSE(CheckQuery(m, {1, QueryType::kJointState, "pan_tilt"}));
  EXPECT_THAT(*CheckQuery(m, {1, QueryType::kLinkPoses, "nose"}), HasSubstr("no link named 'nose'"));
  EXPECT_THAT(*CheckQuery(m, {1, QueryType::kClock, "x"}), HasSubstr("takes no target"));
}

TEST(CommandNames, ParseWhatTheyPrint) {
  for (int t = 1; t <= 8; ++t) {
    auto type = static_cast<CommandType>(t);
    EXPECT_EQ(ParseCommandType(ToString(type)), type);
  }
  EXPECT_EQ(ParseCommandType("goto"), CommandType::kGoto);
  EXPECT_EQ(ParseCommandType("joint-setpoint"), CommandType::kJointSetPoint);
  EXPECT_EQ(ParseQueryType("base_pose"), QueryType::kBasePose);
  EXPECT_FALSE(ParseCommandType("fly"));
  EXPECT_EQ(ToString(Signal::kInterrupted), "INTERRUPTED");
  EXPECT_EQ(SignalFromWire(6), Signal::kPanic);
  EXPECT_FALSE(SignalFromWire(7));
}

}  // namespace
}  // namespace robotalk
