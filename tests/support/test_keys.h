// Deterministic identity keys for tests: the same seed, the same key pair.
#pragma once

#include "robotalk/keys.h"

#include <array>
#include <cstdint>

namespace robotalk::testing {

/// The key pair whose 32-byte seed is `seed` repeated.
inline KeyPair TestKey(std::uint8_t seed) {
  std::array<std::uint8_t, SecretKey::kSeedBytes> bytes{};
  bytes.fill(seed);
  return KeyPair::FromSeed(bytes);
}

}  // namespace robotalk::testing
