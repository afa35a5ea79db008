// AnnounceListener and HearAnnouncement (robotalk/announce_listener.h): which
// ANNOUNCE datagrams reach the programs that follow every robot announced.
#include "robotalk/announce_listener.h"

#include "robotalk/broadcast_signature.h"
#include "robotalk/channels.h"
#include "robotalk/heard_announcement.h"
#include "robotalk/memory_transport.h"
#include "robotalk/request.h"

#include <gtest/gtest.h>

#include <chrono>
#include <mutex>
#include <set>
#include <string>
#include <thread>

#include "support/test_keys.h"

namespace robotalk {
namespace {

using testing::TestKey;

std::vector<std::uint8_t> AnnouncementOf(const std::string& robot) {
  Announcement a;
  a.server_id = 7;
  a.server_time = TimePoint(std::chrono::seconds(1));
  a.uptime = std::chrono::seconds(10);
  a.robots.push_back({.name = robot, .driver = "kinematic"});
  return EncodeAnnouncement(a);
}

std::vector<std::uint8_t> SignedBy(const KeyPair& key, const std::string& robot) {
  std::vector<std::uint8_t> bytes = AnnouncementOf(robot);
  BroadcastSigner(key, Nonce{}).Sign(kAnnounceChannel, bytes);
  return bytes;
}

// The datagrams a hostile bus carries beside a keyed server's own: unsigned,
// signed by another key, a signature that does not verify, and garbage.
struct Bus {
  KeyPair server = TestKey(1), forger = TestKey(2);
  std::vector<std::uint8_t> trusted = SignedBy(server, "real");
  std::vector<std::uint8_t> unsigned_one = AnnouncementOf("unsigned");
  std::vector<std::uint8_t> other_key = SignedBy(forger, "other-key");
  std::vector<std::uint8_t> forged = [this] {
    std::vector<std::uint8_t> b = SignedBy(server, "forged");
    b[b.size() - 1] ^= 1;  // the signature no longer verifies
    return b;
  }();
  std::vector<std::uint8_t> garbage = {1, 2, 3};
};

std::string NameOf(const std::optional<HeardAnnouncement>& h) {
  return h ? h->announcement.robots.at(0).name : "(dropped)";
}

TEST(HearAnnouncement, WithATrustedKeyOnlyWhatThatKeySignedIsHeard) {
  const Bus bus;
  const PublicKey& only = bus.server.public_key;
  EXPECT_EQ(NameOf(HearAnnouncement(bus.trusted, &only)), "real");
  EXPECT_EQ(HearAnnouncement(bus.trusted, &only)->server_key, only.ToString());
  EXPECT_EQ(NameOf(HearAnnouncement(bus.unsigned_one, &only)), "(dropped)");
  EXPECT_EQ(NameOf(HearAnnouncement(bus.other_key, &only)), "(dropped)");
  EXPECT_EQ(NameOf(HearAnnouncement(bus.forged, &only)), "(dropped)");
  EXPECT_EQ(NameOf(HearAnnouncement(bus.garbage, &only)), "(dropped)");
}

TEST(HearAnnouncement, WithoutAKeyEverythingThatDecodesAndIsNotForgedIsHeardWithItsSigner) {
  const Bus bus;
  EXPECT_EQ(NameOf(HearAnnouncement(bus.trusted)), "real");
  EXPECT_EQ(HearAnnouncement(bus.trusted)->server_key, bus.server.public_key.ToString());
  EXPECT_EQ(NameOf(HearAnnouncement(bus.unsigned_one)), "unsigned");
  EXPECT_EQ(HearAnnouncement(bus.unsigned_one)->server_key, "");
  EXPECT_EQ(NameOf(HearAnnouncement(bus.other_key)), "other-key");
  EXPECT_EQ(NameOf(HearAnnouncement(bus.forged)), "(dropped)");
  EXPECT_EQ(NameOf(HearAnnouncement(bus.garbage)), "(dropped)");
}

// The one freshness rule (`robotalk watch`, a keyed client's panic): a
// signed announcement shows its server alive at its signed time, never later
// than now; one more than kAnnounceHeardWithin old on arrival, or stamped
// more than that ahead, shows nothing.
TEST(FreshAnnouncementTime, AnAnnouncementShowsItsServerAliveAtItsTimeUntilItIsTooOld) {
  const TimePoint now = TimePoint{} + std::chrono::hours(1);
  EXPECT_EQ(FreshAnnouncementTime(now, now - std::chrono::milliseconds(200)),
            now - std::chrono::milliseconds(200));
  EXPECT_EQ(FreshAnnouncementTime(now, now - kAnnounceHeardWithin), now - kAnnounceHeardWithin);
  EXPECT_EQ(FreshAnnouncementTime(now, now - kAnnounceHeardWithin - std::chrono::microseconds(1)),
            std::nullopt);
  EXPECT_EQ(FreshAnnouncementTime(now, now - std::chrono::minutes(5)), std::nullopt)
      << "a recording replayed";
  EXPECT_EQ(FreshAnnouncementTime(now, now + std::chrono::milliseconds(200)), now) << "never later than now";
  EXPECT_EQ(FreshAnnouncementTime(now, now + kAnnounceHeardWithin), now) << "the clock sync's slack";
  // Stamped further ahead than an announcement lives: signed by an instance
  // whose clock ran ahead of this one's (its host's before a reboot), never
  // by the server the reader is synchronised with; replayed, it would show
  // that server alive for as long as the stamp is ahead (`robotalk watch`
  // would never say the server is gone; final14b: a keyed panic refused).
  EXPECT_EQ(FreshAnnouncementTime(now, now + kAnnounceHeardWithin + std::chrono::microseconds(1)),
            std::nullopt);
  EXPECT_EQ(FreshAnnouncementTime(now, now + std::chrono::minutes(5)), std::nullopt);
}

TEST(AnnounceListener, HearsOnItsOwnThreadWhatItsKeySignedAndCountsTheRest) {
  const Bus bus;
  auto memory = std::make_shared<MemoryBus>();
  MemoryTransport sender(memory);
  std::mutex mu;
  std::set<std::string> heard;
  AnnounceListener listener(std::make_unique<MemoryTransport>(memory), bus.server.public_key,
                            [&](const HeardAnnouncement& h) {
                              std::lock_guard lock(mu);
                              heard.insert(h.announcement.robots.at(0).name);
                            });
  for (const auto* bytes : {&bus.unsigned_one, &bus.other_key, &bus.forged, &bus.garbage, &bus.trusted})
    sender.Publish(kAnnounceChannel, *bytes);
  auto done = [&] {
    std::lock_guard lock(mu);
    return listener.dropped() >= 4 && !heard.empty();
  };
  for (int i = 0; i < 500 && !done(); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(10));
  std::this_thread::sleep_for(std::chrono::milliseconds(10));
  std::lock_guard lock(mu);
  EXPECT_EQ(heard, std::set<std::string>{"real"});
  EXPECT_EQ(listener.dropped(), 4u);
}

}  // namespace
}  // namespace robotalk
