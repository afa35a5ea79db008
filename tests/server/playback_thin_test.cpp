// Issue 23 item 3, tenth session: a sequence whose frames queue behind each
// other faster than the 10 % stretch grows the buffer, on a link whose
// connect-time delays lay within the gate (the adaptive start, not a followed
// queue). On a manual timeline (the pure model, playback_model.h).
#include "playback_estimator.h"
#include "playback_model.h"
#include "playback_schedule.h"

#include <gtest/gtest.h>

#include <vector>

namespace robotalk {
namespace {

using namespace playback_model;

// Relay U[0, 150] ms, seed 1521 (bench/results/session9/reach1521.json, the
// base server): nine connect-time round trips and the 40 frames, each one-way
// delay in ms (the relay's least + 5 ms, so that none is below zero). The
// connect-time delays (less the copies' waits, as the server saw them) spread
// by 115 ms, within the gate (120 ms): the adaptive start, 91 ms after frame 0;
// then frames 1 to 5 queued: 99, 150, 195, 203, 241 ms against frame 0's 66.
const std::vector<int> kConnect = {120, 39, 60, 110, 5, 6, 51, 103, 73};
const std::vector<int> kFrames = {71, 104, 155, 200, 208, 246, 240, 140, 50, 65, 35, 96, 98, 1,
                                  41, 71,  34,  37,  104, 82,  42,  131, 31, 16, 46, 92, 39, 56,
                                  60, 19,  117, 134, 55,  61,  35,  57,  24, 64, 9,  5};

SimRun Seed1521(PlaybackEstimatorOptions options = {}) {
  return Simulate(
      kFrames.size(), milliseconds(100), kConnect.size(),
      [](std::size_t k, TimePoint) {
        return milliseconds(k < kConnect.size() ? kConnect[k] : kFrames[k - kConnect.size()]);
      },
      options);
}

TEST(ThinBuffer, AQueueWithinTheGateThatOutgrowsTheTenPercentStretchPlaysEveryFrameInTime) {
  // Before (the base, 5b1c8a9): frames 3 and 5 arrived after the 10 %
  // stretch could reach them: two pauses past the bound (as on the relay).
  const SimRun run = Seed1521();
  EXPECT_EQ(run.late, 0) << "frames past the bound";
  EXPECT_LE(ToSeconds(run.start_delay), 0.100) << "the start itself is unchanged (91 ms on the relay)";
}

}  // namespace
}  // namespace robotalk
