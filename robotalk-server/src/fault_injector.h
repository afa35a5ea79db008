// Seeded drop / duplicate decisions for test fault injection on a message stream.
#pragma once

#include <cstdint>
#include <random>

namespace robotalk {

class FaultInjector {
 public:
  FaultInjector(double drop_probability, double duplicate_probability, std::uint64_t seed)
      : drop_(drop_probability), duplicate_(duplicate_probability), rng_(seed) {}
  /// How many copies of the next message to send: 0 (dropped), 1 or 2.
  int Copies() {
    if (drop_ <= 0 && duplicate_ <= 0) return 1;
    if (uniform_(rng_) < drop_) return 0;
    return uniform_(rng_) < duplicate_ ? 2 : 1;
  }

 private:
  double drop_, duplicate_;
  std::mt19937_64 rng_;
  std::uniform_real_distribution<double> uniform_{0.0, 1.0};
};

}  // namespace robotalk
