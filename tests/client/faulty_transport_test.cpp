// FaultyTransport (faulty_transport.h) on an in-process bus: every fault it
// offers, seeded losses, held messages on a ManualClock.
#include "client/faulty_transport.h"

#include "robotalk/memory_transport.h"

#include <gtest/gtest.h>

#include <algorithm>

#include <string>
#include <vector>

namespace robotalk::testing {
namespace {

using std::chrono::milliseconds;

std::vector<std::uint8_t> Bytes(const std::string& s) { return {s.begin(), s.end()}; }

class FaultyTransportTest : public ::testing::Test {
 protected:
  // Everything `receiver_` got on channel A or B so far, as "channel:payload".
  std::vector<std::string> Received() {
    while (receiver_.HandleFor(Duration(0)) > 0) {
    }
    return got_;
  }
  void Send(const std::string& channel, const std::string& payload) {
    sender_.Publish(channel, Bytes(payload));
  }

  std::shared_ptr<MemoryBus> bus_ = std::make_shared<MemoryBus>();
  MemoryTransport sender_end_{bus_};
  MemoryTransport receiver_{bus_};
  ManualClock clock_;
  FaultyTransport sender_{sender_end_, {.seed = 3, .clock = &clock_}};
  std::vector<std::string> got_;
  std::unique_ptr<Subscription> sub_ =
      receiver_.Subscribe("A|B", [this](const std::string& channel, std::span<const std::uint8_t> b) {
        got_.push_back(channel + ":" + std::string(b.begin(), b.end()));
      });
};

TEST_F(FaultyTransportTest, PassesEveryMessageOnUnchangedWhenNoFaultMatches) {
  const auto id = sender_.Add({.channel_regex = "B", .mute = true});
  Send("A", "1");
  Send("A", "2");
  EXPECT_EQ(Received(), (std::vector<std::string>{"A:1", "A:2"}));
  EXPECT_EQ(sender_.counts(id).matched, 0u);
}

TEST_F(FaultyTransportTest, MuteDropsEveryMatchingMessageUntilTheFaultIsRemoved) {
  const auto id = sender_.Add({.channel_regex = "A", .mute = true});
  Send("A", "1");
  Send("B", "2");
  EXPECT_EQ(Received(), (std::vector<std::string>{"B:2"}));
  EXPECT_EQ(sender_.counts(id).dropped, 1u);
  sender_.Remove(id);
  Send("A", "3");
  EXPECT_EQ(Received(), (std::vector<std::string>{"B:2", "A:3"}));
  EXPECT_THROW(sender_.counts(id), Error);
}

TEST_F(FaultyTransportTest, DropFirstDropsOnlyTheFirstMatchingMessages) {
  const auto id = sender_.Add({.channel_regex = "A", .drop_first = 2});
  for (const char* p : {"1", "2", "3", "4"}) Send("A", p);
  EXPECT_EQ(Received(), (std::vector<std::string>{"A:3", "A:4"}));
  EXPECT_EQ(sender_.counts(id).matched, 4u);
  EXPECT_EQ(sender_.counts(id).dropped, 2u);
}

TEST_F(FaultyTransportTest, TheWhenPredicateSelectsMessagesByTheirBytes) {
  sender_.Add({.channel_regex = "A",
               .when = [](const std::string&, std::span<const std::uint8_t> b) { return b[0] == 'x'; },
               .mute = true});
  Send("A", "x1");
  Send("A", "y2");
  EXPECT_EQ(Received(), (std::vector<std::string>{"A:y2"}));
}

TEST_F(FaultyTransportTest, SeededLossesRepeatWithTheSameSeedAndComeNearTheProbability) {
  const auto run = [&](std::uint64_t seed) {
    auto bus = std::make_shared<MemoryBus>();
    MemoryTransport end(bus), rx(bus);
    FaultyTransport net(end, {.seed = seed});
    const auto id = net.Add({.channel_regex = "A", .drop_probability = 0.3});
    std::string pattern;
    auto sub = rx.Subscribe("A", [&](const std::string&, std::span<const std::uint8_t> b) {
      pattern += std::string(b.begin(), b.end()) + ",";
    });
    for (int i = 0; i < 1000; ++i) net.Publish("A", Bytes(std::to_string(i)));
    while (rx.HandleFor(Duration(0)) > 0) {
    }
    EXPECT_EQ(
        net.counts(id).dropped + static_cast<std::uint64_t>(std::count(pattern.begin(), pattern.end(), ',')),
        1000u);
    EXPECT_GT(net.counts(id).dropped, 230u);
    EXPECT_LT(net.counts(id).dropped, 370u);
    return pattern;
  };
  EXPECT_EQ(run(7), run(7));
  EXPECT_NE(run(7), run(8));
}

TEST_F(FaultyTransportTest, DuplicateSendsAMessageTwice) {
  const auto id = sender_.Add({.channel_regex = "A", .duplicate_probability = 1.0});
  Send("A", "1");
  Send("B", "2");
  EXPECT_EQ(Received(), (std::vector<std::string>{"A:1", "A:1", "B:2"}));
  EXPECT_EQ(sender_.counts(id).duplicated, 1u);
}

TEST_F(FaultyTransportTest, AReversedBatchIsHeldUntilFullThenSentLastFirst) {
  const auto id = sender_.Add({.channel_regex = "A", .reverse_batch = 3});
  Send("A", "1");
  Send("A", "2");
  Send("B", "x");
  EXPECT_EQ(Received(), (std::vector<std::string>{"B:x"}));
  EXPECT_EQ(sender_.held(), 2u);
  Send("A", "3");
  EXPECT_EQ(Received(), (std::vector<std::string>{"B:x", "A:3", "A:2", "A:1"}));
  Send("A", "4");
  Send("A", "5");
  EXPECT_EQ(sender_.ReleaseAll(), 2);  // a partial batch, last first too
  EXPECT_EQ(Received(), (std::vector<std::string>{"B:x", "A:3", "A:2", "A:1", "A:5", "A:4"}));
  EXPECT_EQ(sender_.counts(id).held, 5u);
  EXPECT_EQ(sender_.counts(id).released, 5u);
}

TEST_F(FaultyTransportTest, DelayedMessagesLeaveWhenTheManualClockPassesTheirDueTime) {
  sender_.Add({.channel_regex = "A", .delay = milliseconds(100)});
  Send("A", "1");
  clock_.Advance(milliseconds(50));
  Send("A", "2");
  EXPECT_EQ(sender_.ReleaseDue(), 0);
  EXPECT_TRUE(Received().empty());
  clock_.Advance(milliseconds(50));  // "1" is due, "2" is not
  EXPECT_EQ(sender_.ReleaseDue(), 1);
  EXPECT_EQ(Received(), (std::vector<std::string>{"A:1"}));
  clock_.Advance(milliseconds(50));
  Send("B", "3");  // a Publish releases what is due first
  EXPECT_EQ(Received(), (std::vector<std::string>{"A:1", "A:2", "B:3"}));
  EXPECT_EQ(sender_.held(), 0u);
}

TEST_F(FaultyTransportTest, RemovingAFaultSendsWhatItHeld) {
  const auto id = sender_.Add({.channel_regex = "A", .delay = std::chrono::hours(1)});
  Send("A", "1");
  EXPECT_TRUE(Received().empty());
  sender_.Remove(id);
  EXPECT_EQ(Received(), (std::vector<std::string>{"A:1"}));
}

TEST_F(FaultyTransportTest, FaultsApplyInOrderAndTheFirstDropEndsAMessagesWay) {
  const auto first = sender_.Add({.channel_regex = "A", .drop_first = 1});
  const auto second = sender_.Add({.channel_regex = "A|B", .duplicate_probability = 1.0});
  Send("A", "1");
  Send("A", "2");
  EXPECT_EQ(Received(), (std::vector<std::string>{"A:2", "A:2"}));
  EXPECT_EQ(sender_.counts(first).matched, 2u);
  EXPECT_EQ(sender_.counts(second).matched, 1u);  // "1" never reached it
}

TEST_F(FaultyTransportTest, IncomingFaultsDropAndDuplicateWhatHandlersSee) {
  FaultyTransport rx_net(receiver_, {.seed = 1});
  std::vector<std::string> seen;
  auto sub = rx_net.Subscribe(
      "C|D", [&](const std::string& channel, std::span<const std::uint8_t>) { seen.push_back(channel); });
  const auto drop = rx_net.Add({.channel_regex = "C", .direction = Direction::kIncoming, .mute = true});
  rx_net.Add({.channel_regex = "D", .direction = Direction::kIncoming, .duplicate_probability = 1.0});
  rx_net.Add({.channel_regex = "C", .mute = true});  // outgoing: does not touch what arrives
  Send("C", "1");
  Send("D", "2");
  while (rx_net.HandleFor(Duration(0)) > 0) {
  }
  EXPECT_EQ(seen, (std::vector<std::string>{"D", "D"}));
  EXPECT_EQ(rx_net.counts(drop).dropped, 1u);
}

TEST_F(FaultyTransportTest, RefusesFaultsItCannotApply) {
  EXPECT_THROW(sender_.Add({.channel_regex = "(", .mute = true}), Error);
  EXPECT_THROW(sender_.Add({.drop_probability = 1.5}), Error);
  EXPECT_THROW(sender_.Add({.direction = Direction::kIncoming, .delay = milliseconds(1)}), Error);
  EXPECT_THROW(sender_.Add({.direction = Direction::kIncoming, .reverse_batch = 2}), Error);
  EXPECT_THROW(sender_.Add({.reverse_batch = 2, .delay = milliseconds(1)}), Error);
}

}  // namespace
}  // namespace robotalk::testing
