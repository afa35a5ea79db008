// SessionLog: what an LCM log of a RoboTalk session says, decoded with the
// project's message layer (robotalk/request.h; channels parsed by
// robotalk/channels.h) and de-duplicated: robots and servers (ANNOUNCE), each
// client's hellos (HELLO, and the answers refusing them), its command stream
// (REQUEST packages, one copy per (client, sequence): retransmissions are
// counted, not repeated), the final replies (REPLY/<client>) and the
// broadcast state (STATE).
//
// It is pure: events go in through Add() (ReadLog feeds it from
// LcmLogReader), so tests build logs in memory. Undecodable messages on
// RoboTalk channels are counted, never thrown; a package or reply package
// with an item that does not decode, or an inconsistent header, is
// undecodable as a whole (nothing of it is kept). So is a hostile entry:
// a log timestamp, or a PLAYBACK reply's start, that is not a finite wire
// time (|t| <= kMaxWireMicros). rejected() names each such entry (event,
// channel, field); with every kept time a wire time, the timeline's
// arithmetic cannot overflow.
//
// Recovering a client's timing (Timeline): every command is placed on the
// SERVER clock, whatever mode it was sent in:
//   - direct / delay with a start time: the start time itself;
//   - playback: the sequence start the server chose (its PLAYBACK reply,
//     values[1]) + the frame's offset;
//   - "now" (start time 0): the package's send time + the client's clock
//     offset, estimated from the acknowledgements in the log as
//     min(server_receive_us - send_time_us);
// and offsets are the times minus the earliest one. Without replies in the
// log, one client's stream still has one clock (its start times, offsets or
// send times); only mixing those then fails, naming the client.
//
// Thread safety: none (a value type).
#pragma once

#include "robotalk/command.h"
#include "robotalk/error.h"
#include "robotalk/request.h"

#include <cstdint>
#include <map>
#include <optional>
#include <set>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace robotalk::logplay {

/// A log's texts are anyone's bytes: shown in printable ASCII, every other
/// byte as \xNN (EscapeControls' ascii_only: a terminal escape never reaches
/// a terminal; Python's log_info never meets a string that is not UTF-8).
/// RoboTalk's channels and robot names are printable ASCII, unchanged.
std::string Printable(std::string_view text);

/// A log that cannot be used as asked (no such client, mixed clocks ...).
class LogError : public Error {
 public:
  using Error::Error;
};

struct ChannelStats {
  std::uint64_t messages = 0;
  std::uint64_t bytes = 0;
  std::int64_t first_us = 0, last_us = 0;  ///< logger clock (µs since the UNIX epoch)
  std::uint64_t undecodable = 0;           ///< not decoded or rejected (SessionLog::rejected() says why)
  std::uint64_t timed = 0;                 ///< with a usable log timestamp (first_us, last_us are theirs)
};

struct LoggedRobot {
  std::string name, driver;
  std::int64_t server_id = 0;
  std::uint64_t config_hash = 0;
  int total_dofs = 0;
  bool panic_seen = false;
};

/// One command as the server received it (first copy).
struct LoggedCommand {
  std::int64_t client_id = 0;
  std::string robot;
  std::int64_t sequence = 0;
  bool panic = false;  ///< a panic package's marker: no command, never replayed
  RequestMode mode = RequestMode::kDirect;
  std::int64_t playback_id = 0;
  Interpolation interpolation = Interpolation::kStep;  ///< its package's (replayed with it)
  Command command;                ///< start_time as sent: Now, At (server clock), After (playback offset)
  std::int64_t start_us = 0;      ///< the same in micros (0 = now)
  std::int64_t send_time_us = 0;  ///< client clock
  std::int64_t log_time_us = 0;   ///< logger clock, first copy
  std::optional<Reply> reply;     ///< the final reply, when logged
};

struct LoggedClient {
  std::int64_t id = 0;
  std::string robot;
  std::uint64_t packages = 0, retransmissions = 0, heartbeats = 0, queries = 0, panics = 0;
  std::uint64_t hellos = 0, hellos_refused = 0;  ///< HELLOs sent; answers opening no session
  std::set<RequestMode> modes;                   ///< of its command packages
  std::int64_t first_log_us = 0, last_log_us = 0;
  /// server - client clock (µs), from acknowledgements; nullopt without replies.
  std::optional<std::int64_t> clock_offset_us;
  std::map<std::int64_t, std::int64_t> playback_start_us;  ///< playback id -> server start
};

struct StateSample {
  std::string robot;
  std::int64_t log_time_us = 0, server_time_us = 0;
  bool panic = false, moving = false;
  std::vector<double> base;  ///< x y θ v ω
  std::vector<double> position;
};

/// A command with its place on the recovered timeline.
struct TimedFrame {
  double offset_s = 0;   ///< seconds after the first selected command
  std::int64_t time_us;  ///< on the clock `clock` names
  const LoggedCommand* source = nullptr;
};

struct Timeline {
  std::vector<TimedFrame> frames;    ///< in time order (ties: arrival order)
  std::string clock;                 ///< "server", "start times", "playback offsets", "client send times"
  std::vector<std::string> skipped;  ///< PANIC_RESETs and panics not replayed, with why
};

/// Which commands to take: one client, or every client of one robot.
struct Selection {
  std::optional<std::int64_t> client_id;
  std::string robot;
};

class SessionLog {
 public:
  /// One log event. `bytes` is the message; `log_time_us` the logger's timestamp.
  void Add(const std::string& channel, std::int64_t log_time_us, std::span<const std::uint8_t> bytes);
  /// A damaged stretch of the log file (LcmLogReader::damage()): counted and
  /// kept with the rejected entries, so every command that reads the log says it.
  void AddDamage(const std::string& what);

  const std::map<std::string, ChannelStats>& channels() const { return channels_; }
  /// Robots heard in ANNOUNCE, one per (server, name), sorted by name.
  std::vector<LoggedRobot> robots() const;
  std::set<std::int64_t> servers() const;
  const std::map<std::int64_t, LoggedClient>& clients() const { return clients_; }
  /// Commands in arrival order (first copies).
  const std::vector<LoggedCommand>& commands() const { return commands_; }
  const std::vector<StateSample>& states() const { return states_; }
  std::int64_t first_us() const { return first_us_; }
  std::int64_t last_us() const { return last_us_; }
  std::uint64_t events() const { return events_; }
  /// Why entries were not used (each names the event, its channel and the
  /// field): the first kKeptRejections of them; rejections() counts all.
  const std::vector<std::string>& rejected() const { return rejected_; }
  std::uint64_t rejections() const { return rejections_; }
  static constexpr std::size_t kKeptRejections = 20;

  /// The selected commands on one clock (see the file comment). Throws
  /// LogError when nothing matches or the clocks cannot be joined.
  Timeline MakeTimeline(const Selection& selection) const;

 private:
  LoggedClient& Client(std::int64_t id, const std::string& robot, std::int64_t log_time_us);
  void AddRequest(const std::string& robot, std::int64_t log_time_us, std::span<const std::uint8_t> bytes);
  void AddReply(std::span<const std::uint8_t> bytes);
  void AddHelloAnswer(std::span<const std::uint8_t> bytes);
  void AddAnnounce(std::span<const std::uint8_t> bytes);
  void AddState(std::int64_t log_time_us, std::span<const std::uint8_t> bytes);
  std::optional<std::int64_t> ServerTime(const LoggedCommand& c) const;

  std::map<std::string, ChannelStats> channels_;
  std::uint64_t request_messages_ = 0;  // on REQUEST channels, decodable or not
  bool split_layout_seen_ = false;      // a server announced TrafficLayout::kSplit
  std::map<std::pair<std::int64_t, std::string>, LoggedRobot> robots_;  // (server, name)
  std::map<std::int64_t, LoggedClient> clients_;
  std::vector<LoggedCommand> commands_;
  std::map<std::pair<std::int64_t, std::int64_t>, std::size_t> command_index_;     // (client, id)
  std::map<std::pair<std::int64_t, std::int64_t>, std::int64_t> package_send_us_;  // (client, seq)
  std::set<std::pair<std::int64_t, std::int64_t>> playback_ids_;                   // (client, playback id)
  std::vector<StateSample> states_;
  std::int64_t first_us_ = 0, last_us_ = 0;  // over the events with a usable log timestamp
  std::uint64_t events_ = 0, timed_events_ = 0;
  std::vector<std::string> rejected_;
  std::uint64_t rejections_ = 0;
};

/// Parses a client id as printed (16 hex digits) or in decimal; throws LogError.
std::int64_t ParseClientId(const std::string& text);

}  // namespace robotalk::logplay
