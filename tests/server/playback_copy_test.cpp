// Issue 23 item 3, ninth session: a connect-time package that waited behind
// a copy of an earlier one (the client's retransmission, on the relay's
// congested FIFO link) is no delay a frame meets ("The copies" in
// playback_estimator.h). On a manual timeline.
#include "playback_estimator.h"
#include "playback_model.h"

#include <gtest/gtest.h>

namespace robotalk {
namespace {

using namespace playback_model;

// A FIFO link, 40 frames at 10 Hz; frame 0 took 1 ms (the least delay). Two
// seconds before it: a package sent at 0 ms (20 ms) and one at 300 ms
// (40 ms); a copy of the second, resent at 400 ms, handled at 750 ms (it held
// the link until then); a package sent at 690 ms that arrived at 760 ms
// (70 ms: 59 of them behind the copy, 10 its own service); one at 1000 ms (30 ms).
PlaybackEstimator AfterACopy(bool copy_seen, PlaybackEstimatorOptions options = {}) {
  const TimePoint t0 = kT0 - std::chrono::seconds(2);
  DelayHistory h;
  h.Add(t0, t0 + milliseconds(20));
  h.Add(t0 + milliseconds(300), t0 + milliseconds(340));
  if (copy_seen) h.AddCopy(t0 + milliseconds(300), t0 + milliseconds(750));
  h.Add(t0 + milliseconds(690), t0 + milliseconds(760));
  h.Add(t0 + milliseconds(1000), t0 + milliseconds(1030));
  EXPECT_EQ(h.Recent(kT0).size(), 4u) << "a copy is no delay";
  EXPECT_EQ(h.RecentSamples(kT0).size(), copy_seen ? 5u : 4u);
  return AtFirstFrame(h.RecentSamples(kT0), options);
}

TEST(CopyWait, APackageThatWaitedBehindARetransmittedCopyCountsWithoutThatWait) {
  // Before (the copy not seen, or the discount off): the 70 ms package sets
  // the worst delay: 70 + spread / n (69 / 5) ms, less frame 0's 1 ms and the
  // 10 ms lead, + 2 ms margin: 74.8 ms after frame 0.
  for (const PlaybackEstimator& before :
       {AfterACopy(false), AfterACopy(true, {.burst_wait_discount = false})}) {
    ASSERT_TRUE(before.adaptive());
    EXPECT_EQ(*before.delay_spread(), milliseconds(69));
    EXPECT_NEAR(ToSeconds(before.StartTime() - kT0), 0.0748, 1e-6);
  }
  // After: its delay less its 59 ms behind the copy (11 ms), spread 39 ms:
  // worst 40 + 39 / 5 = 47.8 ms; start 47.8 - 1 - 10 + 2 = 38.8 ms after frame 0.
  const PlaybackEstimator after = AfterACopy(true);
  ASSERT_TRUE(after.adaptive());
  EXPECT_TRUE(after.burst_discounted());
  EXPECT_EQ(*after.delay_spread(), milliseconds(39));
  EXPECT_NEAR(ToSeconds(after.StartTime() - kT0), 0.0388, 1e-6);
  EXPECT_NE(after.Describe().find("\"copies\":[[-1250.0,-1699.0]]"), std::string::npos) << after.Describe();
}

TEST(CopyWait, AJitteryLinkKeepsItsDelaysAsMeasured) {
  // The same packages but the 5 ms one arrived before the 70 ms one although
  // sent after it: not a FIFO link, and the spread (69 ms) is within the gate,
  // so nothing is left out, copy or not.
  const TimePoint t0 = kT0 - std::chrono::seconds(2);
  DelayHistory h;
  h.Add(t0, t0 + milliseconds(20));
  h.AddCopy(t0, t0 + milliseconds(700));
  h.Add(t0 + milliseconds(705), t0 + milliseconds(710));
  h.Add(t0 + milliseconds(690), t0 + milliseconds(760));
  h.Add(t0 + milliseconds(1000), t0 + milliseconds(1030));
  const PlaybackEstimator est = AtFirstFrame(h.RecentSamples(kT0));
  ASSERT_TRUE(est.adaptive());
  EXPECT_FALSE(est.burst_discounted());
  EXPECT_EQ(*est.delay_spread(), milliseconds(69));
}

TEST(CopyWait, CopiesNeverPushDelaysOutOfTheHistory) {
  // A WAN's resends: every package resent several times. The history keeps
  // its last kCapacity delays whatever the number of copies, each copy in
  // the order handled among them.
  DelayHistory h;
  const TimePoint t0 = kT0 - std::chrono::seconds(20);
  for (int i = 0; i < 40; ++i) {
    const TimePoint sent = t0 + milliseconds(100) * i;
    h.Add(sent, sent + milliseconds(300));
    for (int k = 1; k <= 3; ++k) h.AddCopy(sent, sent + milliseconds(300 + 10 * k));
  }
  EXPECT_EQ(h.Recent(kT0).size(), DelayHistory::kCapacity);
  const std::vector<DelayHistory::Sample> all = h.RecentSamples(kT0);
  EXPECT_EQ(all.size(), 2 * DelayHistory::kCapacity);
  for (std::size_t k = 1; k < all.size(); ++k) EXPECT_LE(all[k - 1].received, all[k].received);
}

}  // namespace
}  // namespace robotalk
