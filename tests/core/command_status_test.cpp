// CommandStatusOf / CommandStatusText (robotalk/command_status.h): the one
// reader and writer of COMMAND_STATUS's fixed answers.
#include "robotalk/command_status.h"

#include <gtest/gtest.h>

namespace robotalk {
namespace {

TEST(CommandStatusOf, TellsAWaitingOrUnknownCommandFromOneThatEndedBusyOrNa) {
  const auto answer = [](Signal signal, std::string message) {
    return Reply{.id = 99, .signal = signal, .message = std::move(message)};
  };
  EXPECT_EQ(CommandStatusOf(answer(Signal::kBusy, "command 7 has not ended"), 7),
            CommandStatusKind::kNotEnded);
  EXPECT_EQ(CommandStatusOf(answer(Signal::kBusy, CommandStatusText(CommandStatusKind::kNotEnded, 7)), 7),
            CommandStatusKind::kNotEnded);
  EXPECT_EQ(CommandStatusOf(answer(Signal::kNa, CommandStatusText(CommandStatusKind::kNotReceived, 7)), 7),
            CommandStatusKind::kNotReceived);
  // Ended BUSY or NA with its own message, or the text about another command.
  EXPECT_EQ(CommandStatusOf(answer(Signal::kBusy, "GOTO: GOTO in progress (command 6)"), 7),
            CommandStatusKind::kEnded);
  EXPECT_EQ(CommandStatusOf(answer(Signal::kNa, "JOINT_SETPOINT: no such joint"), 7),
            CommandStatusKind::kEnded);
  EXPECT_EQ(CommandStatusOf(answer(Signal::kBusy, "command 8 has not ended"), 7), CommandStatusKind::kEnded);
  EXPECT_EQ(CommandStatusOf(answer(Signal::kSuccess, "command 7 has not ended"), 7),
            CommandStatusKind::kEnded);
  EXPECT_EQ(CommandStatusText(CommandStatusKind::kEnded, 7), "");
}

}  // namespace
}  // namespace robotalk
