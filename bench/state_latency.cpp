// robotalk-bench-state-latency: the latency of a robot's STATE stream on LCM,
// the floor the Foxglove endpoint's added latency is measured against
// (bench/foxglove_bench.sh, docs/performance.md "Foxglove endpoint"):
//   robotalk-bench-state-latency --url U --robot R [--seconds S]
// For S seconds (default 10), every STATE sample of R on its lane of U:
// arrival (CLOCK_MONOTONIC) minus the sample's server time (the server's
// steady clock: the same clock on one machine). Prints one JSON line:
// latency_us {n, p50, p99, mean, max}.
#include "bench_util.h"
#include "robotalk/channels.h"
#include "robotalk/request.h"
#include "robotalk/routed_lcm_transport.h"
#include "robotalk/traffic_layout.h"

#include <lcm/lcm-cpp.hpp>

#include <exception>

namespace {

using namespace robotalk::bench;

struct Latencies {
  std::vector<double> us;
};

void OnState(const lcm::ReceiveBuffer* rbuf, const std::string&, Latencies* l) {
  const std::int64_t now = MonoNs();
  try {
    const robotalk::StateSample s =
        robotalk::DecodeStateSample({static_cast<const std::uint8_t*>(rbuf->data), rbuf->data_size});
    l->us.push_back(static_cast<double>(now / 1000 - robotalk::ToWireMicros(s.server_time)));
  } catch (const std::exception&) {  // never through LCM's C code
  }
}

}  // namespace

int main(int argc, char** argv) {
  try {
    const Args a(argc, argv, 1);
    const std::string robot = a.Str("robot", "pioneer");
    const std::string channel = robotalk::StateChannel(robot);
    const robotalk::TrafficUrl t = robotalk::ParseTrafficUrl(robotalk::ResolveLcmUrl(a.Str("url", "")));
    const std::string url = t.layout == robotalk::TrafficLayout::kSingle
                                ? t.lcm_url
                                : robotalk::LaneUrl(t.lcm_url, robotalk::LaneOfChannel(channel));
    lcm::LCM lcm(url);
    if (!lcm.good()) throw std::runtime_error("cannot open LCM " + url);
    Latencies l;
    lcm.subscribeFunction(channel, &OnState, &l)->setQueueCapacity(10000);
    const std::int64_t end = MonoNs() + static_cast<std::int64_t>(a.Num("seconds", 10) * 1e9);
    while (MonoNs() < end) lcm.handleTimeout(100);
    PrintJson({Summary("latency_us", l.us)});
  } catch (const std::exception& e) {
    std::fprintf(stderr, "robotalk-bench-state-latency: %s\n", e.what());
    return 1;
  }
  return 0;
}
