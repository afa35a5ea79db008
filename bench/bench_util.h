// Small helpers shared by the multi-process bench programs (not a library):
// argument parsing, sample summaries as one JSON line (JsonText), the
// monotonic clock.
// Everything here is single-threaded unless a function says otherwise.
#pragma once

#include "json_text.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <map>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace robotalk::bench {

/// CLOCK_MONOTONIC in nanoseconds (the clock steady_clock and the server use).
inline std::int64_t MonoNs() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return std::int64_t{ts.tv_sec} * 1000000000 + ts.tv_nsec;
}

/// "--key value" pairs after the sub-command; a flag without a value is "1".
class Args {
 public:
  Args(int argc, char** argv, int first) {
    for (int i = first; i < argc; ++i) {
      std::string k = argv[i];
      if (k.rfind("--", 0) != 0) throw std::invalid_argument("unexpected argument '" + k + "'");
      k = k.substr(2);
      if (i + 1 < argc && std::string(argv[i + 1]).rfind("--", 0) != 0) {
        values_[k] = argv[++i];
      } else {
        values_[k] = "1";
      }
    }
  }
  std::string Str(const std::string& k, const std::string& def) const {
    auto it = values_.find(k);
    return it == values_.end() ? def : it->second;
  }
  double Num(const std::string& k, double def) const {
    auto it = values_.find(k);
    return it == values_.end() ? def : std::stod(it->second);
  }
  long Int(const std::string& k, long def) const {
    return static_cast<long>(Num(k, static_cast<double>(def)));
  }

 private:
  std::map<std::string, std::string> values_;
};

/// Nearest-rank percentile (q in [0, 1]) of `v`; 0 for an empty set. Sorts `v`.
inline double Percentile(std::vector<double>& v, double q) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  const auto rank = static_cast<std::size_t>(std::ceil(q * static_cast<double>(v.size())));
  return v[std::min(v.size() - 1, rank == 0 ? 0 : rank - 1)];
}

/// A bench's output is one JSON object per line, written by JsonText
/// (tools/describe/json_text.h), as every JSON the project writes.
using Json = nlohmann::ordered_json;
/// One named figure of that object.
using Field = std::pair<std::string, Json>;

/// `name: {"n", "p50", "p99", "mean", "max"}` of `v`, in the samples' own unit.
inline Field Summary(const std::string& name, std::vector<double> v) {
  double sum = 0;
  for (double x : v) sum += x;
  const double p50 = Percentile(v, 0.5), p99 = Percentile(v, 0.99);
  return {name, Json{{"n", v.size()},
                     {"p50", p50},
                     {"p99", p99},
                     {"mean", v.empty() ? 0.0 : sum / static_cast<double>(v.size())},
                     {"max", v.empty() ? 0.0 : v.back()}}};
}

/// Prints `{fields...}` as one line on stdout and flushes.
inline void PrintJson(const std::vector<Field>& fields) {
  Json object = Json::object();
  for (const auto& [name, value] : fields) object[name] = value;
  std::printf("%s\n", JsonText(object).c_str());
  std::fflush(stdout);
}

/// Sleeps until the absolute CLOCK_MONOTONIC time `ns`.
inline void SleepUntilNs(std::int64_t ns) {
  timespec ts{.tv_sec = ns / 1000000000, .tv_nsec = ns % 1000000000};
  while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) != 0) {
  }
}

}  // namespace robotalk::bench
