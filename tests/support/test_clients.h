// The two clients and the instant the server and driver tests share, so a
// test names a client (kAlice, kBob) instead of spelling its id, and every
// manual clock starts at the same, arbitrary, non-zero time.
#pragma once

#include "robotalk/clock.h"

#include <chrono>
#include <cstdint>

namespace robotalk::testing {

inline constexpr std::int64_t kAlice = 0xA11CE, kBob = 0xB0B;
inline constexpr TimePoint kT0{std::chrono::seconds(1000)};

}  // namespace robotalk::testing
