// Helpers the `robotalk` subcommands share: connecting with a fast, clear
// failure for a robot nobody offers, and JSON output.
#pragma once

#include "cli_commands.h"
#include "robotalk/channels.h"  // kAnnounceHeardWithin
#include "robotalk/robot_client.h"

#include <cstdint>
#include <functional>
#include <iosfwd>
#include <memory>
#include <optional>
#include <set>
#include <string>

namespace robotalk::cli {

/// Listens to ROBOTALK/ANNOUNCE on its own LCM instance and thread from
/// construction to destruction (which wakes and joins it at once). With a
/// `trusted_key` ("ed25519:<hex>", a keyed client's server) it counts only
/// announcements signed by that key: anyone can send an unsigned one, or
/// sign with a key of their own. It keeps at most kMaxListedRobots (1024) robot names.
///
/// Freshness (keyed, with `client_time`: the server time -> client time
/// conversion of a synchronised client): a signed announcement proves the
/// server was alive at its signed `server_time`, not when it arrives (a
/// captured one can be replayed later). It counts as heard at that time, and
/// one older than kAnnounceMaxAge on arrival, or stamped more than that
/// ahead (FreshAnnouncementTime), is refused as stale, counted (Stale()) and
/// said once on stderr.
/// Thread safety: Heard(), LastHeard() and Stale() may be called from any thread.
class AnnounceWatch {
 public:
  /// How old (by its signed server time) a keyed announcement may arrive:
  /// one announce period (1 s) and slack for the network and the clock sync
  /// (kAnnounceHeardWithin, channels.h).
  static constexpr Duration kAnnounceMaxAge = kAnnounceHeardWithin;

  explicit AnnounceWatch(const std::string& url, std::string trusted_key = "",
                         std::function<TimePoint(TimePoint server_time)> client_time = {});
  ~AnnounceWatch();
  AnnounceWatch(const AnnounceWatch&) = delete;
  AnnounceWatch& operator=(const AnnounceWatch&) = delete;
  /// Robot names heard so far, sorted.
  std::set<std::string> Heard() const;
  /// When `robot` was last announced (steady clock), or nullopt.
  std::optional<TimePoint> LastHeard(const std::string& robot) const;
  /// Signed announcements refused as stale (replayed, delayed, or stamped
  /// ahead by another clock).
  std::uint64_t Stale() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// Connects a client to `robot`. While connecting it listens to ANNOUNCE:
/// when the robot does not answer within ~1.2 s (servers announce once a
/// second) and no server announced it, it fails at once with ClientError
/// "no robot 'piooner' on this network (heard: pioneer)" instead of waiting
/// the whole --timeout. Throws TimeoutError / ClientError otherwise.
///
/// `clock`: kTimed syncs the clock in ClientOptions::clock_sync_rounds round
/// trips (commands with start times, the state stream); kUntimed in one
/// (describe, query, panic, reset never convert a time), so a one-shot
/// process connects in fewer round trips.
enum class ClockUse { kTimed, kUntimed };
std::unique_ptr<RobotClient> ConnectClient(const GlobalOptions& g, const std::string& robot,
                                           ClockUse clock = ClockUse::kTimed);

ClientOptions MakeOptions(const GlobalOptions& g);

/// Ends a one-shot command (describe, query, panic, reset) once its answer is
/// written: flushes stdout and stderr and leaves the process without tearing
/// the client down. The teardown (joining the client's thread and one LCM
/// receive thread per lane) costs the caller time and does nothing the exit
/// does not: the client sends nothing on close, the kernel closes the sockets.
[[noreturn]] void ExitAfterOutput(int status);

/// The --json outputs, each one line of JSON (JsonText: non-finite numbers
/// are null, strings that are not UTF-8 are repaired).
/// {"id":12,"signal":"SUCCESS","message":"","exec_time_us":..,"lateness_s":..,"values":[..]}
std::string ReplyJson(const Reply& r);
/// {"robot","sample","server_time_us","period_s","panic","moving","base":[x,y,θ,v,ω],
///  "position":[..],"velocity":[..],"effort":[..]}
std::string StateJson(const StateSample& s);
/// [{"name","driver","dofs","base","config_hash","panic","clients","server","server_key"}, ...]
std::string RobotsJson(const std::vector<AnnouncedRobot>& robots);

}  // namespace robotalk::cli
