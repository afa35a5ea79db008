// What the server and the client run on bytes they receive, one function per
// decoder, shared by the libFuzzer targets (scripts/fuzz.sh, docs/fuzzing.md)
// and the regression replay test of the regular build.
//
// Each function returns normally when the input decodes or is refused with a
// robotalk::Error (ProtocolError, ModelError, UrdfError): that is the
// contract for hostile input. Any other exception escapes, and a crash or a
// sanitizer report is a crash: both are bugs.
#pragma once

#include <cstdint>
#include <span>

namespace robotalk::fuzz {

using Bytes = std::span<const std::uint8_t>;

/// Server, ROBOTALK/<robot>/REQUEST: DecodeRequest (DecodePackage,
/// CheckPackageHeader, FromWire of every query and command).
void Package(Bytes bytes);
/// Client, ROBOTALK/<robot>/REPLY/<id>: DecodeReplyBatch (DecodeReplyPackage,
/// FromWire of every reply).
void ReplyPackage(Bytes bytes);
/// Client, ROBOTALK/<robot>/STATE: DecodeRobotState.
void RobotState(Bytes bytes);
/// Client, ROBOTALK/<robot>/CONFIG: DecodeConfigHeader, then DecodeConfig.
void Config(Bytes bytes);
/// Server and client (`robotalk robots`), ROBOTALK/ANNOUNCE: DecodeAnnouncement
/// (bounds-checked before LCM's generated decoder, which threw std::length_error
/// through LCM's C callback on a zero-length string).
void Announce(Bytes bytes);
/// ParseUrdf on the bytes as text (robotalk-describe, the server's --robot).
void Urdf(Bytes bytes);
/// DecodeHello (server) and DecodeHelloAnswer (client), protocol 2 sessions.
void Hello(Bytes bytes);
void HelloAnswer(Bytes bytes);

struct Target {
  const char* name;  ///< also the folder of its seeds and regressions
  void (*run)(Bytes);
};
/// Every target above, by name.
std::span<const Target> Targets();

}  // namespace robotalk::fuzz
