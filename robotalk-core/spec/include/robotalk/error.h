// The RoboTalk exception hierarchy: one base class and a few kinds a caller can
// tell apart. Every message names the function or element and the bad value.
#pragma once

#include <stdexcept>
#include <string>

namespace robotalk {

/// Base of every exception RoboTalk throws.
class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A robot model is inconsistent (not a tree, duplicate name, bad limit, ...).
class ModelError : public Error {
 public:
  using Error::Error;
};

/// A URDF file could not be read, parsed or imported.
class UrdfError : public Error {
 public:
  using Error::Error;
};

/// An LCM message is malformed, truncated or of an unsupported version.
class ProtocolError : public Error {
 public:
  using Error::Error;
};

/// A transport (LCM, in-memory, log file) could not start, publish or read:
/// the message names the URL or file and what failed.
class TransportError : public Error {
 public:
  using Error::Error;
};

/// A name or index does not exist in a robot model.
class LookupError : public Error {
 public:
  using Error::Error;
};

}  // namespace robotalk
