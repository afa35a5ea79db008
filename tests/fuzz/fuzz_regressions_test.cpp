// Replays every input under tests/fuzz/regressions/<target>/ (crashes the
// fuzzers found, kept after the fix, and the hostile edits of valid messages
// that make_regressions.py writes: truncations, counts and string lengths of
// 0, -1 and 2^31-1, NaN, infinity) through the decoders of fuzz_targets.h in
// the regular build: each must decode or be refused with a robotalk::Error,
// never crash or throw another exception. Every target has inputs (a folder
// without any fails; none is skipped), and the inputs of the LCM targets
// carry the messages' current fingerprints, so a layout change that would
// leave them stopping at the fingerprint fails here until they are
// regenerated. Under scripts/sanitize.sh asan the same replay runs sanitized.
#include "fuzz_targets.h"
#include "robotalk_msgs/announce_t.hpp"
#include "robotalk_msgs/hello_answer_t.hpp"
#include "robotalk_msgs/hello_t.hpp"
#include "robotalk_msgs/package_t.hpp"
#include "robotalk_msgs/reply_package_t.hpp"
#include "robotalk_msgs/robot_config_t.hpp"
#include "robotalk_msgs/robot_state_t.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <map>

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

// The regression inputs of a target (README.md files aside).
std::map<std::string, std::vector<std::uint8_t>> Inputs(const std::string& target) {
  const fs::path dir = fs::path(ROBOTALK_FUZZ_REGRESSIONS) / target;
  std::map<std::string, std::vector<std::uint8_t>> inputs;
  if (!fs::is_directory(dir)) return inputs;
  for (const auto& entry : fs::directory_iterator(dir)) {
    if (entry.is_regular_file() && entry.path().extension() != ".md")
      inputs[entry.path().filename().string()] = Read(entry.path());
  }
  return inputs;
}

void ReplayFolder(const std::string& target) {
  const auto inputs = Inputs(target);
  ASSERT_GE(inputs.size(), 5u) << "tests/fuzz/regressions/" << target
                               << "/ needs its inputs (tests/fuzz/make_regressions.py)";
  for (const auto& [name, bytes] : inputs) {
    SCOPED_TRACE(target + "/" + name);
    EXPECT_NO_THROW(Find(target).run(bytes));
  }
  std::cout << "replayed " << inputs.size() << " input(s) for " << target << "\n";
}

TEST(FuzzRegressions, PackageInputsDecodeOrAreRefused) { ReplayFolder("package"); }
TEST(FuzzRegressions, ReplyPackageInputsDecodeOrAreRefused) { ReplayFolder("reply_package"); }
TEST(FuzzRegressions, RobotStateInputsDecodeOrAreRefused) { ReplayFolder("robot_state"); }
TEST(FuzzRegressions, ConfigInputsDecodeOrAreRefused) { ReplayFolder("config"); }
TEST(FuzzRegressions, UrdfInputsImportOrAreRefused) { ReplayFolder("urdf"); }
// regressions/announce/README.md: fixed by the checked DecodeAnnouncement.
TEST(FuzzRegressions, AnnounceInputsDecodeOrAreDropped) { ReplayFolder("announce"); }
TEST(FuzzRegressions, HelloInputsDecodeOrAreRefused) { ReplayFolder("hello"); }
TEST(FuzzRegressions, HelloAnswerInputsDecodeOrAreRefused) { ReplayFolder("hello_answer"); }

TEST(FuzzRegressions, EveryTargetHasRegressionInputs) {
  for (const Target& t : Targets()) EXPECT_GE(Inputs(t.name).size(), 5u) << t.name;
}

TEST(FuzzRegressions, InputsCarryTheCurrentFingerprintsSoTheyReachTheDecoders) {
  const std::map<std::string, std::int64_t> fingerprints = {
      {"package", robotalk_msgs::package_t::getHash()},
      {"reply_package", robotalk_msgs::reply_package_t::getHash()},
      {"robot_state", robotalk_msgs::robot_state_t::getHash()},
      {"config", robotalk_msgs::robot_config_t::getHash()},
      {"announce", robotalk_msgs::announce_t::getHash()},
      {"hello", robotalk_msgs::hello_t::getHash()},
      {"hello_answer", robotalk_msgs::hello_answer_t::getHash()},
  };
  for (const auto& [target, hash] : fingerprints) {
    std::vector<std::uint8_t> expected(8);
    for (int i = 0; i < 8; ++i)
      expected[static_cast<std::size_t>(i)] =
          static_cast<std::uint8_t>(static_cast<std::uint64_t>(hash) >> (56 - 8 * i));
    std::size_t current = 0;
    const auto inputs = Inputs(target);
    for (const auto& [name, bytes] : inputs) {
      if (bytes.size() >= 8 && std::equal(expected.begin(), expected.end(), bytes.begin())) ++current;
    }
    // A deliberately wrong fingerprint, or a crash input kept from an older layout, may stay.
    EXPECT_GE(current + 2, inputs.size()) << target << ": " << inputs.size() - current
                                          << " inputs stop at an old fingerprint: regenerate them with "
                                             "tests/fuzz/make_regressions.py";
  }
}

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
