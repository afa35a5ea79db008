// Whole protocol messages as C++ values: a client's REQUEST package, a
// server's batch of replies, the hello and its answer, and a server's
// ANNOUNCE. The server core and the C++ client (robotalk-client/src) both
// speak these and nothing else: every package the client sends, hello,
// heartbeat and panic included, goes out through EncodeRequest, and every
// reply package it reads comes in through DecodeReplyBatch -- the functions
// the server's tests use. Only their codec (request_codec.cpp, beside
// protocol_codec.cpp) knows the LCM wire structs (docs/protocol.md).
#pragma once

#include "robotalk/clock.h"
#include "robotalk/command.h"
#include "robotalk/max_late.h"
#include "robotalk/session_auth.h"
#include "robotalk/state_sample.h"
#include "robotalk/traffic_layout.h"
#include "robotalk/trajectory.h"

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
  std::int64_t session_id = 0;  ///< from the client's HelloAnswer (docs/protocol.md, Sessions)
  std::int64_t sequence = 0;    ///< 1, 2, 3 ... per client; a retransmission repeats it
  TimePoint send_time{};        ///< client clock (informational)
  bool panic = false;
  RequestMode mode = RequestMode::kDirect;
  PlaybackDeclaration playback;  ///< kPlayback only
  /// How the package's timed JOINT_SETPOINT / FRAME_SETPOINT commands join
  /// into each actuator's trajectory (docs/protocol.md, Trajectories); kStep
  /// is protocol 3's behaviour. Every package of a playback sequence says the same.
  Interpolation interpolation = Interpolation::kStep;
  /// How late after its start time a command may still begin:
  /// kMaxLateServerDefault, kMaxLateNever, or a limit (> 0).
  Duration max_late = kMaxLateServerDefault;
  /// The client's network round trip to the server, the median of its recent
  /// acknowledged packages' (0 = not measured yet); the server's link health
  /// reports it, and half of it as the one-way delay.
  Duration round_trip{0};
  std::vector<Query> queries;
  std::vector<Command> commands;  ///< kPlayback: start_time holds the offset (see command.h)
  std::vector<MalformedItem> malformed;
  /// Non-empty when the header is inconsistent with the payload (mixed
  /// payload, bad version, ...): every item is answered ERROR with it.
  std::string header_error;
  /// Keyed mode: the package's MAC (the last kMacBytes of its encoding); zeros in open mode.
  Mac mac{};
  /// Not on the wire: who sent it as the server's session gate names it, for
  /// logs ("'alice' (rt:..., client ...)"); empty = by client id.
  std::string sender;

  /// The ids of every item, queries first, as the package carried them.
  std::vector<CommandId> item_ids() const;
};

/// Decodes a REQUEST package. Per-item and header problems are reported in
/// the Request (malformed, header_error) so they can be answered; throws
/// ProtocolError only for bytes that carry no trustworthy client id
/// (truncated, hostile counts, another message type).
Request DecodeRequest(std::span<const std::uint8_t> bytes);
/// Encodes a request (the C++ client, tests). The payload type is COMMANDS
/// when it carries commands, else QUERIES (an empty package -- a heartbeat,
/// a panic -- is `PAYLOAD_QUERIES`, size 0, as docs/protocol.md says); the
/// playback fields are written in kPlayback only; `mac` goes in as given
/// (keyed mode: seal the bytes afterwards, see WriteMacField). Throws
/// ProtocolError for a start time whose kind does not belong in `mode`
/// (command.h, StartTime: offsets in kPlayback only) or a negative time.
std::vector<std::uint8_t> EncodeRequest(const Request& request);

/// Whether the package a ReplyBatch acknowledges belonged to a live session.
enum class SessionStatus : std::int8_t {
  kOk = 0,       ///< accepted in `session_id`
  kUnknown = 1,  ///< this server instance has no such session: nothing ran; say hello again
};

/// What the server did with the panic flag of the package a ReplyBatch
/// acknowledges: a dedicated answer, never inferred from another status.
enum class PanicStatus : std::int8_t {
  kNone = 0,     ///< the package carried no panic flag (or nothing is acknowledged)
  kTaken = 1,    ///< the server acted on it: the robot is in panic
  kRefused = 2,  ///< the server did not act on it; ReplyBatch::panic_refusal says why
};

/// Replies for one client (ROBOTALK/<robot>/REPLY/<client>).
struct ReplyBatch {
  std::int64_t client_id = 0;
  std::int64_t server_id = 0;   ///< the server instance (Announcement::server_id)
  std::int64_t session_id = 0;  ///< the session the replies belong to (kUnknown: the one refused)
  SessionStatus session_status = SessionStatus::kOk;
  std::int64_t ack_sequence = 0;           ///< the package this acknowledges; 0 = none
  PanicStatus panic = PanicStatus::kNone;  ///< what became of that package's panic flag
  std::string panic_refusal;               ///< kRefused: why (names the rule or the missing right)
  TimePoint server_receive{};              ///< when that package arrived (clock sync)
  TimePoint server_send{};
  std::vector<Reply> replies;
  /// Replies that did not decode (an unknown signal, a time out of range):
  /// the rest of the batch stands; their waiters see no reply.
  std::vector<MalformedItem> malformed;
  Mac mac{};  ///< keyed mode: the last kMacBytes of the encoding
};
std::vector<std::uint8_t> EncodeReplyBatch(const ReplyBatch& batch);
/// Throws ProtocolError on truncated, hostile or foreign bytes, another
/// protocol version, or an unknown session or panic status. A SESSION_UNKNOWN
/// package may carry a keyed server's signature suffix (broadcast_signature.h;
/// not verified here).
ReplyBatch DecodeReplyBatch(std::span<const std::uint8_t> bytes);

/// One served robot in an ANNOUNCE.
struct RobotAnnouncement {
  std::string name;
  std::string driver;
  std::uint64_t config_hash = 0;
  int total_dofs = 0;
  BaseType base_type = BaseType::kFixed;  ///< of its first root
  bool panic = false;
  int num_clients = 0;
};
/// ROBOTALK/ANNOUNCE.
struct Announcement {
  std::int64_t server_id = 0;
  TimePoint server_time{};
  Duration uptime{0};  ///< how long the server has been serving
  std::string url_hint;
  TrafficLayout traffic_layout = TrafficLayout::kSingle;
  bool keyed = false;  ///< clients must say hello with a key
  std::vector<RobotAnnouncement> robots;
};
std::vector<std::uint8_t> EncodeAnnouncement(const Announcement& announcement);

/// A broadcast state sample (ROBOTALK/<robot>/STATE) as bytes.
std::vector<std::uint8_t> EncodeStateSample(const StateSample& sample);
/// Bytes to a validated StateSample (what state_sample.h promises: counts,
/// finite values unless in panic, times; `expected_dofs` >= 0 also checks the
/// dof count).
/// Throws ProtocolError on truncated, hostile, foreign or invalid bytes. A
/// keyed server's signature suffix is skipped, not verified
/// (broadcast_signature.h).
StateSample DecodeStateSample(std::span<const std::uint8_t> bytes, int expected_dofs = -1);
/// Throws ProtocolError on truncated, hostile or foreign bytes, or more than
/// 1024 robots. A keyed server's signature suffix is skipped, not verified
/// (broadcast_signature.h).
Announcement DecodeAnnouncement(std::span<const std::uint8_t> bytes);

/// ROBOTALK/<robot>/HELLO: the first message of every session.
struct Hello {
  bool keyed = false;  ///< open mode: only body.client_id and body.client_nonce are meaningful
  ClientHello body;
};
/// ROBOTALK/<robot>/HELLO/<client>: the server's answer.
struct HelloAnswer {
  std::int64_t server_id = 0;   ///< the server instance
  std::int64_t session_id = 0;  ///< > 0: the session opened; 0: refused
  std::string refusal;          ///< why not, when session_id is 0
  bool keyed = false;           ///< open mode: only body.client_id and body.client_nonce are meaningful
  ServerAnswer body;
};
std::vector<std::uint8_t> EncodeHello(const Hello& hello);
/// Throws ProtocolError on truncated or foreign bytes, a bad version or client id 0.
Hello DecodeHello(std::span<const std::uint8_t> bytes);
std::vector<std::uint8_t> EncodeHelloAnswer(const HelloAnswer& answer);
/// Throws ProtocolError on truncated, hostile or foreign bytes.
HelloAnswer DecodeHelloAnswer(std::span<const std::uint8_t> bytes);

/// A REQUEST or REPLY package's MAC is the last kMacBytes of its encoding and
/// covers every byte before it. These read and write it in encoded bytes.
/// Throw ProtocolError when `bytes` is shorter than a MAC.
std::span<const std::uint8_t> MacCoveredBytes(std::span<const std::uint8_t> bytes);
Mac ReadMacField(std::span<const std::uint8_t> bytes);
void WriteMacField(std::span<std::uint8_t> bytes, const Mac& mac);

}  // namespace robotalk
