// LinkLoss (robotalk-client/src/link_loss.h): the client's own count of lost
// messages and the automatic playback redundancy's rule, on a manual clock
// (issue 23 item 3, lossy WAN links).
#include "link_loss.h"

#include <gtest/gtest.h>

namespace robotalk::client {
namespace {

using std::chrono::milliseconds;
using std::chrono::seconds;
const TimePoint kT0(seconds(1000));
const Duration kSettle = milliseconds(400);  // twice a 200 ms retransmission timeout

TEST(LinkLoss, APackageSentOnceAndAcknowledgedIsNoLoss) {
  LinkLoss l;
  l.OnSend(1, kT0);
  l.OnAck(1);
  l.Settle(kT0 + seconds(1), kSettle);
  EXPECT_EQ(l.lost(), 0u);
  EXPECT_EQ(l.settled(), 1u);
  EXPECT_FALSE(l.LostRecently(kT0 + seconds(1)));
}

// WAN 300: the first copy is only slow (a 600 ms round trip against a first
// retransmission timeout of 100 ms): the server acknowledges both copies.
TEST(LinkLoss, ASpuriousRetransmissionIsNoLoss) {
  LinkLoss l;
  l.OnSend(1, kT0);
  l.OnSend(1, kT0 + milliseconds(100));  // the resend
  l.OnAck(1);                            // the first copy's ack, at 600 ms
  l.OnAck(1);                            // the resend's, at 700 ms
  l.Settle(kT0 + seconds(2), kSettle);
  EXPECT_EQ(l.lost(), 0u);
  EXPECT_FALSE(l.last_loss());
}

TEST(LinkLoss, ALostFirstCopyIsCountedOnceEveryAckHadTimeToCome) {
  LinkLoss l;
  l.OnSend(1, kT0);
  l.OnSend(1, kT0 + milliseconds(100));
  l.OnAck(1);  // only the resend's
  l.Settle(kT0 + milliseconds(100) + kSettle - milliseconds(1), kSettle);
  EXPECT_EQ(l.lost(), 0u) << "the first copy's ack may still come";
  l.Settle(kT0 + milliseconds(100) + kSettle, kSettle);
  EXPECT_EQ(l.lost(), 1u);
  EXPECT_TRUE(l.LostRecently(kT0 + seconds(1)));
}

TEST(LinkLoss, AHeartbeatWithoutAckAndALostAckAreLossesToo) {
  LinkLoss l;
  l.OnSend(1, kT0);     // a heartbeat: never resent, its ack lost
  l.OnSend(2, kT0, 2);  // a playback package with its redundancy copy: one ack back
  l.OnAck(2);
  l.OnSend(3, kT0, 2);  // both acks back
  l.OnAck(3);
  l.OnAck(3);
  l.Settle(kT0 + seconds(1), kSettle);
  EXPECT_EQ(l.lost(), 2u);
  EXPECT_EQ(l.settled(), 3u);
}

// A heartbeat never acknowledged, found lost at 1 s.
LinkLoss OneLossFoundAtOneSecond() {
  LinkLoss l;
  l.OnSend(1, kT0);
  l.Settle(kT0 + seconds(1), kSettle);
  return l;
}

TEST(LinkLoss, AnAckAfterThePackageSettledChangesNothing) {
  LinkLoss l = OneLossFoundAtOneSecond();
  l.OnAck(1);
  l.Settle(kT0 + seconds(2), kSettle);
  EXPECT_EQ(l.lost(), 1u);
  EXPECT_EQ(l.settled(), 1u);
}

TEST(LinkLoss, ALossIsForgottenAfterTheMemory) {
  const LinkLoss l = OneLossFoundAtOneSecond();
  ASSERT_EQ(l.last_loss(), kT0 + seconds(1));
  EXPECT_TRUE(l.LostRecently(kT0 + seconds(1) + LinkLoss::kMemory - milliseconds(1)));
  EXPECT_FALSE(l.LostRecently(kT0 + seconds(1) + LinkLoss::kMemory));
}

TEST(LinkLoss, AServerThatNeverAnswersDoesNotGrowTheBookkeeping) {
  LinkLoss l;
  for (std::int64_t k = 1; k <= static_cast<std::int64_t>(LinkLoss::kMaxPending) + 10; ++k) l.OnSend(k, kT0);
  l.Settle(kT0 + seconds(1), kSettle);
  EXPECT_EQ(l.settled(), LinkLoss::kMaxPending) << "the 10 oldest forgotten";
  EXPECT_EQ(l.lost(), LinkLoss::kMaxPending);
}

// The rule: a second copy only on a link that lost a message and only where
// the retransmission would come after the frame is due.
TEST(LinkLoss, ASecondCopyOnlyAfterALossAndWhenARetransmissionWouldComeTooLate) {
  const TimePoint now = kT0 + seconds(2);
  const Duration rto = milliseconds(150);
  EXPECT_FALSE(LinkLoss().WantsSecondCopy(now, rto, std::nullopt))
      << "no loss yet: a congested link keeps one copy";
  const LinkLoss l = OneLossFoundAtOneSecond();
  EXPECT_TRUE(l.WantsSecondCopy(now, rto, std::nullopt)) << "before the delay reply: no headroom known";
  EXPECT_TRUE(l.WantsSecondCopy(now, rto, milliseconds(40))) << "a 40 ms buffer: the resend is late";
  EXPECT_FALSE(l.WantsSecondCopy(now, rto, milliseconds(150))) << "the resend arrives in time";
  EXPECT_FALSE(l.WantsSecondCopy(now, rto, seconds(3))) << "the paper's estimate: seconds of buffer";
  EXPECT_FALSE(l.WantsSecondCopy(kT0 + seconds(1) + LinkLoss::kMemory, rto, std::nullopt))
      << "60 s without a loss";
}

}  // namespace
}  // namespace robotalk::client
