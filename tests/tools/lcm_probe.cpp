// lcm_probe: a tiny raw-bytes LCM publisher / counter for the relay's CLI test.
//   lcm_probe send URL CHANNEL N INTERVAL_MS
//       publishes N messages (16 bytes: sequence, steady-clock send time in ns)
//       at absolute deadlines INTERVAL_MS apart.
//   lcm_probe recv URL CHANNEL SECONDS
//       counts messages on exactly CHANNEL for SECONDS and prints one line:
//       count= unique= duplicates= out_of_order= min_ms= mean_ms= max_ms= seqs=
//       (seqs: a hash of the set of sequence numbers received)
//       (latency = receive - send on CLOCK_MONOTONIC, shared by all processes).
#include <poll.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <set>
#include <string>
#include <thread>

#include <lcm/lcm-cpp.hpp>

namespace {

std::int64_t NowNs() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

struct Counter {
  std::string channel;
  long count = 0, out_of_order = 0;
  std::int64_t last_seq = -1;
  std::set<std::int64_t> seen;
  double min_ms = 1e300, max_ms = 0, sum_ms = 0;

  void On(const lcm::ReceiveBuffer* rbuf, const std::string& ch) {
    if (ch != channel || rbuf->data_size != 16) return;
    std::int64_t seq = 0, sent = 0;
    std::memcpy(&seq, rbuf->data, 8);
    std::memcpy(&sent, static_cast<const char*>(rbuf->data) + 8, 8);
    const double ms = static_cast<double>(NowNs() - sent) / 1e6;
    ++count;
    if (seq < last_seq) ++out_of_order;
    last_seq = std::max(last_seq, seq);
    seen.insert(seq);
    min_ms = std::min(min_ms, ms);
    max_ms = std::max(max_ms, ms);
    sum_ms += ms;
  }
};

int Usage() {
  std::fprintf(stderr,
               "usage: lcm_probe send URL CHANNEL N INTERVAL_MS\n"
               "       lcm_probe recv URL CHANNEL SECONDS\n");
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 5 && argc != 6) return Usage();
  const std::string mode = argv[1];
  lcm::LCM lcm(argv[2]);
  if (!lcm.good()) {
    std::fprintf(stderr, "lcm_probe: cannot open %s\n", argv[2]);
    return 1;
  }
  const std::string channel = argv[3];
  if (mode == "send" && argc == 6) {
    const long n = std::atol(argv[4]);
    const auto interval = std::chrono::microseconds(static_cast<long>(std::atof(argv[5]) * 1000));
    auto next = std::chrono::steady_clock::now();
    for (std::int64_t seq = 0; seq < n; ++seq) {
      std::this_thread::sleep_until(next);
      char buf[16];
      const std::int64_t now = NowNs();
      std::memcpy(buf, &seq, 8);
      std::memcpy(buf + 8, &now, 8);
      if (lcm.publish(channel, buf, sizeof buf) != 0) return 1;
      next += interval;
    }
    return 0;
  }
  if (mode == "recv" && argc == 5) {
    Counter c;
    c.channel = channel;
    lcm.subscribe(channel, &Counter::On, &c);
    const auto end = std::chrono::steady_clock::now() + std::chrono::milliseconds(std::atol(argv[4]) * 1000);
    pollfd fd{lcm.getFileno(), POLLIN, 0};
    while (std::chrono::steady_clock::now() < end) {
      if (::poll(&fd, 1, 20) > 0) lcm.handleTimeout(0);
    }
    const long unique = static_cast<long>(c.seen.size());
    std::uint64_t seqs = 14695981039346656037ull;  // FNV-1a over the sorted set
    for (std::int64_t seq : c.seen) seqs = (seqs ^ static_cast<std::uint64_t>(seq)) * 1099511628211ull;
    std::printf(
        "count=%ld unique=%ld duplicates=%ld out_of_order=%ld min_ms=%.3f mean_ms=%.3f max_ms=%.3f "
        "seqs=%016llx\n",
        c.count, unique, c.count - unique, c.out_of_order, c.count ? c.min_ms : 0.0,
        c.count ? c.sum_ms / static_cast<double>(c.count) : 0.0, c.max_ms,
        static_cast<unsigned long long>(seqs));
    return 0;
  }
  return Usage();
}
