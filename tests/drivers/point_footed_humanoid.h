// Synthetic humanoids for the sole tests (issue 26, item 5):
// models/simple_humanoid.urdf with each foot's collision box replaced by
// contact points (spheres, radius 0 as in Drake's models), written to a
// temporary URDF file that is removed with the object.
#pragma once

#include "test_paths.h"

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>

namespace robotalk::testing {

/// The simple humanoid's URDF text with each foot's <collision> replaced by `collisions`.
inline std::string PointFootedHumanoid(const std::string& collisions) {
  std::ifstream in(ProjectModel("simple_humanoid.urdf"));
  std::stringstream text;
  text << in.rdbuf();
  const std::regex foot_collision(
      R"((<link name="(left|right)_foot">[\s\S]*?)<collision>[\s\S]*?</collision>)");
  return std::regex_replace(text.str(), foot_collision, "$1" + collisions);
}

/// A <collision> sphere of `radius` at (x, y, z) in the link frame.
inline std::string ContactPoint(double x, double y, double z, double radius = 0) {
  return "<collision><origin xyz=\"" + std::to_string(x) + " " + std::to_string(y) + " " + std::to_string(z) +
         "\"/><geometry><sphere radius=\"" + std::to_string(radius) + "\"/></geometry></collision>";
}

/// Six points at the corners and mid-sides of the simple humanoid's sole
/// (0.24 x 0.12 m, 0.07 m below the ankle) and a bumper above it.
inline std::string SixPointSoles() {
  std::string points;
  for (double x : {-0.09, 0.03, 0.15}) {
    for (double y : {-0.06, 0.06}) points += ContactPoint(x, y, -0.07);
  }
  return points + ContactPoint(0, 0, -0.02, 0.01);
}

/// A URDF file in the temporary directory, removed by the destructor.
struct TempUrdf {
  TempUrdf(const std::string& name, const std::string& text)
      : path((std::filesystem::temp_directory_path() / (name + "_" + std::to_string(::getpid()) + ".urdf"))
                 .string()) {
    std::ofstream(path) << text;
  }
  ~TempUrdf() { std::filesystem::remove(path); }
  TempUrdf(const TempUrdf&) = delete;
  TempUrdf& operator=(const TempUrdf&) = delete;
  std::string path;
};

}  // namespace robotalk::testing
