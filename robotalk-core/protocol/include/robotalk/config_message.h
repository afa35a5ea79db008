// A RobotModel as the bytes of its configuration message
// (ROBOTALK/<robot>/CONFIG; docs/configuration_message.md), and the
// configuration hash. The message starts with a fixed-length header carrying
// counts, byte offsets of the link, joint and frame blocks, the total dofs and
// a hash of the whole description, so a client can read the hash alone,
// compare it with its cache and skip the rest.
//
// Project types only: the wire structs stay in the protocol library
// (robotalk-core/protocol/src/config_codec.h). Pure functions; thread-safe.
#pragma once

#include "robotalk/robot_model.h"

#include <cstdint>
#include <span>
#include <vector>

namespace robotalk {

/// Encodes `model` as its configuration message (with LCM's fingerprint,
/// header filled: counts, offsets, hash). Throws ModelError when a name
/// cannot travel (a NUL byte).
std::vector<std::uint8_t> EncodeConfig(const RobotModel& model);
/// Decodes bytes of EncodeConfig(). Throws ProtocolError on truncated or
/// hostile input, a header that disagrees with the blocks or a hash that does
/// not match, ModelError when the description is invalid (each naming the
/// element). A keyed server's signature suffix is skipped, not verified
/// (broadcast_signature.h).
RobotModel DecodeConfig(std::span<const std::uint8_t> bytes);
/// The configuration hash the header of encoded config bytes carries, read
/// from the fixed-length header alone. Throws ProtocolError on truncated or
/// foreign bytes or an unsupported format version.
std::uint64_t DecodeConfigHash(std::span<const std::uint8_t> bytes);

/// Stable 64-bit hash of the whole description (FNV-1a over its canonical
/// encoding); equal models have equal hashes on every machine.
std::uint64_t ConfigHash(const RobotModel& model);

}  // namespace robotalk
