// robotalk-bench-timer: the bare-timer floors of docs/performance.md.
//
//   robotalk-bench-timer sleeploop --count N [--period-us P] [--slack-ns S]
//       a clock_nanosleep(TIMER_ABSTIME) loop on a fixed grid; prints the
//       lateness of each wake-up after its deadline (us). --slack-ns 0 keeps
//       the default timer slack (50 us), 1 sets 1 ns (prctl PR_SET_TIMERSLACK).
//   robotalk-bench-timer burn --seconds S
//       a bounded busy loop: loads one core for S seconds.
// Each prints one JSON line on stdout.
#include "bench_util.h"

#include <sys/prctl.h>

using namespace robotalk::bench;

namespace {

int SleepLoop(const Args& a) {
  const long slack = a.Int("slack-ns", 0);
  if (slack > 0) prctl(PR_SET_TIMERSLACK, static_cast<unsigned long>(slack));
  const long count = a.Int("count", 2000);
  const std::int64_t period = a.Int("period-us", 1000) * 1000;
  std::vector<double> late_us;
  late_us.reserve(static_cast<std::size_t>(count));
  std::int64_t deadline = MonoNs() + 10 * period;
  for (long i = 0; i < count; ++i) {
    SleepUntilNs(deadline);
    late_us.push_back(static_cast<double>(MonoNs() - deadline) / 1e3);
    deadline += period;
  }
  // Wake-ups more than 1 ms late (issue 23, eleventh session: a playback frame's "late" is > 1 ms).
  const auto over_1ms = std::count_if(late_us.begin(), late_us.end(), [](double l) { return l > 1000.0; });
  PrintJson({Summary("lateness_us", late_us), Field("late_over_1ms", static_cast<double>(over_1ms)),
             Field("timer_slack_ns", static_cast<double>(prctl(PR_GET_TIMERSLACK)))});
  return 0;
}

int Burn(const Args& a) {
  const std::int64_t end = MonoNs() + static_cast<std::int64_t>(a.Num("seconds", 1) * 1e9);
  volatile std::uint64_t x = 1;
  std::uint64_t rounds = 0;
  while (MonoNs() < end) {
    for (int i = 0; i < 10000; ++i) x = x * 6364136223846793005ULL + 1442695040888963407ULL;
    ++rounds;
  }
  PrintJson({Field("rounds", static_cast<double>(rounds))});
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: %s sleeploop|burn [--key value ...]\n", argv[0]);
    return 2;
  }
  try {
    const std::string cmd = argv[1];
    const Args a(argc, argv, 2);
    if (cmd == "sleeploop") return SleepLoop(a);
    if (cmd == "burn") return Burn(a);
    std::fprintf(stderr, "robotalk-bench-timer: unknown sub-command '%s'\n", cmd.c_str());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "robotalk-bench-timer: %s\n", e.what());
    return 1;
  }
}
