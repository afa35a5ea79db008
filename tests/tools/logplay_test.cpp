// SessionLog and the frame/sequence helpers of robotalk-logplay, fed with
// packages encoded by the message layer in memory (no LCM), and hostile logs
// written with LCM's log API in a temp dir.
#include "logplay.h"
#include "mcap_export.h"
#include "receipt_order.h"
#include "robotalk/channels.h"
#include "robotalk/request.h"
#include "robotalk/sequence_file.h"

#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <lcm/lcm-cpp.hpp>
#include <limits>
#include <memory>
#include <sstream>

namespace robotalk::logplay {
namespace {

constexpr std::int64_t kClient = 0x1234;
constexpr RequestMode kDirect = RequestMode::kDirect, kDelay = RequestMode::kDelay,
                      kPlayback = RequestMode::kPlayback;

TimePoint AtMicros(std::int64_t us) { return TimePoint(std::chrono::microseconds(us)); }

struct Cmd {
  std::int64_t id;
  CommandType type;
  std::int64_t start_us;  ///< 0 = now; else absolute, or the playback offset
  std::string target;
  std::vector<double> values;
};

std::vector<std::uint8_t> Package(std::int64_t client, std::int64_t seq, std::int64_t send_us,
                                  RequestMode mode, const std::vector<Cmd>& cmds,
                                  std::int64_t playback_id = 0) {
  Request r{.client_id = client, .sequence = seq, .send_time = AtMicros(send_us), .mode = mode};
  if (mode == kPlayback) r.playback = {playback_id, static_cast<std::int64_t>(cmds.size()), Duration(0)};
  for (const Cmd& c : cmds) {
    const StartTime start = mode == kPlayback ? StartTime::After(std::chrono::microseconds(c.start_us))
                            : c.start_us == 0 ? StartTime::Now()
                                              : StartTime::At(AtMicros(c.start_us));
    r.commands.push_back(Command{c.id, c.type, start, c.target, c.values});
  }
  return EncodeRequest(r);
}

std::vector<std::uint8_t> ReplyPackage(std::int64_t client, std::int64_t ack, std::int64_t receive_us,
                                       std::vector<Reply> replies) {
  return EncodeReplyBatch({.client_id = client,
                           .ack_sequence = ack,
                           .server_receive = AtMicros(receive_us),
                           .server_send = AtMicros(receive_us),
                           .replies = std::move(replies)});
}

const std::string kRequest = RequestChannel("pioneer");
const std::string kReply = ReplyChannel("pioneer", kClient);

TEST(SessionLog, KeepsOneCopyOfARetransmittedPackage) {
  SessionLog log;
  const auto p = Package(kClient, 1, 100, kDelay, {{1, CommandType::kGoto, 5'000'000, "", {1, 0, 0}}});
  log.Add(kRequest, 10, p);
  log.Add(kRequest, 20, p);
  log.Add(kRequest, 30, p);
  ASSERT_EQ(log.commands().size(), 1u);
  EXPECT_EQ(log.clients().at(kClient).retransmissions, 2u);
  EXPECT_EQ(log.clients().at(kClient).packages, 1u);
  EXPECT_EQ(log.channels().at(kRequest).messages, 3u);
}

TEST(SessionLog, RecoversDelayModeOffsetsFromStartTimes) {
  SessionLog log;
  log.Add(kRequest, 10,
          Package(kClient, 1, 100, kDelay,
                  {{1, CommandType::kSetSpeed, 9'000'000, "", {0.3, 0}},
                   {2, CommandType::kStop, 12'500'000, "", {}},
                   {3, CommandType::kJointSetPoint, 10'000'000, "pan", {0.4}}}));
  const Timeline t = log.MakeTimeline({.robot = "pioneer"});
  EXPECT_EQ(t.clock, "server");  // absolute start times are server-clock times already
  ASSERT_EQ(t.frames.size(), 3u);
  EXPECT_DOUBLE_EQ(t.frames[0].offset_s, 0.0);
  EXPECT_DOUBLE_EQ(t.frames[1].offset_s, 1.0);
  EXPECT_EQ(t.frames[1].source->command.target, "pan");
  EXPECT_DOUBLE_EQ(t.frames[2].offset_s, 3.5);
}

TEST(SessionLog, PlacesDirectCommandsBySendTimePlusTheAckedClockOffset) {
  SessionLog log;
  // Client clock 1 s behind the server: acks say receive = send + 1 s (+ latency).
  log.Add(kRequest, 10,
          Package(kClient, 1, 1'000'000, kDirect, {{1, CommandType::kSetSpeed, 0, "", {0.1, 0}}}));
  log.Add(kReply, 11, ReplyPackage(kClient, 1, 2'000'300, {}));
  log.Add(kRequest, 12, Package(kClient, 2, 1'700'000, kDirect, {{2, CommandType::kStop, 0, "", {}}}));
  log.Add(kReply, 13, ReplyPackage(kClient, 2, 2'700'100, {}));
  EXPECT_EQ(log.clients().at(kClient).clock_offset_us, 1'000'100);
  const Timeline t = log.MakeTimeline({.client_id = kClient});
  EXPECT_EQ(t.clock, "server");
  ASSERT_EQ(t.frames.size(), 2u);
  EXPECT_NEAR(t.frames[1].offset_s, 0.7, 1e-9);
}

TEST(SessionLog, PlacesPlaybackFramesAtTheServersChosenStart) {
  SessionLog log;
  log.Add(kRequest, 10,
          Package(kClient, 1, 0, kPlayback,
                  {{2, CommandType::kSetSpeed, 0, "", {0.2, 0}}, {3, CommandType::kStop, 2'000'000, "", {}}},
                  /*playback_id=*/1));
  Reply delay{.id = 1, .values = {0.25, 50'000'000.0}};
  log.Add(kReply, 11, ReplyPackage(kClient, 1, 49'750'000, {delay}));
  EXPECT_EQ(log.clients().at(kClient).playback_start_us.at(1), 50'000'000);
  const Timeline t = log.MakeTimeline({.client_id = kClient});
  EXPECT_EQ(t.clock, "server");
  EXPECT_EQ(t.frames[1].time_us, 52'000'000);
  EXPECT_DOUBLE_EQ(t.frames[1].offset_s, 2.0);
}

TEST(SessionLog, RefusesToMixClientsWhoseClocksCannotBeJoined) {
  SessionLog log;
  log.Add(kRequest, 10, Package(kClient, 1, 5, kDirect, {{1, CommandType::kSetSpeed, 0, "", {0.1, 0}}}));
  log.Add(kRequest, 11, Package(kClient + 1, 1, 7, kDirect, {{1, CommandType::kStop, 0, "", {}}}));
  EXPECT_THROW(log.MakeTimeline({.robot = "pioneer"}), LogError);
  EXPECT_EQ(log.MakeTimeline({.client_id = kClient}).clock, "client send times");
}

TEST(SessionLog, NeverReplaysAPanicOrAPanicReset) {
  SessionLog log;
  log.Add(kRequest, 10, Package(kClient, 1, 5, kDelay, {{1, CommandType::kGoto, 100, "", {1, 0, 0}}}));
  // A panic package (review9: the test checked only the reset, not the panic its name promises).
  Request panic{.client_id = kClient, .sequence = 2, .send_time = AtMicros(6), .mode = kDirect};
  panic.panic = true;
  log.Add(kRequest, 11, EncodeRequest(panic));
  log.Add(kRequest, 12, Package(kClient, 3, 7, kDelay, {{2, CommandType::kPanicReset, 200, "", {}}}));
  EXPECT_EQ(log.clients().at(kClient).panics, 1u);
  const Timeline t = log.MakeTimeline({.client_id = kClient});
  ASSERT_EQ(t.frames.size(), 1u);
  EXPECT_EQ(t.frames[0].source->command.type, CommandType::kGoto);
  ASSERT_EQ(t.skipped.size(), 2u);
  EXPECT_NE(t.skipped[0].find("a panic from client"), std::string::npos) << t.skipped[0];
  EXPECT_NE(t.skipped[1].find("PANIC_RESET"), std::string::npos) << t.skipped[1];
  const std::vector<TimedCommand> frames = ToFrames(t, {});
  ASSERT_EQ(frames.size(), 1u);  // what replay and extract send
  EXPECT_EQ(frames[0].command.type, CommandType::kGoto);
}

TEST(SessionLog, CountsUndecodableMessagesInsteadOfThrowing) {
  SessionLog log;
  const std::vector<std::uint8_t> junk = {1, 2, 3};
  log.Add(kRequest, 10, junk);
  log.Add("OTHER", 11, junk);
  EXPECT_EQ(log.channels().at(kRequest).undecodable, 1u);
  EXPECT_EQ(log.events(), 2u);
  EXPECT_THROW(log.MakeTimeline({.robot = "pioneer"}), LogError);
}

TEST(SessionLog, KeepsNothingOfAPackageWithAnItemThatDoesNotDecode) {
  SessionLog log;
  log.Add(kRequest, 10,
          Package(kClient, 1, 5, kDelay,
                  {{1, CommandType::kStop, 100, "", {}}, {2, static_cast<CommandType>(99), 200, "", {}}}));
  EXPECT_EQ(log.channels().at(kRequest).undecodable, 1u);
  EXPECT_TRUE(log.commands().empty());
  EXPECT_TRUE(log.clients().empty());
}

// Issue 21: an lcm-logger log of a split-layout session holds the main lane
// only (ANNOUNCE, CONFIG, STATE): replaying it must say why there is nothing
// to replay and how to record one, not only "no command".
TEST(SessionLog, ALogWithoutRequestsOfASplitLayoutServerSaysHowToRecordOne) {
  SessionLog log;
  Announcement a{.server_id = 7, .traffic_layout = TrafficLayout::kSplit};
  a.robots.push_back({.name = "pioneer", .driver = "kinematic", .total_dofs = 4});
  log.Add(kAnnounceChannel, 10, EncodeAnnouncement(a));
  try {
    log.MakeTimeline({.robot = "pioneer"});
    FAIL() << "a log without requests has nothing to replay";
  } catch (const LogError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("no request"), std::string::npos) << what;
    EXPECT_NE(what.find("split traffic layout"), std::string::npos) << what;
    EXPECT_NE(what.find("robotalk-logplay record"), std::string::npos) << what;
  }
  // With requests from the robot in the log, the message stays the plain one.
  log.Add(kRequest, 20, Package(kClient, 1, 100, kDelay, {{1, CommandType::kStop, 0, "", {}}}));
  try {
    log.MakeTimeline({.robot = "other"});
    FAIL() << "no command of robot 'other'";
  } catch (const LogError& e) {
    EXPECT_EQ(std::string(e.what()).find("split traffic layout"), std::string::npos) << e.what();
  }
}

TEST(Frames, RenameWindowAndSpeedApplyInThatOrder) {
  SessionLog log;
  log.Add(kRequest, 10,
          Package(kClient, 1, 0, kDelay,
                  {{1, CommandType::kJointSetPoint, 1'000'000, "pan", {0.1}},
                   {2, CommandType::kJointSetPoint, 3'000'000, "pan", {0.2}},
                   {3, CommandType::kJointSetPoint, 5'000'000, "tilt", {0.3}}}));
  const Timeline t = log.MakeTimeline({.robot = "pioneer"});
  const auto frames =
      ToFrames(t, {.rename = {{"pan", "head_pan"}}, .from_s = 1.0, .to_s = 4.0, .speed = 2.0});
  ASSERT_EQ(frames.size(), 2u);
  EXPECT_EQ(frames[0].command.target, "head_pan");
  EXPECT_DOUBLE_EQ(ToSeconds(frames[0].offset), 0.5);  // (2 s - 1 s) / 2
  EXPECT_DOUBLE_EQ(ToSeconds(frames[1].offset), 1.5);
  EXPECT_THROW(ToFrames(t, {.from_s = 4.5, .to_s = 4.9}), LogError);
}

TEST(Frames, AnExtractedSequenceParsesBackToTheSameCommands) {
  std::vector<TimedCommand> frames = {
      {FromSeconds(0), {0, CommandType::kSetSpeed, std::nullopt, "", {0.3, -0.123456789}}},
      {FromSeconds(1.25), {0, CommandType::kJointSetPoint, std::nullopt, "pan", {0.4}}},
      {FromSeconds(3.4), {0, CommandType::kStop, std::nullopt, "", {}}}};
  const std::string text = FormatSequence(frames, "a header\nof two lines");
  const auto entries = cli::ParseSequence(text, "extracted.txt");
  ASSERT_EQ(entries.size(), 3u);
  EXPECT_DOUBLE_EQ(entries[1].offset_s, 1.25);
  EXPECT_EQ(entries[1].command.target, "pan");
  EXPECT_DOUBLE_EQ(entries[0].command.values[1], -0.123456789);
  EXPECT_EQ(entries[2].command.type, CommandType::kStop);
}

// A frame without an interpolation (nullopt: the sequence's, as Python's
// format_sequence may be given) takes the file's; it is no second one.
TEST(Frames, AFrameWithoutAnInterpolationTakesTheFiles) {
  const std::vector<TimedCommand> frames = {
      {FromSeconds(0), {0, CommandType::kJointSetPoint, std::nullopt, "pan", {0.1}}, Interpolation::kQuintic},
      {FromSeconds(1), {0, CommandType::kJointSetPoint, std::nullopt, "pan", {0.2}}}};
  const SequenceFile file = ParseSequenceFile(FormatSequence(frames, ""), "extracted.txt");
  EXPECT_EQ(file.interpolation, Interpolation::kQuintic);
  EXPECT_EQ(file.entries.size(), 2u);
  EXPECT_FALSE(ParseSequenceFile(FormatSequence({frames[1]}, ""), "extracted.txt").interpolation);
}

TEST(Options, ParseMapsWindowsAndClientIds) {
  EXPECT_EQ(ParseRename("pan=head_pan"), std::make_pair(std::string("pan"), std::string("head_pan")));
  EXPECT_THROW(ParseRename("pan"), cli::UsageError);
  EXPECT_EQ(ParseWindow("2:5"), std::make_pair(2.0, 5.0));
  EXPECT_EQ(ParseWindow(":5").first, 0.0);
  EXPECT_THROW(ParseWindow("5:2"), cli::UsageError);
  EXPECT_EQ(ParseClientId("0000000000001234"), 0x1234);
  EXPECT_EQ(ParseClientId("4660"), 0x1234);
  EXPECT_THROW(ParseClientId("nope"), LogError);
}

// Channels are parsed by robotalk/channels.h (tests/core/channels_test.cpp),
// which knows every RoboTalk channel; logplay's own parser did not know HELLO.
TEST(SessionLog, RecognisesLoggedHellosAndTheirRefusals) {
  SessionLog log;
  log.Add(HelloChannel("pioneer"), 5, EncodeHello({.body = {.client_id = kClient}}));
  log.Add(HelloAnswerChannel("pioneer", kClient), 6,
          EncodeHelloAnswer(
              {.server_id = 9, .session_id = 0, .refusal = "full", .body = {.client_id = kClient}}));
  const std::vector<std::uint8_t> junk = {1, 2, 3};
  log.Add(HelloChannel("pioneer"), 7, junk);
  log.Add(HelloAnswerChannel("pioneer", kClient), 8, junk);
  EXPECT_EQ(log.channels().at(HelloChannel("pioneer")).undecodable, 1u) << "a HELLO channel is RoboTalk's";
  EXPECT_EQ(log.channels().at(HelloAnswerChannel("pioneer", kClient)).undecodable, 1u);
  ASSERT_EQ(log.clients().count(kClient), 1u);
  EXPECT_EQ(log.clients().at(kClient).robot, "pioneer");
  EXPECT_EQ(log.clients().at(kClient).hellos, 1u);
  EXPECT_EQ(log.clients().at(kClient).hellos_refused, 1u);
  std::ostringstream info;
  PrintInfo(log, "x.lcmlog", info);
  EXPECT_NE(info.str().find("hellos 1 (1 refused)"), std::string::npos) << info.str();
}

// A hostile (or corrupt) log: numbers that are not finite or out of range
// are refused entry by entry, with a message naming the event, its channel
// and the field; never undefined behaviour (a NaN cast to an integer), never
// an overflow of `time - t0` that silently drops valid frames from a replay.
// The log is written with LCM's own log API, as lcm-logger would.
class HostileLog : public ::testing::Test {
 protected:
  void Write(const std::string& channel, std::int64_t timestamp, const std::vector<std::uint8_t>& bytes) {
    lcm::LogEvent e{};
    e.eventnum = next_++;
    e.timestamp = timestamp;
    e.channel = channel;
    e.datalen = static_cast<std::int32_t>(bytes.size());
    e.data = const_cast<std::uint8_t*>(bytes.data());
    ASSERT_EQ(file_->writeEvent(&e), 0);
  }
  SessionLog Read() {
    file_.reset();  // closed: flushed
    return ReadLog(path_);
  }
  void Restart() {
    file_ = std::make_unique<lcm::LogFile>(path_, "w");
    next_ = 0;
  }
  static bool Names(const SessionLog& log, const std::vector<std::string>& words) {
    for (const std::string& r : log.rejected()) {
      bool all = true;
      for (const std::string& w : words) all = all && r.find(w) != std::string::npos;
      if (all) return true;
    }
    return false;
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  const std::string dir_ = testing::TempDir() + "/logplay_hostile_" + std::to_string(::getpid());
  const std::string path_ = (std::filesystem::create_directories(dir_), dir_ + "/hostile.lcmlog");
  std::unique_ptr<lcm::LogFile> file_ = std::make_unique<lcm::LogFile>(path_, "w");
  std::int64_t next_ = 0;
};

TEST_F(HostileLog, RefusesAPlaybackStartThatIsNotAFiniteTimeAndKeepsEveryValidFrame) {
  const std::int64_t kOther = kClient + 1;
  const double starts[] = {std::nan(""), std::numeric_limits<double>::infinity(), -1e300, -9.2e18};
  for (std::size_t i = 0; i < std::size(starts); ++i) {
    SCOPED_TRACE(starts[i]);
    Restart();
    // Client A plays back two frames (offsets 0 and 2 s); its PLAYBACK reply's start is hostile.
    Write(kRequest, 10,
          Package(kClient, 1, 0, kPlayback,
                  {{2, CommandType::kSetSpeed, 0, "", {0.2, 0}}, {3, CommandType::kStop, 2'000'000, "", {}}},
                  /*playback_id=*/1));
    Write(kReply, 11, ReplyPackage(kClient, 1, 49'750'000, {Reply{.id = 1, .values = {0.25, starts[i]}}}));
    // Client B sends two delay-mode commands at real server-clock times.
    Write(kRequest, 12,
          Package(kOther, 1, 5, kDelay,
                  {{1, CommandType::kSetSpeed, 1'700'000'000'000'000, "", {0.1, 0}},
                   {2, CommandType::kStop, 1'700'000'001'000'000, "", {}}}));
    const SessionLog log = Read();
    EXPECT_TRUE(Names(log, {"event 1", kReply, "values[1]", "playback 1"}))
        << (log.rejected().empty() ? "nothing rejected" : log.rejected()[0]);
    EXPECT_EQ(log.channels().at(kReply).undecodable, 1u);
    EXPECT_TRUE(log.clients().at(kClient).playback_start_us.empty());
    // A's frames keep their own clock (the playback offsets), both of them.
    const Timeline a = log.MakeTimeline({.client_id = kClient});
    EXPECT_EQ(a.clock, "playback offsets");
    ASSERT_EQ(a.frames.size(), 2u);
    EXPECT_DOUBLE_EQ(a.frames[1].offset_s, 2.0);
    // Both clients together cannot be put on one clock: said, not B's frames dropped.
    EXPECT_THROW(log.MakeTimeline({.robot = "pioneer"}), LogError);
    const Timeline b = log.MakeTimeline({.client_id = kOther});
    ASSERT_EQ(b.frames.size(), 2u);
    EXPECT_DOUBLE_EQ(b.frames[1].offset_s, 1.0);
  }
}

// Review 12: a log's channel names and the texts of its messages are
// anyone's bytes. `robotalk-logplay info` printed them raw (a channel
// "ROBOTALK/a<ESC>]0;...<BEL>/HELLO" put its escape sequence on the
// terminal, in the channel list and as the client's robot), and Python's
// log_info raised UnicodeDecodeError for a whole log holding one channel
// name that is not UTF-8. Now every byte outside printable ASCII is shown
// as \xNN; the events still count.
TEST_F(HostileLog, ChannelNamesAndStateTextsAreShownInPrintableAscii) {
  const std::vector<std::uint8_t> hello = EncodeHello({.body = {.client_id = kClient}});
  Write("ROBOTALK/a\x1b]0;owned\x07/HELLO", 10, hello);
  Write("ROBOTALK/j\xe9/HELLO", 11, hello);
  robotalk::StateSample state;
  state.robot = "st\x1b[2Jate\xff";
  state.server_time = TimePoint(std::chrono::seconds(1));
  Write(StateChannel("pioneer"), 12, EncodeStateSample(state));
  const SessionLog log = Read();
  std::ostringstream out;
  PrintInfo(log, path_, out);
  const std::string info = out.str();
  std::size_t bad = 0;
  for (const char c : info) {
    const auto u = static_cast<unsigned char>(c);
    bad += (u < 0x20 && c != '\n') || u >= 0x7f;
  }
  EXPECT_EQ(bad, 0u) << "bytes outside printable ASCII in the info text";
  EXPECT_NE(info.find("a\\x1b]0;owned\\x07"), std::string::npos) << info;
  EXPECT_NE(info.find("j\\xe9"), std::string::npos) << info;
  // A STATE naming a robot no server can serve is refused by its decoder
  // (gaps13), counted and said without its name; the bytes never print.
  EXPECT_EQ(log.channels().at(StateChannel("pioneer")).undecodable, 1u);
  EXPECT_NE(info.find("robot: a robot name is"), std::string::npos) << info;
  EXPECT_EQ(info.find("2Jate"), std::string::npos) << info;
  EXPECT_EQ(log.events(), 3u);
}

TEST_F(HostileLog, RefusesLogTimestampsOutOfRangeAndNamesThem) {
  const auto p = Package(kClient, 1, 100, kDelay, {{1, CommandType::kGoto, 5'000'000, "", {1, 0, 0}}});
  Write(kRequest, std::numeric_limits<std::int64_t>::min(), p);
  Write("OTHER", std::numeric_limits<std::int64_t>::max(), {1, 2, 3});
  Write(kRequest, 1'700'000'000'000'000,
        Package(kClient, 2, 200, kDelay, {{2, CommandType::kStop, 6'000'000, "", {}}}));
  const SessionLog log = Read();
  EXPECT_TRUE(Names(log, {"event 0", kRequest, "log timestamp"}));
  EXPECT_TRUE(Names(log, {"event 1", "OTHER", "log timestamp"}));
  EXPECT_EQ(log.first_us(), 1'700'000'000'000'000);
  EXPECT_EQ(log.last_us(), 1'700'000'000'000'000);
  EXPECT_EQ(log.events(), 3u);
  ASSERT_EQ(log.commands().size(), 1u);
  std::ostringstream info;
  PrintInfo(log, "hostile.lcmlog", info);
  EXPECT_NE(info.str().find("2 log entries rejected"), std::string::npos) << info.str();
  EXPECT_NE(info.str().find("log timestamp"), std::string::npos) << info.str();
}

// Review 13: `robotalk-logplay export --mcap` named a log's channels and
// robots in its warnings raw (an undecodable message's channel, a STATE's
// robot with no logged configuration): a hostile log's terminal escapes and
// line breaks reached the terminal, as `info`'s did before review 12. Every
// warning line is now written in printable ASCII, one line each.
TEST_F(HostileLog, ExportMcapsWarningsShowChannelsAndRobotsInPrintableAscii) {
  robotalk::StateSample s;
  s.robot = "a";
  s.server_time = TimePoint(std::chrono::seconds(1));
  s.sample = 1;
  Write("ROBOTALK/a\x1b]0;owned\x07/STATE", 1'700'000'000'000'000, EncodeStateSample(s));
  Write("ROBOTALK/b\x1b[2J\nrobotalk-logplay: forged\xc2\x9b/REQUEST", 1'700'000'000'000'001, {1, 2, 3});
  file_.reset();  // closed: flushed
  std::ostringstream warnings;
  ExportMcap(path_, dir_ + "/hostile.mcap", warnings);
  const std::string w = warnings.str();
  EXPECT_NE(w.find("robot 'a\\x1b]0;owned\\x07'"), std::string::npos) << w;
  EXPECT_NE(w.find("ROBOTALK/b\\x1b[2J\\x0arobotalk-logplay: forged\\xc2\\x9b/REQUEST"), std::string::npos)
      << w;
  for (const char c : w) {
    if (c == '\n') continue;
    EXPECT_TRUE(c >= 0x20 && c < 0x7f) << "a byte outside printable ASCII: " << static_cast<int>(c) << "\n"
                                       << w;
  }
}

// Review 13: a command's target is anyone's bytes in a log. `extract` wrote
// it raw into the sequence file, whose words are split at blanks and cut at
// '#': a target "pan 0.1<LF>0.000000 setspeed 5 0 #" became a SETSPEED line
// of its own, "pan 0.9 #" turned a set-point of 0.1 into one of 0.9, and the
// extract's re-parse check read both files as valid. A frame whose target the
// sequence file cannot carry as one word is refused, named in printable
// ASCII; nothing is written.
TEST_F(HostileLog, ATargetASequenceFileCannotCarryAsOneWordIsRefusedByExtract) {
  for (const std::string target : {"pan 0.1\n0.000000 setspeed 5 0 #", "pan 0.9 #", "pan\t0.9", "pan#"}) {
    SCOPED_TRACE(target);
    Restart();
    Write(kRequest, 1'700'000'000'000'000,
          Package(kClient, 1, 100, kDelay, {{1, CommandType::kJointSetPoint, 5'000'000, "pan", {0.2}}}));
    Write(kRequest, 1'700'000'000'000'001,
          Package(kClient, 2, 200, kDelay, {{2, CommandType::kJointSetPoint, 6'000'000, target, {0.1}}}));
    const std::vector<TimedCommand> frames = ToFrames(Read().MakeTimeline({.client_id = kClient}), {});
    try {
      const std::string text = FormatSequence(frames, "extracted");
      ADD_FAILURE() << "written:\n" << text;
    } catch (const LogError& e) {
      EXPECT_NE(std::string(e.what()).find("frame 2 JOINT_SETPOINT: target '" + Printable(target) + "'"),
                std::string::npos)
          << e.what();
    }
  }
}

// Consolidate 14: `extract` wrote each frame's type, target and values
// (%.10g) and nothing else, so a recorded waypoint lost its velocities and
// accelerations, a value lost its last bits, and a cubic session came back
// as a step one (no `interpolation` line). What it writes, read back with
// the client's own parser (ParseSequenceFile, as `robotalk send --file`),
// is every command as the log holds it.
class ExtractedLog : public HostileLog {
 protected:
  // One delay-mode package of kClient: `commands` start 5 s, 6 s ... after 0.
  void WritePackage(std::int64_t seq, Interpolation interpolation, std::vector<Command> commands) {
    Request r{.client_id = kClient, .sequence = seq, .send_time = AtMicros(100 * seq), .mode = kDelay};
    r.interpolation = interpolation;
    for (Command& c : commands) {
      c.id = seq * 10 + static_cast<std::int64_t>(r.commands.size());
      c.start_time = StartTime::At(AtMicros(5'000'000 + (c.id - 10) * 1'000'000));
      r.commands.push_back(std::move(c));
    }
    Write(kRequest, 1'700'000'000'000'000 + seq, EncodeRequest(r));
  }
};

TEST_F(ExtractedLog, AWaypointsVelocitiesAccelerationsExactValuesAndInterpolationReadBack) {
  const double third = 1.0 / 3;  // not exact in 10 digits
  Command pan{.type = CommandType::kJointSetPoint, .target = "pan", .values = {third}};
  pan.velocities = {0.5};
  pan.accelerations = {-0.25};
  Command tool{.type = CommandType::kFrameSetPoint, .target = "tool", .values = {0.1, 0.2, 0.3, 1, 0, 0, 0}};
  tool.velocities = {0.01, 0.02, 0.03, 0, 0, third};
  WritePackage(1, Interpolation::kCubic, {pan, tool});
  WritePackage(2, Interpolation::kCubic, {Command{.type = CommandType::kGoto, .values = {1, 2, third}}});
  const std::vector<TimedCommand> frames = ToFrames(Read().MakeTimeline({.client_id = kClient}), {});
  ASSERT_EQ(frames.size(), 3u);
  const std::string text = FormatSequence(frames, "extracted");
  const SequenceFile file = ParseSequenceFile(text, "extracted.txt");
  ASSERT_EQ(file.entries.size(), frames.size()) << text;
  EXPECT_EQ(file.interpolation, Interpolation::kCubic) << text;
  for (std::size_t i = 0; i < frames.size(); ++i) {
    SCOPED_TRACE(i);
    const Command& back = file.entries[i].command;
    const Command& logged = frames[i].command;
    EXPECT_EQ(back.type, logged.type);
    EXPECT_EQ(back.target, logged.target);
    EXPECT_EQ(back.values, logged.values) << text;  // to the last bit
    EXPECT_EQ(back.velocities, logged.velocities) << text;
    EXPECT_EQ(back.accelerations, logged.accelerations) << text;
    EXPECT_DOUBLE_EQ(file.entries[i].offset_s, ToSeconds(frames[i].offset));
  }
}

// A sequence file has one interpolation: set-points recorded in packages of
// two are refused (naming both), never written as one of them; replay keeps them.
TEST_F(ExtractedLog, SetPointsOfTwoInterpolationsAreRefusedNamingThem) {
  WritePackage(1, Interpolation::kCubic,
               {Command{.type = CommandType::kJointSetPoint, .target = "pan", .values = {0.1}}});
  WritePackage(2, Interpolation::kLinear,
               {Command{.type = CommandType::kJointSetPoint, .target = "pan", .values = {0.2}}});
  const std::vector<TimedCommand> frames = ToFrames(Read().MakeTimeline({.client_id = kClient}), {});
  try {
    const std::string text = FormatSequence(frames, "extracted");
    ADD_FAILURE() << "written:\n" << text;
  } catch (const LogError& e) {
    EXPECT_NE(std::string(e.what()).find("frame 2 JOINT_SETPOINT: interpolation linear, frame 1's cubic"),
              std::string::npos)
        << e.what();
  }
}

// A step package's GOTO beside cubic set-points: its interpolation means nothing, the file says cubic.
TEST_F(ExtractedLog, TheInterpolationOfACommandThatIsNoSetPointDoesNotCount) {
  WritePackage(1, Interpolation::kStep, {Command{.type = CommandType::kGoto, .values = {1, 0, 0}}});
  WritePackage(2, Interpolation::kCubic,
               {Command{.type = CommandType::kJointSetPoint, .target = "pan", .values = {0.2}}});
  const std::vector<TimedCommand> frames = ToFrames(Read().MakeTimeline({.client_id = kClient}), {});
  EXPECT_EQ(ParseSequenceFile(FormatSequence(frames, "extracted"), "extracted.txt").interpolation,
            Interpolation::kCubic);
}

// A damaged log (review9): LCM's reader allocated what an event header
// declared before reading it; a header declaring 2^31 - 1 data bytes made it
// fread into a failed allocation (a segfault in every reader: robotalk-logplay
// info/replay/export, Python's robotalk.log_info), and a log cut short inside
// its last event (a recorder stopped mid-write) ended without a word. Both are
// said, naming the byte, and every intact event is still read.
class DamagedLog : public HostileLog {
 protected:
  // Three delay-mode packages of one client; returns each event's first byte.
  std::vector<std::uint64_t> WriteThree() {
    std::vector<std::uint64_t> offsets;
    std::uint64_t at = 0;
    for (std::int64_t seq = 1; seq <= 3; ++seq) {
      const auto p = Package(kClient, seq, 100 * seq, kDelay,
                             {{seq, CommandType::kGoto, 5'000'000 + seq * 1'000'000, "", {0.1 * seq, 0, 0}}});
      offsets.push_back(at);
      at += 28 + kRequest.size() + p.size();
      Write(kRequest, 1'700'000'000'000'000 + seq, p);
    }
    file_.reset();  // closed: flushed
    return offsets;
  }
  void Overwrite(std::uint64_t at, const std::vector<std::uint8_t>& bytes) {
    std::FILE* f = std::fopen(path_.c_str(), "r+b");
    ASSERT_NE(f, nullptr);
    ASSERT_EQ(std::fseek(f, static_cast<long>(at), SEEK_SET), 0);
    ASSERT_EQ(std::fwrite(bytes.data(), 1, bytes.size(), f), bytes.size());
    std::fclose(f);
  }
  static std::string All(const SessionLog& log) {
    std::string s;
    for (const std::string& r : log.rejected()) s += r + "\n";
    return s.empty() ? "nothing rejected" : s;
  }
};

TEST_F(DamagedLog, AnEventDeclaringMoreBytesThanTheLogHoldsIsNamedAndTheEventsAfterItAreRead) {
  const auto offsets = WriteThree();
  Overwrite(offsets[1] + 24, {0x7F, 0xFF, 0xFF, 0xFF});  // event 1's data length: 2^31 - 1
  const SessionLog log = ReadLog(path_);
  EXPECT_EQ(log.events(), 2u);
  ASSERT_EQ(log.commands().size(), 2u);
  EXPECT_EQ(log.commands()[1].sequence, 3);  // the event after the damage is read
  EXPECT_TRUE(Names(log, {"byte " + std::to_string(offsets[1]), "2147483647 data bytes"})) << All(log);
  EXPECT_TRUE(Names(log, {"skipped", "at byte " + std::to_string(offsets[2])})) << All(log);
  std::ostringstream info;
  PrintInfo(log, "damaged.lcmlog", info);
  EXPECT_NE(info.str().find("1 log entry rejected"), std::string::npos) << info.str();
}

TEST_F(DamagedLog, ALogCutShortInsideItsLastEventSaysSoAndKeepsTheEventsBefore) {
  WriteThree();
  std::filesystem::resize_file(path_, std::filesystem::file_size(path_) - 10);
  const SessionLog log = ReadLog(path_);
  EXPECT_EQ(log.events(), 2u);
  EXPECT_EQ(log.commands().size(), 2u);
  EXPECT_TRUE(Names(log, {"event 2", "cut short"})) << All(log);
}

TEST_F(DamagedLog, AStretchOfGarbageIsSkippedToTheNextEvent) {
  const auto offsets = WriteThree();
  Overwrite(offsets[1], {'g', 'a', 'r', 'b', 'a', 'g', 'e'});  // event 1's sync word and more
  const SessionLog log = ReadLog(path_);
  EXPECT_EQ(log.events(), 2u);
  EXPECT_TRUE(Names(log, {"byte " + std::to_string(offsets[1]), "no event starts here", "skipped"}))
      << All(log);
}

// Issue 19: the recorder dispatches the 66 lanes one after the other, so a
// reply (received later) could be written before its request.
TEST(ReceiptOrder, WritesEventsByReceiveTimeNotByDispatchOrder) {
  ReceiptOrder order(/*hold_us=*/1000);
  const std::vector<std::uint8_t> none;
  // Dispatched: the reply lane first, then the request lane.
  order.Add(2050, "ROBOTALK/pioneer/REPLY/00", none);
  order.Add(2000, "ROBOTALK/pioneer/REQUEST", none);
  order.Add(2050, "ROBOTALK/pioneer/STATE", none);  // same time: dispatch order kept
  std::vector<std::string> written;
  const auto write = [&](const ReceiptOrder::Event& e) { written.push_back(e.channel); };
  order.Release(3000, write);
  EXPECT_EQ(written, std::vector<std::string>{"ROBOTALK/pioneer/REQUEST"}) << "held until `hold` has passed";
  order.Release(3050, write);
  EXPECT_EQ(written, (std::vector<std::string>{"ROBOTALK/pioneer/REQUEST", "ROBOTALK/pioneer/REPLY/00",
                                               "ROBOTALK/pioneer/STATE"}));
  EXPECT_EQ(order.late(), 0u);
  // Dispatched later than `hold`: written at once, and counted.
  order.Add(1500, "LATE", none);
  order.ReleaseAll(write);
  EXPECT_EQ(written.back(), "LATE");
  EXPECT_EQ(order.late(), 1u);
}

TEST(ReceiptOrder, HoldsAtMostItsBoundWritingTheOldestFirst) {
  ReceiptOrder order(/*hold_us=*/1000000, /*max_held=*/2);
  std::vector<std::int64_t> written;
  const auto write = [&](const ReceiptOrder::Event& e) { written.push_back(e.received_us); };
  for (std::int64_t t : {30, 10, 20}) order.Add(t, "C", std::vector<std::uint8_t>{});
  order.Release(0, write);
  EXPECT_EQ(written, std::vector<std::int64_t>{10});
  EXPECT_EQ(order.held(), 2u);
}

// gaps13 (safety.md's Known gaps): the recorder's sort held up to 100,000
// events whatever their size, so well-formed large messages (1 MiB each here)
// arriving within the 0.25 s sort grew its memory by their bytes. Now it
// holds 64 MiB at most by default: past that the oldest are written at once
// (nothing dropped) and counted, so `record` can say which.
TEST(ReceiptOrder, HoldsAtMostItsByteBoundWritingTheOldestFirstAndCountsThem) {
  ReceiptOrder order;  // the recorder's defaults
  std::vector<std::int64_t> written;
  const auto write = [&](const ReceiptOrder::Event& e) { written.push_back(e.received_us); };
  const std::vector<std::uint8_t> mib(1 << 20, 0x5a);
  for (std::int64_t t = 0; t < 80; ++t) order.Add(1000 + t, "ROBOTALK/bot/CONFIG", mib);
  order.Release(1000, write);  // none of them is due yet
  EXPECT_LE(order.held(), 64u) << "more than 64 MiB held";
  ASSERT_EQ(written.size(), 80u - order.held());
  for (std::size_t i = 0; i < written.size(); ++i) EXPECT_EQ(written[i], 1000 + static_cast<std::int64_t>(i));
  EXPECT_EQ(order.held_bytes(), order.held() * mib.size());
  EXPECT_EQ(order.early(), written.size()) << "each written before its hold was over, counted";
  EXPECT_EQ(order.early_bytes(), written.size() * mib.size());
  order.ReleaseAll(write);
  EXPECT_EQ(written.size(), 80u) << "none dropped";
  EXPECT_EQ(order.held_bytes(), 0u);
}

// The wall clock stepped back (an NTP step, a date set by hand) while
// recording: what came before the step is written at once and first, not
// held until the clock catches up (an hour here: a recorder killed meanwhile
// lost it, against logplay.md's 1.25 s, and it was written after the events
// that came after it), and nothing after the step counts as late.
TEST(ReceiptOrder, AWallClockSteppedBackWritesWhatCameBeforeTheStepAtOnceAndFirst) {
  ReceiptOrder order(/*hold_us=*/1000);
  const std::vector<std::uint8_t> none;
  std::vector<std::string> written;
  const auto write = [&](const ReceiptOrder::Event& e) { written.push_back(e.channel); };
  const std::int64_t t0 = 1'800'000'000'000'000, hour = 3'600'000'000;
  order.Add(t0, "BEFORE", none);
  order.Release(t0 + 500, write);
  EXPECT_TRUE(written.empty()) << "held for `hold`";
  order.Add(t0 - hour + 600, "AFTER", none);  // the clock stepped back an hour
  order.Release(t0 - hour + 700, write);
  EXPECT_EQ(written, std::vector<std::string>{"BEFORE"}) << "held until the clock caught up";
  order.Release(t0 - hour + 1700, write);
  EXPECT_EQ(written, (std::vector<std::string>{"BEFORE", "AFTER"}));
  order.Add(t0 - hour + 2000, "LATER", none);
  order.ReleaseAll(write);
  EXPECT_EQ(order.late(), 0u) << "events after the step counted as dispatched late";
}

}  // namespace
}  // namespace robotalk::logplay
