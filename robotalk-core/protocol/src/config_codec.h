// Conversion between a RobotModel and its LCM configuration message
// (lcmtypes/robotalk_msgs/robot_config_t.lcm), and the configuration hash.
//
// The message starts with a fixed-length header (robotalk_msgs::config_header_t)
// carrying counts, byte offsets of the link, joint and frame blocks, the total
// dofs and a hash of the whole description, so a client can read the header
// alone, compare the hash with its cache and skip the rest.
#pragma once

#include "robotalk/robot_model.h"
#include "robotalk_msgs/config_header_t.hpp"
#include "robotalk_msgs/robot_config_t.hpp"

#include <cstdint>
#include <span>
#include <vector>

namespace robotalk {

/// The message for `model`, header filled (counts, offsets, hash).
robotalk_msgs::robot_config_t ToMessage(const RobotModel& model);

/// The model of a message. Throws ProtocolError when the header disagrees with
/// the blocks or the hash does not match, ModelError when the description is
/// invalid (each naming the element).
RobotModel FromMessage(const robotalk_msgs::robot_config_t& msg);

/// Encodes ToMessage(model) as LCM bytes (with LCM's fingerprint).
std::vector<std::uint8_t> EncodeConfig(const RobotModel& model);
/// Decodes bytes of EncodeConfig(). Throws ProtocolError on truncated or
/// hostile input. A keyed server's signature suffix is skipped, not verified
/// (broadcast_signature.h).
RobotModel DecodeConfig(std::span<const std::uint8_t> bytes);
/// Decodes only the fixed-length header at the start of encoded config bytes.
robotalk_msgs::config_header_t DecodeConfigHeader(std::span<const std::uint8_t> bytes);

/// Stable 64-bit hash of the whole description (FNV-1a over its canonical
/// encoding); equal models have equal hashes on every machine.
std::uint64_t ConfigHash(const RobotModel& model);

}  // namespace robotalk
