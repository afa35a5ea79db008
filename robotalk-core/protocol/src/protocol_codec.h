// Private to the protocol library (and the tests of its codec): conversions
// between the C++ protocol values (command.h, state_sample.h) and their LCM
// wire forms (lcmtypes/robotalk_msgs), and safe decoding of received bytes.
// The rest of the project speaks the whole messages of request.h, which
// request_codec.cpp builds from these.
//
// Decoding never trusts the sender: LCM's generated decoders allocate an
// array from its count field before checking that the bytes are there, so a
// hostile count would allocate gigabytes. Decode*() first walk the encoding
// with bounds checks and throw ProtocolError naming the field instead.
#pragma once

#include "robotalk/command.h"
#include "robotalk/request.h"
#include "robotalk/state_sample.h"
#include "robotalk_msgs/package_t.hpp"
#include "robotalk_msgs/reply_package_t.hpp"
#include "robotalk_msgs/robot_state_t.hpp"

#include <cstdint>
#include <span>
#include <string>

namespace robotalk {

inline constexpr std::int16_t kProtocolVersion = 4;
/// The `mac` field that ends package_t and reply_package_t.
inline constexpr std::int64_t kMacBytesOnWire = 16;

// Start times on the wire (command_t.start_time_us, by the package's mode,
// package_header_t::MODE_*):
//   StartTime::Now()       <-> 0 in every mode
//   StartTime::At(t)       <-> server-clock micros of t, DIRECT and DELAY packages
//   StartTime::After(d)    <-> micros of the offset d, PLAYBACK packages (0 = the
//                              sequence start: After(0), not Now())
// Every wire time is range-checked (clock.h): an out-of-range value, or a kind
// that does not belong in the package's mode, is a ProtocolError naming the
// command id, the field and the value.

/// Encodes by the start time's kind (Now -> 0, At -> time, After -> offset).
/// Throws ProtocolError for a negative time or offset. (At(the epoch) encodes
/// as 0, which a DIRECT/DELAY package reads as now: server clocks start far
/// from their epoch, so only a test meets it.)
robotalk_msgs::command_t ToWire(const Command& c);
/// Same, and checks the kind against the package mode the command travels in.
robotalk_msgs::command_t ToWire(const Command& c, std::int8_t package_mode);
robotalk_msgs::query_t ToWire(const Query& q);
robotalk_msgs::reply_t ToWire(const Reply& r);

/// Throw ProtocolError naming the id and the bad field (unknown type, time
/// out of range, ...). The command's start time is read per `package_mode`;
/// without one, as in a DIRECT package (absolute).
Command FromWire(const robotalk_msgs::command_t& c);
Command FromWire(const robotalk_msgs::command_t& c, std::int8_t package_mode);
Query FromWire(const robotalk_msgs::query_t& q);
Reply FromWire(const robotalk_msgs::reply_t& r);

/// State samples. FromWire validates: num_dofs and num_frames non-negative and
/// equal to the array sizes, every value finite unless the sample says panic
/// (then NaN or inf is what a broken driver reported; the server halted the
/// robot for it), times in range, period and sample not negative; throws ProtocolError naming the field
/// ("robot_state 'pioneer' sample 3: position[2] is NaN"). `expected_dofs` >= 0 also checks the dof count
/// against a model's.
StateSample FromWire(const robotalk_msgs::robot_state_t& w, int expected_dofs = -1);
robotalk_msgs::robot_state_t ToWire(const StateSample& s);

/// Decodes a client package; throws ProtocolError on truncated, hostile or
/// foreign bytes (wrong fingerprint), naming what was wrong.
robotalk_msgs::package_t DecodePackage(std::span<const std::uint8_t> bytes);
/// Decodes a server reply package; same guarantees.
robotalk_msgs::reply_package_t DecodeReplyPackage(std::span<const std::uint8_t> bytes);

/// The reply package's answer to the acknowledged package's panic flag, as
/// the PANIC_* value (0 none, 1 taken, 2 refused; request.h PanicStatus).
/// Throws ProtocolError for any other value.
std::int8_t CheckedPanicStatus(const robotalk_msgs::reply_package_t& p);

/// Decodes a broadcast state sample; same guarantees. A keyed server's
/// signature suffix is skipped, not verified (broadcast_signature.h).
robotalk_msgs::robot_state_t DecodeRobotState(std::span<const std::uint8_t> bytes);
// DecodeStateSample (DecodeRobotState + FromWire) is declared in request.h.

/// Checks a decoded package's header against its payload: version, client id,
/// sequence, payload type and size, never both queries and commands. Returns
/// the ERROR text, or an empty string when consistent.
std::string CheckPackageHeader(const robotalk_msgs::package_t& p);

}  // namespace robotalk
