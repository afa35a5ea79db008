#include "fuzz_targets.h"

#include "config_codec.h"
#include "protocol_codec.h"
#include "robotalk/error.h"
#include "robotalk/request.h"
#include "robotalk/urdf_import.h"
#include "robotalk_msgs/announce_t.hpp"

#include <climits>
#include <string>

namespace robotalk::fuzz {

void Package(Bytes bytes) {
  // What the server runs on ROBOTALK/<robot>/REQUEST (header and item
  // problems come back inside the Request, to be answered ERROR).
  try {
    (void)DecodeRequest(bytes);
  } catch (const Error&) {
  }
}

void ReplyPackage(Bytes bytes) {
  // What the client runs on ROBOTALK/<robot>/REPLY/<id>.
  try {
    (void)DecodeReplyBatch(bytes);
  } catch (const Error&) {
  }
}

void RobotState(Bytes bytes) {
  try {
    (void)DecodeRobotState(bytes);
  } catch (const Error&) {
  }
}

void Config(Bytes bytes) {
  try {
    (void)DecodeConfigHeader(bytes);
    (void)DecodeConfig(bytes);
  } catch (const Error&) {
  }
}

void Announce(Bytes bytes) {
  // What the server, `robotalk robots` and the CLI's announce watch run.
  try {
    (void)DecodeAnnouncement(bytes);
  } catch (const ProtocolError&) {
  }
}

void Hello(Bytes bytes) {
  // What the server runs on ROBOTALK/<robot>/HELLO.
  try {
    (void)DecodeHello(bytes);
  } catch (const ProtocolError&) {
  }
}

void HelloAnswer(Bytes bytes) {
  // What the client runs on ROBOTALK/<robot>/HELLO/<client>.
  try {
    (void)DecodeHelloAnswer(bytes);
  } catch (const ProtocolError&) {
  }
}

void Urdf(Bytes bytes) {
  try {
    (void)ParseUrdf(std::string(reinterpret_cast<const char*>(bytes.data()), bytes.size()), {}, "fuzz.urdf");
  } catch (const Error&) {
  }
}

std::span<const Target> Targets() {
  static const Target targets[] = {
      {"package", &Package}, {"reply_package", &ReplyPackage}, {"robot_state", &RobotState},
      {"config", &Config},   {"announce", &Announce},          {"urdf", &Urdf},
      {"hello", &Hello},     {"hello_answer", &HelloAnswer},
  };
  return targets;
}

}  // namespace robotalk::fuzz
