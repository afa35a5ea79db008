// Command deadlines (expiry.h, issue 23): which limit a command carries, the
// refusal's text, and what holds its actuator.
#include "expiry.h"

#include <gtest/gtest.h>

namespace robotalk {
namespace {

using std::chrono::milliseconds;

TEST(EffectiveMaxLate, ServoCommandsTakeTheRobotsDefaultUnlessThePackageGivesOne) {
  const Duration robot = milliseconds(100);
  EXPECT_EQ(EffectiveMaxLate(CommandType::kJointSetPoint, true, Duration(0), robot), robot);
  EXPECT_EQ(EffectiveMaxLate(CommandType::kSetSpeed, true, Duration(0), robot), robot);
  EXPECT_EQ(EffectiveMaxLate(CommandType::kJointSetPoint, true, milliseconds(30), robot), milliseconds(30));
  EXPECT_EQ(EffectiveMaxLate(CommandType::kJointSetPoint, true, Duration::max(), robot), kNeverExpires);
}

TEST(EffectiveMaxLate, AGotoRunsLateUnlessItCarriesALimit) {
  EXPECT_EQ(EffectiveMaxLate(CommandType::kGoto, true, Duration(0), milliseconds(100)), kNeverExpires);
  EXPECT_EQ(EffectiveMaxLate(CommandType::kGoto, true, milliseconds(500), milliseconds(100)),
            milliseconds(500));
}

TEST(EffectiveMaxLate, AStopOrACommandDueNowNeverExpires) {
  EXPECT_EQ(EffectiveMaxLate(CommandType::kStop, true, milliseconds(1), milliseconds(1)), kNeverExpires);
  EXPECT_EQ(EffectiveMaxLate(CommandType::kJointSpeed, false, milliseconds(1), milliseconds(1)),
            kNeverExpires);
}

TEST(ExpiryRefusal, NamesHowLateItArrivedAndTheLimit) {
  EXPECT_EQ(ExpiryRefusal(milliseconds(100), milliseconds(100)), std::nullopt);  // at the limit: runs
  EXPECT_EQ(ExpiryRefusal(Duration::max() / 2, kNeverExpires), std::nullopt);
  EXPECT_EQ(ExpiryRefusal(milliseconds(840), milliseconds(100)).value(),
            "expired: arrived 0.84 s after its start, limit 0.1 s");
  EXPECT_EQ(ExpiryRefusal(milliseconds(840), milliseconds(100), milliseconds(840)).value(),
            "expired: arrived 0.84 s after its start, limit 0.1 s");
}

TEST(ExpiryRefusal, SaysWhenTheCommandArrivedInTimeAndTheServerWasLate) {
  EXPECT_EQ(ExpiryRefusal(milliseconds(200), milliseconds(100), -milliseconds(5)).value(),
            "expired: began 0.2 s after its start (it arrived in time), limit 0.1 s");
  EXPECT_EQ(ExpiryRefusal(milliseconds(200), milliseconds(100), milliseconds(50)).value(),
            "expired: began 0.2 s after its start (it arrived 0.05 s after it), limit 0.1 s");
}

TEST(ExpiryRefusal, ItsRepliesAreRecognisedAndNoOtherInterruption) {
  Reply r;
  r.signal = Signal::kInterrupted;
  r.message = *ExpiryRefusal(milliseconds(300), milliseconds(100));
  EXPECT_TRUE(IsExpiryReply(r));
  r.message = "flushed by panic from client 1";
  EXPECT_FALSE(IsExpiryReply(r));
  r.message = *ExpiryRefusal(milliseconds(300), milliseconds(100));
  r.signal = Signal::kSuccess;
  EXPECT_FALSE(IsExpiryReply(r));
}

TEST(HoldAfterExpiry, StopsASpeedOrForceActuatorAndLeavesASetPointHolding) {
  EXPECT_EQ(HoldAfterExpiry(CommandType::kJointSpeed, 3).joint, 3);
  EXPECT_EQ(HoldAfterExpiry(CommandType::kJointForce, 2).joint, 2);
  EXPECT_TRUE(HoldAfterExpiry(CommandType::kSetSpeed, -1).base);
  EXPECT_FALSE(HoldAfterExpiry(CommandType::kJointSetPoint, 3).any());
  EXPECT_FALSE(HoldAfterExpiry(CommandType::kFrameSetPoint, 0).any());
  EXPECT_FALSE(HoldAfterExpiry(CommandType::kGoto, -1).any());
}

}  // namespace
}  // namespace robotalk
