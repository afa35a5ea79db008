#include "robotalk/driver.h"

#include "robotalk/driver_support.h"
#include "robotalk/error.h"

#include <algorithm>

namespace robotalk {

DriverResult Driver::Track(const JointReference& reference, TimePoint now,
                           std::vector<Completion>& completed) {
  DriverCommand setpoint;
  setpoint.type = CommandType::kJointSetPoint;
  setpoint.target = reference.joint;
  setpoint.num_values = static_cast<int>(std::min(reference.position.size(), setpoint.values.size()));
  std::copy_n(reference.position.begin(), setpoint.num_values, setpoint.values.begin());
  return Execute(setpoint, now, completed);
}

DriverResult Driver::TrackBase(const BaseReference& reference, TimePoint now,
                               std::vector<Completion>& completed) {
  return Execute(driver_support::SetSpeedOf(reference), now, completed);
}

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
