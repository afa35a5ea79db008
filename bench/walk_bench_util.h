// What robotalk-walk-bench and robotalk-walk-sweep share (not a library):
// the humanoid and driver options they start from, `--option key=value`,
// and a fresh ode driver. Single-threaded.
#pragma once

#include "ode_driver.h"

#include <cstdio>
#include <cstdlib>
#include <map>
#include <memory>
#include <string>

namespace robotalk::bench {

/// models/simple_humanoid.urdf (ROBOTALK_BENCH_MODELS: the source tree's models).
inline std::string DefaultWalkModel() { return std::string(ROBOTALK_BENCH_MODELS) + "/simple_humanoid.urdf"; }

/// The driver options both start from (walk=true), before any --option.
inline std::map<std::string, std::string> DefaultWalkOptions() { return {{"walk", "true"}}; }

/// --option key=value: sets `key` to `value` ("" for a word without '=').
inline void SetDriverOption(std::map<std::string, std::string>& options, const std::string& key_value) {
  const std::size_t eq = key_value.find('=');
  options[key_value.substr(0, eq)] = eq == std::string::npos ? "" : key_value.substr(eq + 1);
}

/// Both tools read `--flag value` pairs: a flag left without its value (a
/// trailing --help) ends the tool with status 2 naming it, rather than being
/// ignored while the whole default run starts.
inline void RequireFlagValuePairs(int argc, char** argv) {
  if (argc > 1 && argc % 2 == 0) {
    std::fprintf(stderr, "%s needs a value (every option is --flag value; see the header of %s's source)\n",
                 argv[argc - 1], argv[0]);
    std::exit(2);
  }
}

/// A fresh ode driver (robot name "") of `model` with `options`; throws Error
/// as the registry does (a bad option, a URDF that cannot be read).
inline std::unique_ptr<Driver> NewOdeDriver(const std::string& model,
                                            const std::map<std::string, std::string>& options) {
  DriverRegistry registry;
  RegisterOdeDriver(registry);
  return registry.Create("ode", DriverConfig{.robot_name = "", .urdf_path = model, .options = options});
}

}  // namespace robotalk::bench
