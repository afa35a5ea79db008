// Private to urdf_import.cpp: the parsing side of URDF import. urdfdom runs
// with its console_bridge output captured; tinyxml reads what urdfdom forgets
// (the file order of links and joints, which <limit> attributes were actually
// written) and the RoboTalk extension block (docs/urdf_import.md).
//
// Every function throws UrdfError whose message starts with the source name.
#pragma once

#include "robotalk/model_types.h"

#include <tinyxml.h>
#include <urdf_model/model.h>
#include <urdf_world/types.h>

#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace robotalk::urdf_detail {

/// Throws UrdfError("<source>: <what>").
[[noreturn]] void Refuse(const std::string& source, const std::string& what);

/// What urdfdom said through console_bridge during one parse.
struct UrdfdomMessages {
  std::vector<std::string> errors;
  std::vector<std::string> warnings;
};

/// urdf::parseURDF with console_bridge's output captured into `messages`
/// (nothing reaches stderr). Imports are serialised here: the output handler
/// is process-wide. Messages other threads log meanwhile go to the handler
/// installed before. Returns nullptr when urdfdom refuses or throws.
urdf::ModelInterfaceSharedPtr ParseQuietly(const std::string& xml, UrdfdomMessages& messages);

/// Refuses `xml` when its elements nest deeper than `max_depth`, naming the
/// depth, the line where the limit is first passed and the limit. TinyXML
/// (and urdfdom through it) parses and frees elements recursively, so this
/// runs first: one pass over the text, no recursion, no allocation. It skips
/// comments, CDATA, declarations and processing instructions, and quoted
/// attribute values, where TinyXML does; where it cannot tell, it counts an
/// element, so it never reports less depth than TinyXML would recurse.
void CheckXmlDepth(std::string_view xml, int max_depth, const std::string& source);

/// The text of the file at `path`, never more than `max_bytes` + 1 of it in
/// memory (a pipe has no size to ask for beforehand). Throws UrdfError:
/// "<who>: cannot open '<path>'", or "<path>: ... is more than the limit of
/// <max_bytes> bytes (UrdfImportOptions::max_file_bytes)".
std::string ReadLimited(const std::string& path, std::size_t max_bytes, const std::string& who);

/// "'name'".
std::string Quote(const std::string& s);

/// A number as a short text ("2.775", "inf").
std::string Num(double v);

/// What the XML says about one <joint> that urdfdom does not keep.
struct XmlJoint {
  int line = 0;
  bool has_limit = false;  ///< a <limit> child is present
  bool has_lower = false;  ///< <limit lower=...> written
  bool has_upper = false;  ///< <limit upper=...> written
  std::string parent;      ///< <parent link=...>, empty when absent
  std::string child;       ///< <child link=...>, empty when absent
};

/// The direct children <link> and <joint> of <robot>, in file order.
struct XmlScan {
  std::vector<std::string> links;
  std::vector<std::string> joints;
  std::map<std::string, XmlJoint> joint_info;
};

/// Reads names and limit attributes. Refuses an unnamed or duplicated link or
/// joint and a joint naming an unknown link (urdfdom would too, but with a
/// less useful message).
XmlScan ScanRobot(const TiXmlElement& robot, const std::string& source);

/// The parsed <robotalk> block. Names are not resolved yet (the importer
/// checks them against the model); `line` points the user at the element.
struct Extensions {
  struct Frame {
    std::string name;
    std::string link;
    Pose pose;
    ServoTypes servo = ServoType::kSetPoint;
    int line = 0;
  };
  struct Servo {
    std::string joint;
    ServoTypes types;
    int line = 0;
  };
  struct Base {
    std::optional<std::string> link;  ///< when given, must be the root link
    BaseType type = BaseType::kFixed;
    Pose pose;  ///< of the root link frame in the world
    int line = 0;
  };
  std::vector<Frame> frames;
  std::vector<Servo> servos;
  std::optional<Base> base;
};

/// Parses the top-level <robotalk> element of <robot>, if any. Refuses
/// unknown elements and attributes, malformed numbers, unknown servo or base
/// types, a second <robotalk>, <base> or <servo> for the same joint.
Extensions ParseExtensions(const TiXmlElement& robot, const std::string& source);

}  // namespace robotalk::urdf_detail
