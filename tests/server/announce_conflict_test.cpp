// Issue 19 item 3: one robot, one server, decided by the server that starts
// later during its start-up window; an ANNOUNCE never makes a serving server
// give up a robot it serves (a forged one disabled a robot until restart).
#include "server_daemon.h"

#include "fake_driver.h"
#include "robotalk/channels.h"
#include "robotalk/memory_transport.h"
#include "robotalk/request.h"
#include "session_test_util.h"
#include "support/test_clients.h"
#include "two_robot_server.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <functional>
#include <sstream>

namespace robotalk {
namespace {

using testing::FakeDriver;
using ::testing::HasSubstr;
using testing::PanRobot;
using testing::SayHello;

using testing::kAlice;

std::vector<std::uint8_t> ForgedAnnounce(std::int64_t server_id, const std::string& robot) {
  Announcement a;
  a.server_id = server_id;
  a.server_time = TimePoint(std::chrono::hours(1000));
  a.uptime = std::chrono::hours(24 * 365);  // "I have served it for a year"
  a.url_hint = "udpm://10.6.6.6:7667";
  a.robots.push_back({robot, "fake", 1, 1, BaseType::kFixed, false, 0});
  return EncodeAnnouncement(a);
}

// One ServerDaemon serving "bot" (and "arm") on the in-memory bus.
class AnnounceConflictTest : public testing::TwoRobotServerTest {
 protected:
  AnnounceConflictTest() {
    announce_sub_ =
        lan_.Subscribe(kAnnounceChannel, [this](const std::string&, std::span<const std::uint8_t> b) {
          const Announcement a = DecodeAnnouncement(b);
          if (a.server_id != 42) return;
          announced_.clear();
          for (const auto& r : a.robots) announced_.push_back(r.name);
        });
    reply_sub_ =
        lan_.Subscribe("ROBOTALK/bot/REPLY/.*", [this](const std::string&, std::span<const std::uint8_t> b) {
          for (Reply& r : DecodeReplyBatch(b).replies) replies_[r.id] = r;
        });
  }

  // Moves "bot"'s pan joint as a fresh client; true when it ran.
  bool BotStillServes(std::int64_t client_id) {
    const std::int64_t session = SayHello(lan_, "bot", client_id, [this] { Step(); }).session_id;
    if (session == 0) return false;
    Request move{.client_id = client_id, .session_id = session, .sequence = 1};
    move.commands.push_back(Command{client_id, CommandType::kJointSetPoint, std::nullopt, "pan", {0.25}});
    lan_.Publish(RequestChannel("bot"), EncodeRequest(move));
    Step();
    Step();
    auto it = replies_.find(client_id);
    return it != replies_.end() && it->second.signal == Signal::kSuccess;
  }

  MemoryTransport& lan_ = client_;  // anyone on the LAN
  std::unique_ptr<Subscription> announce_sub_;
  std::unique_ptr<Subscription> reply_sub_;
  std::vector<std::string> announced_;
  std::map<CommandId, Reply> replies_;
};

TEST_F(AnnounceConflictTest, AForgedAnnounceLeavesAServingServerServingAndAnnouncingItsRobot) {
  Step();                                    // starts serving
  clock_.Advance(std::chrono::seconds(10));  // well past its start-up window
  Step();
  ASSERT_TRUE(BotStillServes(1));
  ::testing::internal::CaptureStderr();
  for (int i = 0; i < 100; ++i) lan_.Publish(kAnnounceChannel, ForgedAnnounce(1 + i, "bot"));
  Step();  // RunOnce writes its log at the end
  const std::string log = ::testing::internal::GetCapturedStderr();
  EXPECT_EQ(server_->refused("bot"), "");
  EXPECT_EQ(server_->serving(), 2u);
  clock_.Advance(std::chrono::seconds(2));
  Step();
  EXPECT_THAT(announced_, ::testing::Contains("bot")) << "still announced";
  EXPECT_TRUE(BotStillServes(2)) << "still executes commands";
  // Logged, once for the burst (rate-limited), naming the claimant and that nothing changed.
  EXPECT_THAT(log, HasSubstr("robot 'bot': server 0000000000000001"));
  EXPECT_THAT(log, HasSubstr("keeps serving it"));
  EXPECT_EQ(std::count(log.begin(), log.end(), '\n'), 1) << log;
}

TEST_F(AnnounceConflictTest, AConflictDuringTheStartUpWindowRefusesTheRobotAndTheOthersStayServed) {
  Step();                                                    // starts; its window is open
  lan_.Publish(kAnnounceChannel, ForgedAnnounce(7, "bot"));  // an older server of "bot"
  Step();
  EXPECT_THAT(server_->refused("bot"), HasSubstr("is served by server 0000000000000007"));
  EXPECT_EQ(server_->refused("arm"), "");
  EXPECT_EQ(server_->serving(), 1u) << "still serves 'arm'";
  EXPECT_THAT(server_->refusals(), ::testing::ElementsAre(HasSubstr("robot 'bot' is served by")));
}

// server.md: a robot given up in the start-up window is stopped if it
// moved (a client of this server may have moved it in those 2 s); one at
// rest gets no STOP.
TEST_F(AnnounceConflictTest, ARobotGivenUpInTheStartUpWindowIsStoppedIfItMovedAndOnlyThen) {
  Step();  // starts; its window is open
  ASSERT_TRUE(BotStillServes(1));
  ASSERT_TRUE(fakes_["bot"]->moving);
  const std::size_t bot_calls = fakes_["bot"]->calls.size();
  lan_.Publish(kAnnounceChannel, ForgedAnnounce(7, "bot"));
  lan_.Publish(kAnnounceChannel, ForgedAnnounce(8, "arm"));
  Step();
  ASSERT_THAT(server_->refused("bot"), HasSubstr("is served by server 0000000000000007"));
  ASSERT_THAT(server_->refused("arm"), HasSubstr("is served by server 0000000000000008"));
  ASSERT_EQ(fakes_["bot"]->calls.size(), bot_calls + 1);
  EXPECT_EQ(fakes_["bot"]->calls.back().type, CommandType::kStop) << "the robot it moved is stopped";
  EXPECT_FALSE(fakes_["bot"]->moving);
  EXPECT_TRUE(fakes_["arm"]->calls.empty()) << "a robot at rest gets no STOP";
}

// A conflict after the start-up window is logged at most once per robot per
// 10 s, the ANNOUNCEs between counted in the next line (the burst above is
// one line; this is the period).
TEST_F(AnnounceConflictTest, AConflictIsLoggedAtMostOncePerRobotPerTenSeconds) {
  Step();
  clock_.Advance(std::chrono::seconds(10));  // past the start-up window
  Step();
  const auto lines = [this](const std::function<void()>& burst, const std::string& robot) {
    ::testing::internal::CaptureStderr();
    burst();
    Step();
    std::istringstream log(::testing::internal::GetCapturedStderr());
    std::vector<std::string> found;
    for (std::string line; std::getline(log, line);) {
      if (line.find("robot '" + robot + "': ") != std::string::npos &&
          line.find("also announces it") != std::string::npos)
        found.push_back(line);
    }
    return found;
  };
  const auto forge = [this](const std::string& robot, int n) {
    return [this, robot, n] {
      for (int i = 0; i < n; ++i) lan_.Publish(kAnnounceChannel, ForgedAnnounce(100 + i, robot));
    };
  };
  EXPECT_EQ(lines(forge("bot", 1), "bot").size(), 1u) << "the first is logged";
  clock_.Advance(std::chrono::seconds(5));
  EXPECT_TRUE(lines(forge("bot", 50), "bot").empty()) << "5 s later: counted, not logged";
  EXPECT_EQ(lines(forge("arm", 1), "arm").size(), 1u) << "another robot's conflict has its own period";
  clock_.Advance(std::chrono::milliseconds(4990));
  EXPECT_TRUE(lines(forge("bot", 1), "bot").empty()) << "9.99 s after the first line";
  clock_.Advance(std::chrono::milliseconds(10));
  const auto line = lines(forge("bot", 1), "bot");
  ASSERT_EQ(line.size(), 1u) << "10 s after the first line, the next";
  EXPECT_THAT(line.front(), HasSubstr("; 51 more such ANNOUNCEs since the last line"));
  EXPECT_EQ(server_->refused("bot"), "");
}

TEST_F(AnnounceConflictTest, AServerThatRefusesEveryRobotServesNothingAndSaysSo) {
  Step();
  lan_.Publish(kAnnounceChannel, ForgedAnnounce(7, "bot"));
  lan_.Publish(kAnnounceChannel, ForgedAnnounce(8, "arm"));
  Step();
  EXPECT_EQ(server_->serving(), 0u);
  EXPECT_EQ(server_->refusals().size(), 2u);
}

}  // namespace
}  // namespace robotalk
