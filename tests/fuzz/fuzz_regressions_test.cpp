// Replays every input under tests/fuzz/regressions/<target>/ (crashes the
// fuzzers found, kept after the fix) and a few hand-made hostile inputs
// through the decoders of fuzz_targets.h in the regular build: each must
// decode or be refused with a robotalk::Error, never crash or throw another
// exception. Under scripts/sanitize.sh asan the same replay runs sanitized.
#include "fuzz_targets.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

namespace robotalk::fuzz {
namespace {

namespace fs = std::filesystem;

std::vector<std::uint8_t> Read(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

const Target& Find(const std::string& name) {
  for (const Target& t : Targets()) {
    if (name == t.name) return t;
  }
  throw std::invalid_argument("no fuzz target '" + name + "'");
}

void ReplayFolder(const std::string& target) {
  const fs::path dir = fs::path(ROBOTALK_FUZZ_REGRESSIONS) / target;
  if (!fs::exists(dir)) GTEST_SKIP() << "no regression inputs for " << target;
  int replayed = 0;
  for (const auto& entry : fs::directory_iterator(dir)) {
    if (!entry.is_regular_file() || entry.path().extension() == ".md") continue;
    SCOPED_TRACE(entry.path().string());
    const std::vector<std::uint8_t> bytes = Read(entry.path());
    EXPECT_NO_THROW(Find(target).run(bytes));
    ++replayed;
  }
  std::cout << "replayed " << replayed << " input(s) for " << target << "\n";
}

TEST(FuzzRegressions, PackageInputsDecodeOrAreRefused) { ReplayFolder("package"); }
TEST(FuzzRegressions, ReplyPackageInputsDecodeOrAreRefused) { ReplayFolder("reply_package"); }
TEST(FuzzRegressions, RobotStateInputsDecodeOrAreRefused) { ReplayFolder("robot_state"); }
TEST(FuzzRegressions, ConfigInputsDecodeOrAreRefused) { ReplayFolder("config"); }
TEST(FuzzRegressions, UrdfInputsImportOrAreRefused) { ReplayFolder("urdf"); }
// regressions/announce/README.md: fixed by the checked DecodeAnnouncement.
TEST(FuzzRegressions, AnnounceInputsDecodeOrAreDropped) { ReplayFolder("announce"); }

TEST(FuzzRegressions, EveryTargetSurvivesEmptyAndShortInputs) {
  for (const Target& t : Targets()) {
    SCOPED_TRACE(t.name);
    for (std::size_t n = 0; n <= 16; ++n) {
      const std::vector<std::uint8_t> zeros(n, 0), ones(n, 0xff);
      EXPECT_NO_THROW(t.run(zeros));
      EXPECT_NO_THROW(t.run(ones));
    }
  }
}

}  // namespace
}  // namespace robotalk::fuzz
