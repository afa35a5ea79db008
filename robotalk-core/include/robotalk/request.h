// Whole protocol messages as C++ values: a client's REQUEST package, a
// server's batch of replies, and a server's ANNOUNCE. The server core and the
// client speak these; only their codec (request_codec.cpp, beside
// protocol_codec.cpp) knows the LCM wire structs (docs/protocol.md).
#pragma once

#include "robotalk/clock.h"
#include "robotalk/command.h"
#include "robotalk/state_sample.h"

#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace robotalk {

/// How a package's start times are to be read (paper Table I).
enum class RequestMode : std::int8_t {
  kDirect = 0,    ///< absolute server-clock start times (or none)
  kDelay = 1,     ///< absolute server-clock start times, chosen ahead by a delay
  kPlayback = 2,  ///< start times are offsets from the sequence start
};

/// A playback package's declaration of its whole sequence.
struct PlaybackDeclaration {
  std::int64_t id = 0;      ///< chosen by the client, unique among its sequences
  std::int64_t frames = 0;  ///< commands in the whole sequence
  Duration duration{0};     ///< offset of its last command
};

/// An item of a package that did not decode: it is answered ERROR.
struct MalformedItem {
  CommandId id = 0;
  std::string reason;
};

/// One client package (ROBOTALK/<robot>/REQUEST).
struct Request {
  std::int64_t client_id = 0;
  std::int64_t sequence = 0;  ///< 1, 2, 3 ... per client; a retransmission repeats it
  TimePoint send_time{};      ///< client clock (informational)
  bool panic = false;
  RequestMode mode = RequestMode::kDirect;
  PlaybackDeclaration playback;  ///< kPlayback only
  std::vector<Query> queries;
  std::vector<Command> commands;  ///< kPlayback: start_time holds the offset (see command.h)
  std::vector<MalformedItem> malformed;
  /// Non-empty when the header is inconsistent with the payload (mixed
  /// payload, bad version, ...): every item is answered ERROR with it.
  std::string header_error;

  /// The ids of every item, queries first, as the package carried them.
  std::vector<CommandId> item_ids() const;
};

/// Decodes a REQUEST package. Per-item and header problems are reported in
/// the Request (malformed, header_error) so they can be answered; throws
/// ProtocolError only for bytes that carry no trustworthy client id
/// (truncated, hostile counts, another message type).
Request DecodeRequest(std::span<const std::uint8_t> bytes);
/// Encodes a request (clients and tests).
std::vector<std::uint8_t> EncodeRequest(const Request& request);

/// Replies for one client (ROBOTALK/<robot>/REPLY/<client>).
struct ReplyBatch {
  std::int64_t client_id = 0;
  std::int64_t ack_sequence = 0;  ///< the package this acknowledges; 0 = none
  TimePoint server_receive{};     ///< when that package arrived (clock sync)
  TimePoint server_send{};
  std::vector<Reply> replies;
};
std::vector<std::uint8_t> EncodeReplyBatch(const ReplyBatch& batch);
/// Throws ProtocolError on truncated, hostile or foreign bytes.
ReplyBatch DecodeReplyBatch(std::span<const std::uint8_t> bytes);

/// One served robot in an ANNOUNCE.
struct RobotAnnouncement {
  std::string name;
  std::string driver;
  std::uint64_t config_hash = 0;
  int total_dofs = 0;
  std::int8_t base_type = 0;
  bool panic = false;
  int num_clients = 0;
};
/// ROBOTALK/ANNOUNCE.
struct Announcement {
  std::int64_t server_id = 0;
  TimePoint server_time{};
  Duration uptime{0};  ///< how long the server has been serving
  std::string url_hint;
  std::vector<RobotAnnouncement> robots;
};
std::vector<std::uint8_t> EncodeAnnouncement(const Announcement& announcement);

/// A broadcast state sample (ROBOTALK/<robot>/STATE) as bytes.
std::vector<std::uint8_t> EncodeStateSample(const StateSample& sample);
/// Throws ProtocolError on truncated, hostile or foreign bytes, or more than
/// 1024 robots.
Announcement DecodeAnnouncement(std::span<const std::uint8_t> bytes);

}  // namespace robotalk
