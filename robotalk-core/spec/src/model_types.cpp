#include "robotalk/model_types.h"

#include "robotalk/error.h"

#include <algorithm>
#include <cctype>
#include <sstream>

namespace robotalk {

Eigen::Isometry3d Pose::ToIsometry() const {
  Eigen::Isometry3d x = Eigen::Isometry3d::Identity();
  x.linear() = rotation.normalized().toRotationMatrix();
  x.translation() = translation;
  return x;
}

Pose Pose::FromIsometry(const Eigen::Isometry3d& x) {
  return Pose{x.translation(), Eigen::Quaterniond(x.linear()).normalized()};
}

// Quaternions compare by coefficients: q and -q are the same rotation but not
// the same description (the hash and the bytes differ).
bool Pose::operator==(const Pose& o) const {
  return translation == o.translation && rotation.coeffs() == o.rotation.coeffs();
}

bool Joint::operator==(const Joint& o) const {
  return name == o.name && parent_link == o.parent_link && child_link == o.child_link &&
         inboard == o.inboard && outboard == o.outboard && rest.coeffs() == o.rest.coeffs() &&
         dofs == o.dofs && servo_types == o.servo_types && mimic == o.mimic;
}

std::string ServoTypes::ToString() const {
  if (empty()) return "none";
  std::string s;
  auto add = [&](ServoType t, const char* word) {
    if (!Has(t)) return;
    if (!s.empty()) s += ' ';
    s += word;
  };
  add(ServoType::kSetPoint, "setpoint");
  add(ServoType::kSpeed, "speed");
  add(ServoType::kForce, "force");
  return s;
}

ServoTypes ServoTypes::Parse(const std::string& text) {
  std::string cleaned = text;
  std::replace_if(
      cleaned.begin(), cleaned.end(), [](char c) { return c == ',' || c == '|'; }, ' ');
  std::istringstream words(cleaned);
  ServoTypes result;
  std::string word;
  while (words >> word) {
    std::transform(word.begin(), word.end(), word.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    if (word == "setpoint" || word == "set-point" || word == "position") {
      result = result | ServoType::kSetPoint;
    } else if (word == "speed" || word == "velocity") {
      result = result | ServoType::kSpeed;
    } else if (word == "force" || word == "effort" || word == "torque") {
      result = result | ServoType::kForce;
    } else if (word != "none") {
      throw ModelError("ServoTypes::Parse: unknown servo type '" + word + "' in '" + text +
                       "' (expected setpoint, speed, force or none)");
    }
  }
  return result;
}

const char* ToString(DofType t) { return t == DofType::kPrismatic ? "prismatic" : "revolute"; }

const char* ToString(BaseType t) {
  switch (t) {
    case BaseType::kFixed:
      return "fixed";
    case BaseType::kDifferential:
      return "differential";
    case BaseType::kHolonomic:
      return "holonomic";
    case BaseType::kFloating:
      return "floating";
  }
  return "unknown";
}

BaseType ParseBaseType(const std::string& text) {
  for (BaseType t : {BaseType::kFixed, BaseType::kDifferential, BaseType::kHolonomic, BaseType::kFloating}) {
    if (text == ToString(t)) return t;
  }
  throw ModelError("ParseBaseType: unknown base type '" + text +
                   "' (expected fixed, differential, holonomic or floating)");
}

}  // namespace robotalk
