#include "robotalk/driver.h"

#include "robotalk/error.h"

namespace robotalk {

void DriverRegistry::Register(const std::string& name, Factory factory) {
  if (!factories_.emplace(name, std::move(factory)).second) {
    throw Error("DriverRegistry::Register: driver '" + name + "' is registered twice");
  }
}

std::unique_ptr<Driver> DriverRegistry::Create(const std::string& name, const DriverConfig& config) const {
  auto it = factories_.find(name);
  if (it == factories_.end()) {
    std::string known;
    for (const auto& [n, f] : factories_) known += (known.empty() ? "" : ", ") + n;
    throw Error("unknown driver '" + name + "' for robot '" + config.robot_name + "' (known: " + known + ")");
  }
  return it->second(config);
}

std::vector<std::string> DriverRegistry::names() const {
  std::vector<std::string> out;
  for (const auto& [n, f] : factories_) out.push_back(n);
  return out;
}

}  // namespace robotalk
