// Command-line options of robotalk-lcm-relay, parsed without I/O so they can
// be tested. See docs/lcm_relay.md for the user's view.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "impaired_channel.h"
#include "queue_bound.h"

namespace robotalk::relay {

/// One direction: its impairments and which channels it forwards.
struct DirectionOptions {
  ImpairmentParams impairment;
  std::string channels = ".*";  ///< ECMAScript regex matched against the whole channel name
};

struct RelayOptions {
  std::string url_a;  ///< client side
  std::string url_b;  ///< server side
  DirectionOptions a2b;
  DirectionOptions b2a;
  std::uint64_t seed = 1;   ///< a2b uses seed, b2a a seed derived from it
  double duration_s = 0.0;  ///< 0: run until SIGINT/SIGTERM
  bool stats = false;       ///< print counters at exit
  Duration echo_window = std::chrono::seconds(2);
  QueueLimits queue;  ///< --max-queue, --max-queue-bytes: each direction's release queue
  bool help = false;
  bool version = false;  ///< --version: print it and exit
};

/// Parses argv[1..]. Unprefixed impairment options set both directions;
/// --a2b-X / --b2a-X set one and win over --X wherever they appear.
/// Throws std::invalid_argument naming the option and the bad value.
RelayOptions ParseRelayOptions(const std::vector<std::string>& args);

/// The impairments of a --profile: "wan" (100 ms +-50 ms uniform,
/// 1 % loss) or "wan-300" (300 ms +-50 ms, 1 % loss). Throws
/// std::invalid_argument naming an unknown profile.
ImpairmentParams RelayProfile(const std::string& name);

/// The --help text.
std::string RelayUsage();

/// Seed of the b2a channel: a splitmix64 step of `seed`, so both directions
/// are independent but fixed by the one --seed.
std::uint64_t DerivedSeed(std::uint64_t seed);

/// "udpm://239.255.76.67:7667?ttl=0" -> 7667 (7667 when no port); -1 if the
/// URL is not udpm.
int UdpmPort(const std::string& url);

/// The LCM URLs the relay listens and publishes on for RoboTalk URL `url`:
/// the 66 lanes of the split traffic layout (robotalk/traffic_layout.h), or
/// the one URL of the single layout (traffic=single, memq://). The traffic=
/// option is removed. Throws std::invalid_argument for a bad traffic= option.
std::vector<std::string> RelayLaneUrls(const std::string& url);

}  // namespace robotalk::relay
