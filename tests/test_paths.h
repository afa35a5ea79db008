// Where tests find robot descriptions. Shared robots live outside the project
// (../shared/robots); a clone without them skips those tests.
#pragma once

#include <gtest/gtest.h>

#include <filesystem>
#include <string>

namespace robotalk::testing {

inline std::string SharedRobot(const std::string& file) {
  return std::string(ROBOTALK_SHARED_ROBOTS) + "/" + file;
}
inline std::string ProjectModel(const std::string& file) {
  return std::string(ROBOTALK_MODELS_DIR) + "/" + file;
}
inline bool HaveSharedRobots() { return std::filesystem::is_directory(ROBOTALK_SHARED_ROBOTS); }

}  // namespace robotalk::testing

/// Skips the current test when ../shared/robots is absent (a user's clone).
#define ROBOTALK_REQUIRE_SHARED_ROBOTS()                                                \
  do {                                                                                  \
    if (!::robotalk::testing::HaveSharedRobots())                                       \
      GTEST_SKIP() << "shared robot descriptions not found at " ROBOTALK_SHARED_ROBOTS; \
  } while (0)
