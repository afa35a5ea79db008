// One libFuzzer target: compiled once per decoder with
// ROBOTALK_FUZZ_TARGET set to a function of fuzz_targets.h.
#include "fuzz_targets.h"

#include <cstddef>
#include <cstdint>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  robotalk::fuzz::ROBOTALK_FUZZ_TARGET({data, size});
  return 0;
}
