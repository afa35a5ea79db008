#include "protocol_codec.h"
#include "robotalk/error.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
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
  EXPECT_TRUE(FromWire(ToWire(Command{1, CommandType::kStop, std::nullopt, "", {}})).start_time.is_now());

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
  const size_t num_commands_at = 8 + 78 + 4;  // fingerprint, header (protocol 4: 78 bytes), num_queries
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

// --- Start times and wire times ----------------------------------------------

using Header = robotalk_msgs::package_header_t;

robotalk_msgs::command_t WireStop(std::int64_t start_us) {
  robotalk_msgs::command_t w{};
  w.id = 7;
  w.type = static_cast<std::int8_t>(CommandType::kStop);
  w.start_time_us = start_us;
  return w;
}

TEST(StartTime, MapsToTheWireByThePackageMode) {
  const TimePoint t(std::chrono::seconds(12));
  EXPECT_EQ(ToWire(Command{.start_time = StartTime::Now()}).start_time_us, 0);
  EXPECT_EQ(ToWire(Command{.start_time = StartTime::At(t)}, Header::MODE_DELAY).start_time_us, 12000000);
  EXPECT_EQ(
      ToWire(Command{.start_time = StartTime::After(std::chrono::milliseconds(300))}, Header::MODE_PLAYBACK)
          .start_time_us,
      300000);
  EXPECT_EQ(FromWire(WireStop(0), Header::MODE_DIRECT).start_time, StartTime::Now());
  EXPECT_EQ(FromWire(WireStop(12000000), Header::MODE_DELAY).start_time, StartTime::At(t));
  EXPECT_EQ(FromWire(WireStop(12000000)).start_time, StartTime::At(t));  // no mode: absolute
  EXPECT_EQ(FromWire(WireStop(300000), Header::MODE_PLAYBACK).start_time,
            StartTime::After(std::chrono::milliseconds(300)));
  // In a playback package 0 is the sequence start, not "now".
  EXPECT_EQ(FromWire(WireStop(0), Header::MODE_PLAYBACK).start_time, StartTime::After(Duration(0)));
}

TEST(StartTime, RefusesAKindThatDoesNotBelongInThePackageMode) {
  const Command offset{.id = 3, .start_time = StartTime::After(std::chrono::seconds(1))};
  const Command absolute{.id = 4, .start_time = StartTime::At(TimePoint(std::chrono::seconds(5)))};
  EXPECT_THROW(ToWire(offset, Header::MODE_DIRECT), ProtocolError);
  EXPECT_THROW(ToWire(offset, Header::MODE_DELAY), ProtocolError);
  EXPECT_THROW(ToWire(absolute, Header::MODE_PLAYBACK), ProtocolError);
  EXPECT_NO_THROW(ToWire(Command{}, Header::MODE_PLAYBACK));
  try {
    ToWire(Command{.id = 5, .start_time = StartTime::At(TimePoint(-std::chrono::seconds(1)))});
    ADD_FAILURE() << "a start before the epoch has no wire form";
  } catch (const ProtocolError& e) {
    EXPECT_THAT(e.what(), HasSubstr("command 5"));
  }
  EXPECT_THROW(ToWire(Command{.start_time = StartTime::After(-std::chrono::seconds(1))}), ProtocolError);
}

TEST(StartTime, ConvertsFromTimePointsAndOptionals) {
  const TimePoint t(std::chrono::seconds(3));
  const StartTime from_time = t;
  const StartTime from_nullopt = std::nullopt;
  const StartTime from_optional = std::optional<TimePoint>(t);
  EXPECT_EQ(from_time, StartTime::At(t));
  EXPECT_TRUE(from_nullopt.is_now());
  EXPECT_EQ(from_optional.time(), t);
  EXPECT_FALSE(StartTime::After(Duration(5)).time());
  EXPECT_EQ(StartTime::After(Duration(5)).offset(), Duration(5));
  EXPECT_NE(StartTime::At(TimePoint(Duration(5))), StartTime::After(Duration(5)));
  EXPECT_EQ(ToString(StartTime::After(std::chrono::milliseconds(250))), "after 0.250000 s");
}

TEST(WireTime, ConvertsTheExtremesWithoutOverflow) {
  EXPECT_EQ(FromWireMicros(kMaxWireMicros).time_since_epoch().count(), kMaxWireMicros * 1000);
  EXPECT_EQ(FromWireMicros(-kMaxWireMicros).time_since_epoch().count(), -kMaxWireMicros * 1000);
  EXPECT_EQ(FromWireMicros(9'300'000'000'000LL).time_since_epoch(), std::chrono::seconds(9'300'000));
  for (std::int64_t bad : {INT64_MAX, INT64_MIN, kMaxWireMicros + 1, -kMaxWireMicros - 1,
                           std::int64_t{18446744073709552}, std::int64_t{9'300'000'000'000'000}}) {
    EXPECT_FALSE(TryDurationFromWireMicros(bad)) << bad;
    try {
      FromWireMicros(bad, "reply 3: exec_time_us");
      ADD_FAILURE() << bad;
    } catch (const ProtocolError& e) {
      EXPECT_THAT(e.what(),
                  HasSubstr("reply 3: exec_time_us " + std::to_string(bad) + " us is out of range"));
    }
  }
  // The other way cannot overflow: it divides.
  EXPECT_EQ(ToWireMicros(TimePoint::max()), INT64_MAX / 1000);
  EXPECT_EQ(ToWireMicros(TimePoint::min()), INT64_MIN / 1000);
}

TEST(WireTime, OutOfRangeStartTimesAreProtocolErrorsNamingTheField) {
  for (std::int8_t mode : {Header::MODE_DIRECT, Header::MODE_DELAY, Header::MODE_PLAYBACK}) {
    for (std::int64_t bad :
         {INT64_MAX, std::int64_t{18446744073709552}, std::int64_t{9'300'000'000'000'000}}) {
      try {
        FromWire(WireStop(bad), mode);
        ADD_FAILURE() << bad;
      } catch (const ProtocolError& e) {
        EXPECT_THAT(e.what(), HasSubstr("command 7: start_time_us " + std::to_string(bad) + " us"));
      }
    }
    EXPECT_THROW(FromWire(WireStop(INT64_MIN), mode), ProtocolError);
  }
}

TEST(WireTime, RepliesAndQueriesCheckTheirTimes) {
  robotalk_msgs::reply_t r = ToWire(Reply{.id = 9});
  r.exec_time_us = INT64_MIN;
  EXPECT_THROW(FromWire(r), ProtocolError);
  r = ToWire(Reply{.id = 9});
  r.lateness_us = INT64_MAX;
  try {
    FromWire(r);
    ADD_FAILURE();
  } catch (const ProtocolError& e) {
    EXPECT_THAT(e.what(), HasSubstr("reply 9: lateness_us"));
  }
  robotalk_msgs::query_t q = ToWire(Query{.id = 2, .type = QueryType::kStateStream});
  q.period_us = INT64_MAX;
  EXPECT_THROW(FromWire(q), ProtocolError);
  auto p = SamplePackage();
  p.header.mode = Header::MODE_PLAYBACK;
  p.header.playback_id = 1;
  p.header.playback_frames = 2;
  p.header.playback_duration_us = INT64_MAX;
  EXPECT_THAT(CheckPackageHeader(p), HasSubstr("playback_duration_us"));
}

TEST(WireTime, FromSecondsRefusesWhatNoDurationHolds) {
  EXPECT_EQ(FromSeconds(1.5), std::chrono::milliseconds(1500));
  EXPECT_THROW(FromSeconds(std::nan("")), Error);
  EXPECT_THROW(FromSeconds(1e300), Error);
  EXPECT_THROW(FromSeconds(-std::numeric_limits<double>::infinity()), Error);
}

// Issue 19: "FromSeconds: 1e12 s is not a finite time" (it is finite).
TEST(WireTime, FromSecondsNamesTheLimitForAFiniteTimeOutOfRangeAndNonFiniteOnlyForNaNAndInfinity) {
  const auto message = [](double s) {
    try {
      FromSeconds(s);
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_EQ(message(1e12),
            "FromSeconds: 1e+12 s is out of range: a time holds at most +-9.2e+09 s (292 years)");
  EXPECT_EQ(message(-1e12),
            "FromSeconds: -1e+12 s is out of range: a time holds at most +-9.2e+09 s (292 years)");
  EXPECT_THAT(message(std::nan("")), HasSubstr("nan s is not a finite time"));
  EXPECT_THAT(message(std::numeric_limits<double>::infinity()), HasSubstr("inf s is not a finite time"));
  EXPECT_NO_THROW(FromSeconds(9.1e9));
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
  auto bad = CheckCommand(m, c);
  return {bad ? bad->signal : Signal::kSuccess, bad ? bad->message : ""};
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

// Issue 22: a waypoint's velocities and accelerations are one per dof (6 for a frame), finite, and only a
// set-point waypoint has them.
TEST(CheckCommand, AWaypointsRatesAreOnePerDofOrSixForAFrameAndFinite) {
  const RobotModel m = TestRobot(BaseType::kDifferential);
  Command joint{1, CommandType::kJointSetPoint, {}, "pan_tilt", {0.1, 0.2}, {0.5, -0.5}, {1, 2}};
  EXPECT_EQ(Check(m, joint).first, Signal::kSuccess);
  joint.accelerations.clear();  // velocities alone
  EXPECT_EQ(Check(m, joint).first, Signal::kSuccess);
  joint.velocities = {0.5};
  EXPECT_EQ(Check(m, joint).second, "JOINT_SETPOINT 'pan_tilt': expected 0 or 2 velocities, got 1");
  joint.velocities = {0.5, std::nan("")};
  EXPECT_EQ(Check(m, joint).second, "JOINT_SETPOINT 'pan_tilt': velocity 1 is NaN");
  Command frame{1, CommandType::kFrameSetPoint, {}, "camera", {0, 0, 1, 1, 0, 0, 0}, {0, 0, 0, 0, 0, 1}, {}};
  EXPECT_EQ(Check(m, frame).first, Signal::kSuccess);
  frame.accelerations = {1, 2, 3};
  EXPECT_EQ(Check(m, frame).second, "FRAME_SETPOINT 'camera': expected 0 or 6 accelerations, got 3");
  EXPECT_EQ(Check(m, {1, CommandType::kGoto, {}, "", {1, 2, 0}, {1, 0, 0}, {}}).second,
            "GOTO: takes no velocities (only a JOINT_SETPOINT or FRAME_SETPOINT waypoint does)");
}

// Issue 19: `GOTO 1e308 0 0` was accepted (ODE drove at full speed).
TEST(CheckCommand, RefusesAGotoBeyondTheBoundNamingTheTargetAndTheBound) {
  const RobotModel m = TestRobot(BaseType::kDifferential);
  auto [s1, m1] = Check(m, {1, CommandType::kGoto, {}, "", {1e308, 0, 0}});
  EXPECT_EQ(s1, Signal::kError);
  EXPECT_EQ(m1, "GOTO: target (1e+308, 0) m is 1e+308 m from the world origin; the bound is 100 m");
  auto [s2, m2] = Check(m, {1, CommandType::kGoto, {}, "", {-80, 70, 0}});
  EXPECT_EQ(s2, Signal::kError);
  EXPECT_THAT(m2, HasSubstr("106.3 m from the world origin"));
  EXPECT_EQ(Check(m, {1, CommandType::kGoto, {}, "", {-60, 79, 3}}).first, Signal::kSuccess);
  // Configurable: the server's --max-goto-distance.
  const CommandLimits wide{.max_goto_distance = 1000};
  EXPECT_FALSE(CheckCommand(m, {1, CommandType::kGoto, {}, "", {-80, 70, 0}}, wide));
  EXPECT_THAT(CheckCommand(m, {1, CommandType::kGoto, {}, "", {0, 2000, 0}}, wide)->message,
              HasSubstr("the bound is 1000 m"));
}

TEST(CheckCommand, ChecksQueryTargets) {
  const RobotModel m = TestRobot(BaseType::kDifferential);
  EXPECT_FALSE(CheckQuery(m, {1, QueryType::kJointState, "pan_tilt"}));
  EXPECT_THAT(CheckQuery(m, {1, QueryType::kLinkPoses, "nose"})->message, HasSubstr("no link named 'nose'"));
  EXPECT_THAT(CheckQuery(m, {1, QueryType::kClock, "x"})->message, HasSubstr("takes no target"));
  EXPECT_EQ(CheckQuery(m, {1, QueryType::kClock, "x"})->signal, Signal::kError);
}

TEST(CommandNames, ParseWhatTheyPrint) {
  for (int t = 1; t <= 8; ++t) {
    auto type = static_cast<CommandType>(t);
    EXPECT_EQ(ParseCommandType(ToString(type)), type);
  }
  EXPECT_EQ(ParseCommandType("goto"), CommandType::kGoto);
  EXPECT_EQ(ParseCommandType("joint-setpoint"), CommandType::kJointSetPoint);
  EXPECT_EQ(ParseQueryType("base_pose"), QueryType::kBasePose);
  // Every query type parses what it prints (COMMAND_STATUS and SERVER_COUNTERS did not).
  for (int t = static_cast<int>(QueryType::kConfig); t <= static_cast<int>(QueryType::kServerCounters); ++t) {
    auto type = static_cast<QueryType>(t);
    EXPECT_EQ(ParseQueryType(ToString(type)), type) << ToString(type);
  }
  EXPECT_FALSE(ParseQueryType("fly"));
  EXPECT_FALSE(ParseCommandType("fly"));
  EXPECT_EQ(ToString(Signal::kInterrupted), "INTERRUPTED");
  EXPECT_EQ(SignalFromWire(6), Signal::kPanic);
  EXPECT_FALSE(SignalFromWire(7));
}

}  // namespace
}  // namespace robotalk
