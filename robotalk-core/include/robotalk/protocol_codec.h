// Conversions between the C++ protocol values (command.h) and their LCM wire
// forms (lcmtypes/robotalk_msgs), and safe decoding of received bytes.
//
// Decoding never trusts the sender: LCM's generated decoders allocate an
// array from its count field before checking that the bytes are there, so a
// hostile count would allocate gigabytes. Decode*() first walk the encoding
// with bounds checks and throw ProtocolError naming the field instead.
#pragma once

#include "robotalk/command.h"
#include "robotalk_msgs/package_t.hpp"
#include "robotalk_msgs/reply_package_t.hpp"
#include "robotalk_msgs/robot_state_t.hpp"

#include <cstdint>
#include <span>
#include <string>

namespace robotalk {

inline constexpr std::int16_t kProtocolVersion = 1;

robotalk_msgs::command_t ToWire(const Command& c);
robotalk_msgs::query_t ToWire(const Query& q);
robotalk_msgs::reply_t ToWire(const Reply& r);

/// Throw ProtocolError naming the id and the bad field (unknown type, ...).
Command FromWire(const robotalk_msgs::command_t& c);
Query FromWire(const robotalk_msgs::query_t& q);
Reply FromWire(const robotalk_msgs::reply_t& r);

/// Decodes a client package; throws ProtocolError on truncated, hostile or
/// foreign bytes (wrong fingerprint), naming what was wrong.
robotalk_msgs::package_t DecodePackage(std::span<const std::uint8_t> bytes);
/// Decodes a server reply package; same guarantees.
robotalk_msgs::reply_package_t DecodeReplyPackage(std::span<const std::uint8_t> bytes);

/// Decodes a broadcast state sample; same guarantees.
robotalk_msgs::robot_state_t DecodeRobotState(std::span<const std::uint8_t> bytes);

/// Checks a decoded package's header against its payload: version, client id,
/// sequence, payload type and size, never both queries and commands. Returns
/// the ERROR text, or an empty string when consistent.
std::string CheckPackageHeader(const robotalk_msgs::package_t& p);

}  // namespace robotalk
