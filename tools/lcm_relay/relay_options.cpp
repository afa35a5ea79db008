#include "relay_options.h"

#include <robotalk/error.h>
#include <robotalk/option_reader.h>
#include <robotalk/routed_lcm_transport.h>
#include <robotalk/sequence_file.h>  // NumberOf
#include <robotalk/traffic_layout.h>

#include <cmath>
#include <regex>
#include <set>
#include <stdexcept>

namespace robotalk::relay {
namespace {

[[noreturn]] void Bad(const std::string& option, const std::string& value, const std::string& why) {
  throw std::invalid_argument("ParseRelayOptions: " + option + " '" + value + "': " + why);
}

double ParseDouble(const std::string& option, const std::string& value) {
  const std::optional<double> x = NumberOf(value);  // the one rule of every number option
  if (!x) Bad(option, value, "not a number");
  if (!std::isfinite(*x)) Bad(option, value, "not a finite number");
  return *x;
}

double ParseProbability(const std::string& option, const std::string& value) {
  const double p = ParseDouble(option, value);
  if (p < 0.0 || p > 1.0) Bad(option, value, "must be a probability in [0, 1]");
  return p;
}

Duration ParseMillis(const std::string& option, const std::string& value) {
  const double ms = ParseDouble(option, value);
  if (ms < 0.0 || ms > 3.6e6) Bad(option, value, "must be milliseconds in [0, 3600000]");
  return FromSeconds(ms / 1000.0);
}

// A whole number in [1, 1e12] (a queue limit).
std::size_t ParseCount(const std::string& option, const std::string& value) {
  const double x = ParseDouble(option, value);
  if (x < 1 || x > 1e12 || x != std::floor(x)) Bad(option, value, "must be a whole number in [1, 1e12]");
  return static_cast<std::size_t>(x);
}

// Applies an impairment option (name without prefix) to one direction.
// Returns false if `name` is not an impairment option.
bool ApplyDirection(const std::string& option, const std::string& name, const std::string& value,
                    DirectionOptions& d) {
  ImpairmentParams& p = d.impairment;
  if (name == "latency-ms") {
    p.latency = ParseMillis(option, value);
  } else if (name == "jitter-ms") {
    p.jitter = ParseMillis(option, value);
  } else if (name == "jitter-dist") {
    if (value == "uniform") {
      p.jitter_distribution = JitterDistribution::kUniform;
    } else if (value == "normal") {
      p.jitter_distribution = JitterDistribution::kNormal;
    } else {
      Bad(option, value, "must be 'uniform' or 'normal'");
    }
  } else if (name == "loss") {
    p.loss = ParseProbability(option, value);
  } else if (name == "dup") {
    p.duplicate = ParseProbability(option, value);
  } else if (name == "reorder") {
    p.reorder = ParseProbability(option, value);
  } else if (name == "reorder-delay-ms") {
    p.reorder_delay = ParseMillis(option, value);
  } else if (name == "congestion-max-ms") {
    p.congestion_max = ParseMillis(option, value);
  } else if (name == "outage-at-ms") {
    p.outage_at = ParseMillis(option, value);
  } else if (name == "outage-ms") {
    p.outage = ParseMillis(option, value);
  } else if (name == "channels") {
    try {
      std::regex check(value);
    } catch (const std::regex_error& e) {
      Bad(option, value, std::string("not a valid regex: ") + e.what());
    }
    d.channels = value;
  } else {
    return false;
  }
  return true;
}

// Whether `name` (without "--") is an option that takes a value.
bool TakesValue(std::string name) {
  if (name.rfind("a2b-", 0) == 0 || name.rfind("b2a-", 0) == 0) name = name.substr(4);
  for (const char* known :
       {"a", "b", "seed", "duration", "echo-window-ms", "profile", "latency-ms", "jitter-ms", "jitter-dist",
        "loss", "dup", "reorder", "reorder-delay-ms", "congestion-max-ms", "outage-at-ms", "outage-ms",
        "channels", "max-queue", "max-queue-bytes"}) {
    if (name == known) return true;
  }
  return false;
}

}  // namespace

std::uint64_t DerivedSeed(std::uint64_t seed) {
  std::uint64_t z = seed + 0x9e3779b97f4a7c15ull;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return z ^ (z >> 31);
}

std::vector<std::string> RelayLaneUrls(const std::string& url) {
  try {
    const TrafficUrl parsed = ParseTrafficUrl(ResolveLcmUrl(url));
    if (parsed.layout == TrafficLayout::kSingle) return {parsed.lcm_url};
    std::vector<std::string> lanes;
    for (int lane = 0; lane < kLaneCount; ++lane) lanes.push_back(LaneUrl(parsed.lcm_url, lane));
    return lanes;
  } catch (const TransportError& e) {
    throw std::invalid_argument(std::string("robotalk-lcm-relay: ") + e.what());
  }
}

int UdpmPort(const std::string& url) {
  const std::string scheme = "udpm://";
  if (url.rfind(scheme, 0) != 0) return -1;
  const std::string rest = url.substr(scheme.size(), url.find('?') - scheme.size());
  const auto colon = rest.find(':');
  if (colon == std::string::npos) return 7667;
  try {
    return std::stoi(rest.substr(colon + 1));
  } catch (const std::exception&) {
    return -1;
  }
}

ImpairmentParams RelayProfile(const std::string& name) {
  ImpairmentParams p;
  if (name == "wan" || name == "wan-300") {
    // Issue 23: a WAN-like path, 100-300 ms of delay with +-50 ms of jitter
    // and 1 % loss; "wan" is its short end, "wan-300" its long end.
    p.latency = std::chrono::milliseconds(name == "wan" ? 100 : 300);
    p.jitter = std::chrono::milliseconds(50);
    p.jitter_distribution = JitterDistribution::kUniform;
    p.loss = 0.01;
  } else {
    throw std::invalid_argument("ParseRelayOptions: --profile '" + name + "': expected wan or wan-300");
  }
  return p;
}

RelayOptions ParseRelayOptions(const std::vector<std::string>& args) {
  RelayOptions o;
  // Pass 1 splits "--opt=value" / "--opt value"; pass 2 applies unprefixed
  // options, pass 3 the per-direction ones, so those win in any order.
  struct Item {
    std::string option, value;
  };
  std::vector<Item> items;
  try {  // the reader's UsageError as this function's invalid_argument, as Bad's
    OptionReader r(args);
    while (r.Next()) {
      const std::string& arg = r.word();
      if (r.IsHelp()) {
        o.help = true;
        return o;
      }
      if (r.IsVersion()) {
        o.version = true;
        return o;
      }
      if (arg == "--stats") {
        o.stats = true;
        continue;
      }
      if (arg.rfind("--", 0) != 0) Bad(arg, "", "unexpected argument (options start with --)");
      const auto eq = arg.find('=');
      if (eq != std::string::npos) {
        if (!TakesValue(arg.substr(2, eq - 2))) ThrowUnknownOption(arg.substr(0, eq));  // without its value
        items.push_back({arg.substr(0, eq), arg.substr(eq + 1)});
      } else {
        if (!TakesValue(arg.substr(2))) r.Unknown();
        items.push_back({arg, r.Value()});
      }
    }
  } catch (const UsageError& e) {
    throw std::invalid_argument(e.what());  // the words every tool says
  }
  // A profile first: every other impairment option overrides its part.
  for (const auto& [option, value] : items) {
    if (option != "--profile") continue;
    const ImpairmentParams profile = RelayProfile(value);
    o.a2b.impairment = profile;
    o.b2a.impairment = profile;
  }
  for (const auto& [option, value] : items) {
    const std::string name = option.substr(2);
    if (name.rfind("a2b-", 0) == 0 || name.rfind("b2a-", 0) == 0) continue;
    if (name == "profile") continue;  // applied above
    if (name == "a") {
      o.url_a = value;
    } else if (name == "b") {
      o.url_b = value;
    } else if (name == "seed") {
      try {
        std::size_t used = 0;
        if (value.empty() || value[0] < '0' || value[0] > '9') throw std::invalid_argument("sign");
        o.seed = std::stoull(value, &used);
        if (used != value.size()) throw std::invalid_argument("trailing");
      } catch (const std::exception&) {
        Bad(option, value, "not an unsigned integer");
      }
    } else if (name == "duration") {
      o.duration_s = ParseDouble(option, value);
      if (o.duration_s < 0) Bad(option, value, "must be seconds >= 0");
    } else if (name == "echo-window-ms") {
      o.echo_window = ParseMillis(option, value);
    } else if (name == "max-queue") {
      o.queue.max_messages = ParseCount(option, value);
    } else if (name == "max-queue-bytes") {
      o.queue.max_bytes = ParseCount(option, value);
    } else {
      if (!ApplyDirection(option, name, value, o.a2b)) Bad(option, value, "unknown option (see --help)");
      ApplyDirection(option, name, value, o.b2a);
    }
  }
  for (const auto& [option, value] : items) {
    const std::string name = option.substr(2);
    const bool a2b = name.rfind("a2b-", 0) == 0;
    if (!a2b && name.rfind("b2a-", 0) != 0) continue;
    if (!ApplyDirection(option, name.substr(4), value, a2b ? o.a2b : o.b2a)) {
      Bad(option, value, "unknown option (see --help)");
    }
  }
  if (o.url_a.empty() || o.url_b.empty()) Bad("--a/--b", o.url_a + "' '" + o.url_b, "both URLs are required");
  if (o.url_a == o.url_b) Bad("--b", o.url_b, "must differ from --a (the relay would hear its own output)");
  // Linux delivers multicast to every socket bound to the port whose host
  // joined the group (IP_MULTICAST_ALL), and LCM binds INADDR_ANY:port, so
  // two groups on one port would hear each other: no port of A's lanes may
  // be one of B's.
  std::set<int> ports_a;
  for (const std::string& url : RelayLaneUrls(o.url_a)) ports_a.insert(UdpmPort(url));
  ports_a.erase(-1);
  for (const std::string& url : RelayLaneUrls(o.url_b)) {
    if (ports_a.count(UdpmPort(url))) {
      Bad("--b", o.url_b,
          "uses udpm port " + std::to_string(UdpmPort(url)) +
              ", a port of --a too (same-port groups cross-talk on Linux; the split traffic layout uses "
              "66 ports from each URL's port)");
    }
  }
  return o;
}

std::string RelayUsage() {
  return R"(usage: robotalk-lcm-relay --a URL --b URL [options]

Forwards every LCM message between side A (client side) and side B (server
side), both ways, through a seeded impaired channel per direction.

  --a URL, --b URL        the two LCM URLs; udpm URLs must use different ports
  --seed N                random seed (default 1); same seed, same schedule
  --duration S            stop after S seconds (default 0: until SIGINT/SIGTERM)
  --stats                 print per-direction counters at exit
  --echo-window-ms MS     how long to recognise our own publications (default 2000)
  --max-queue N           messages each direction holds for release at most (default
                          65536); one more is dropped on arrival, counted (queue_dropped)
  --max-queue-bytes B     the same in bytes (default 67108864, 64 MiB)
  --version               the version

  --profile NAME          preset impairments of both directions, which the options
                          below override: wan (100 ms +-50 ms uniform, 1 % loss),
                          wan-300 (300 ms +-50 ms uniform, 1 % loss)

Impairments (set both directions; --a2b-NAME / --b2a-NAME set one and win):
  --latency-ms MS         fixed delay
  --jitter-ms MS          jitter: half-width (uniform) or sigma (normal, clamped at 3 sigma)
  --jitter-dist D         uniform (default) or normal; delay = max(0, latency + jitter)
  --loss P                loss probability
  --dup P                 duplication probability (the copy gets its own delay)
  --reorder P             probability a copy is held back by --reorder-delay-ms
  --reorder-delay-ms MS   extra delay of a held-back copy
  --congestion-max-ms X   congested link: a single-server FIFO holding each
                          message U[0, X] ms before the next may pass
  --outage-at-ms MS, --outage-ms MS
                          an outage: messages arriving from MS after the first
                          one, for MS, are held and then released at once
  --channels REGEX        forward only channels fully matching REGEX (default .*)

Example: --a udpm://239.255.76.67:7667?ttl=0 --b udpm://239.255.76.67:7767?ttl=0
         --a2b-congestion-max-ms 250 --latency-ms 5 --seed 7 --stats
)";
}

}  // namespace robotalk::relay
