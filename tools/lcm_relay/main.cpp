// robotalk-lcm-relay: an LCM impairment relay between two URLs.
// See docs/lcm_relay.md and `robotalk-lcm-relay --help`.
#include <csignal>
#include <cstdio>
#include <exception>
#include <string>
#include <vector>

#include "lcm_relay.h"
#include "robotalk/log_writer.h"  // OpenStandardDescriptors

#ifndef ROBOTALK_VERSION
#define ROBOTALK_VERSION "unknown"
#endif

namespace {
robotalk::relay::LcmRelay* g_relay = nullptr;
extern "C" void OnSignal(int) {
  if (g_relay != nullptr) g_relay->RequestStop();  // one atomic store
}
}  // namespace

int main(int argc, char** argv) {
  robotalk::OpenStandardDescriptors();  // first: nothing of ours on descriptors 0-2
  using namespace robotalk::relay;
  RelayOptions options;
  try {
    options = ParseRelayOptions(std::vector<std::string>(argv + 1, argv + argc));
  } catch (const std::exception& e) {
    std::fprintf(stderr, "robotalk-lcm-relay: %s\n(see --help)\n", e.what());
    return 2;
  }
  if (options.help) {
    std::fputs(RelayUsage().c_str(), stdout);
    return 0;
  }
  if (options.version) {
    std::printf("robotalk-lcm-relay %s\n", ROBOTALK_VERSION);
    return 0;
  }
  try {
    LcmRelay relay(options);
    g_relay = &relay;
    std::signal(SIGINT, OnSignal);
    std::signal(SIGTERM, OnSignal);
    std::fprintf(stderr, "robotalk-lcm-relay: A=%s B=%s seed=%llu\n", options.url_a.c_str(),
                 options.url_b.c_str(), static_cast<unsigned long long>(options.seed));
    int status = 0;
    try {
      relay.Run();
    } catch (const std::exception& e) {
      std::fprintf(stderr, "robotalk-lcm-relay: %s\n", e.what());
      status = 1;
    }
    std::signal(SIGINT, SIG_DFL);
    std::signal(SIGTERM, SIG_DFL);
    g_relay = nullptr;
    if (options.stats) {
      std::fputs(FormatStats(relay.Stats()).c_str(), stdout);
      std::fflush(stdout);
    }
    return status;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "robotalk-lcm-relay: %s\n", e.what());
    return 1;
  }
}
