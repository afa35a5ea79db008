// robotalk-bench-raw's `sessions` sub-command (sessions_bench.cpp): K client
// sessions, idle or under an exhaustion load, for the memory figure.
#pragma once

#include "bench_util.h"

namespace robotalk::bench {

/// Runs the sub-command; prints one JSON line. Returns the exit status.
int Sessions(const Args& a);

}  // namespace robotalk::bench
