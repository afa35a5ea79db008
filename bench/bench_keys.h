// A deterministic identity key for the in-process benches (auth_bench,
// flood_bench): every byte of the seed `v`.
#pragma once

#include "robotalk/keys.h"

#include <array>
#include <cstdint>

namespace robotalk::bench {

inline KeyPair Identity(std::uint8_t v) {
  std::array<std::uint8_t, 32> seed{};
  seed.fill(v);
  return KeyPair::FromSeed(seed);
}

}  // namespace robotalk::bench
