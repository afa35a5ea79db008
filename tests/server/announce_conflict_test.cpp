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

#include <gmock/gmock.h>
#include <gtest/gtest.h>

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
class AnnounceConflictTest : public ::testing::Test {
 protected:
  AnnounceConflictTest() : server_transport_(bus_), lan_(bus_) {
    for (const char* name : {"bot", "arm"}) {
      auto driver = std::make_unique<FakeDriver>(PanRobot());
      fakes_[name] = driver.get();
      robots_.push_back(std::make_unique<RobotDaemon>(name, "fake", std::move(driver), clock_));
    }
    server_ = std::make_unique<ServerDaemon>(server_transport_, clock_, ServerDaemonOptions{.server_id = 42});
    for (auto& r : robots_) server_->AddRobot(*r, SessionOptions{});
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

  void Step() {
    server_->RunOnce(Duration(0));
    for (auto& r : robots_) r->RunOnce(clock_.Now());
    server_->RunOnce(Duration(0));
    lan_.HandleFor(Duration(0));
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

  ManualClock clock_;
  std::shared_ptr<MemoryBus> bus_ = std::make_shared<MemoryBus>();
  MemoryTransport server_transport_;
  MemoryTransport lan_;  // anyone on the LAN
  std::map<std::string, FakeDriver*> fakes_;
  std::vector<std::unique_ptr<RobotDaemon>> robots_;
  std::unique_ptr<ServerDaemon> server_;
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
