// Private to the protocol library (and the tests of its codec): conversion
// between a RobotModel and its LCM configuration message struct
// (lcmtypes/robotalk_msgs/robot_config_t.lcm). What the rest of the project
// uses -- bytes and the hash -- is robotalk/config_message.h.
//
// The message starts with a fixed-length header (robotalk_msgs::config_header_t)
// carrying counts, byte offsets of the link, joint and frame blocks, the total
// dofs and a hash of the whole description, so a client can read the header
// alone, compare the hash with its cache and skip the rest.
#pragma once

#include "robotalk/config_message.h"
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

/// Decodes only the fixed-length header at the start of encoded config bytes
/// (EncodeConfig(), config_message.h). Throws as DecodeConfigHash.
robotalk_msgs::config_header_t DecodeConfigHeader(std::span<const std::uint8_t> bytes);

}  // namespace robotalk
