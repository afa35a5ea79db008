#include "panic_state.h"

#include <gtest/gtest.h>

namespace robotalk {
namespace {

TEST(PanicState, AClientsPanicHaltsTheDriverOnceAndAResetResumesIt) {
  PanicState p;
  EXPECT_FALSE(p.BeginHalt()) << "running: nothing to halt";
  EXPECT_TRUE(p.Raise());
  EXPECT_TRUE(p.in_panic());
  EXPECT_FALSE(p.faulted());
  EXPECT_EQ(p.reason(), "") << "a client's panic has no reason";
  EXPECT_FALSE(p.driver_halted()) << "latched at once, halted by the RobotDaemon";
  EXPECT_TRUE(p.requests_pending());
  EXPECT_TRUE(p.BeginHalt());
  EXPECT_TRUE(p.driver_halted());
  EXPECT_FALSE(p.BeginHalt()) << "halted once";
  EXPECT_FALSE(p.BeginResume()) << "still in panic";
  EXPECT_FALSE(p.Raise()) << "a second panic is not the first";

  EXPECT_TRUE(p.Reset());
  EXPECT_FALSE(p.in_panic());
  EXPECT_TRUE(p.driver_halted()) << "until the RobotDaemon resumes it";
  EXPECT_FALSE(p.BeginHalt());
  EXPECT_TRUE(p.BeginResume());
  EXPECT_FALSE(p.driver_halted());
  EXPECT_FALSE(p.BeginResume()) << "resumed once";
  EXPECT_FALSE(p.Reset()) << "not in panic";
}

TEST(PanicState, ADriverFaultHaltsAtOnceNamesItselfAndIsClearedOnlyByAReset) {
  PanicState p;
  EXPECT_TRUE(p.Fault("driver 'x' threw in Update: bus off")) << "the caller halts now";
  EXPECT_TRUE(p.in_panic());
  EXPECT_TRUE(p.faulted());
  EXPECT_TRUE(p.driver_halted());
  EXPECT_EQ(p.reason(), "driver 'x' threw in Update: bus off");
  EXPECT_FALSE(p.BeginHalt()) << "already halted by the fault";
  EXPECT_FALSE(p.Fault("driver 'x' threw in ReadState: bus off")) << "halted once";
  EXPECT_EQ(p.reason(), "driver 'x' threw in ReadState: bus off");
  p.Raise();  // a client's panic on top keeps the fault's reason
  EXPECT_EQ(p.reason(), "driver 'x' threw in ReadState: bus off");

  EXPECT_TRUE(p.Reset());
  EXPECT_FALSE(p.faulted());
  EXPECT_EQ(p.reason(), "");
  EXPECT_EQ(p.last_fault(), "driver 'x' threw in ReadState: bus off") << "kept for the command's ERROR";
}

TEST(PanicState, ARaiseWithAReasonNamesIt) {
  PanicState p;
  p.Raise("driver 'x' Update has run for 3 s (the bound is 2 s)");
  EXPECT_EQ(p.reason(), "driver 'x' Update has run for 3 s (the bound is 2 s)");
  EXPECT_FALSE(p.faulted()) << "an overrun or the latch is not a fault the RobotDaemon saw";
}

TEST(PanicState, APanicResetBeforeTheRobotDaemonRanStillHaltsOnceThenResumes) {
  PanicState p;
  p.Raise();
  EXPECT_TRUE(p.Reset());
  EXPECT_TRUE(p.BeginHalt()) << "the halt asked for is not lost";
  EXPECT_TRUE(p.BeginResume());
  EXPECT_FALSE(p.driver_halted());
}

TEST(PanicState, AResumeThatFaultsLeavesTheRobotHaltedAgain) {
  PanicState p;
  p.Raise();
  p.BeginHalt();
  p.Reset();
  ASSERT_TRUE(p.BeginResume());
  EXPECT_TRUE(p.Fault("driver 'x' threw in Resume: brake stuck")) << "halt again";
  EXPECT_TRUE(p.in_panic());
  EXPECT_TRUE(p.driver_halted());
}

TEST(PanicState, APanicDuringAResetIsNotResumed) {
  PanicState p;
  p.Raise();
  p.BeginHalt();
  p.Reset();
  p.Raise();  // before the RobotDaemon resumed
  EXPECT_FALSE(p.BeginHalt()) << "still halted";
  EXPECT_FALSE(p.BeginResume()) << "in panic again";
  EXPECT_TRUE(p.driver_halted());
}

}  // namespace
}  // namespace robotalk
