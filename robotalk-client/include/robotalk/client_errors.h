// Exceptions thrown by the RoboTalk client (robot_client.h), beside the core
// hierarchy of robotalk/error.h.
#pragma once

#include "robotalk/error.h"

namespace robotalk {

/// A blocking call did not get its answer in time: the reply did not arrive
/// before the call's timeout, or the client gave up retransmitting a package the
/// server never answered (server gone, network down). The message names the
/// call, the id or robot and the time waited.
class TimeoutError : public Error {
 public:
  using Error::Error;
};

/// The client cannot tell whether a command ran: it gave up retransmitting a
/// package the server may have received, or the server instance that had it
/// is gone (restarted) or forgot the session. Ask with
/// RobotClient::CommandStatus (same session) or re-plan from the robot's state.
class UnknownOutcomeError : public TimeoutError {
 public:
  using TimeoutError::TimeoutError;
};

/// The server answered a panic package and did NOT act on it: the robot is
/// not in panic because of this call. what() names the robot and the
/// server's reason (a key without the `panic` right on that robot, a package
/// the server could not accept, ...). Never thrown for a panic the server took.
class PanicRefusedError : public Error {
 public:
  using Error::Error;
};

/// The client cannot do what was asked: not connected, already connected, LCM
/// could not be initialised, a package too large, the client is closing, or
/// an argument it checks is wrong (SendTrajectory: the message names the
/// point and the value).
class ClientError : public Error {
 public:
  using Error::Error;
};

}  // namespace robotalk
