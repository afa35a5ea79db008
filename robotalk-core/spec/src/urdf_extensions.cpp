#include "urdf_extensions.h"

#include "robotalk/error.h"
#include "robotalk/sequence_file.h"  // StrtodC

#include <console_bridge/console.h>
#include <urdf_parser/urdf_parser.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <set>
#include <sstream>
#include <thread>

namespace robotalk::urdf_detail {

void Refuse(const std::string& source, const std::string& what) { throw UrdfError(source + ": " + what); }

std::string Quote(const std::string& s) { return "'" + s + "'"; }

std::string Num(double v) {
  std::ostringstream s;
  s.precision(10);
  s << v;
  return s.str();
}

namespace {

// The end of the start tag that begins at xml[lt] ('<'): the index past its
// '>', or npos when the text ends first. `self_closing` tells "<a/>".
// TinyXML reads a quoted value only right after '=' (spaces allowed) and
// refuses a quote anywhere else in a tag, so only such quotes open a value.
std::size_t StartTagEnd(std::string_view xml, std::size_t lt, bool& self_closing) {
  char last = 0;  // the last character outside spaces and values
  for (std::size_t p = lt + 1; p < xml.size(); ++p) {
    const char c = xml[p];
    if ((c == '"' || c == '\'') && last == '=') {
      p = xml.find(c, p + 1);
      if (p == std::string_view::npos) return p;
      last = c;
    } else if (c == '>') {
      self_closing = last == '/';
      return p + 1;
    } else if (c != ' ' && c != '\t' && c != '\n' && c != '\r') {
      last = c;
    }
  }
  return std::string_view::npos;
}

}  // namespace

void CheckXmlDepth(std::string_view xml, int max_depth, const std::string& source) {
  constexpr auto npos = std::string_view::npos;
  auto past = [&](std::size_t from, std::string_view end) {
    const std::size_t at = xml.find(end, from);
    return at == npos ? npos : at + end.size();
  };
  int depth = 0;
  int deepest = 0;
  std::size_t first_too_deep = npos;
  for (std::size_t i = 0; i < xml.size();) {
    const std::size_t lt = xml.find('<', i);
    if (lt == npos) break;
    const std::string_view tag = xml.substr(lt);
    bool self_closing = false;
    if (tag.starts_with("<!--")) {
      i = past(lt + 4, "-->");
    } else if (tag.starts_with("<![CDATA[")) {
      i = past(lt + 9, "]]>");
    } else if (tag.starts_with("</")) {
      depth = std::max(depth - 1, 0);
      i = past(lt + 2, ">");
    } else if (tag.starts_with("<!") || tag.starts_with("<?")) {
      i = past(lt + 2, ">");  // TinyXML too ends these at the first '>'
    } else {
      i = StartTagEnd(xml, lt, self_closing);
      if (i == npos || self_closing) continue;
      deepest = std::max(deepest, ++depth);
      if (depth > max_depth && first_too_deep == npos) first_too_deep = lt;
    }
  }
  if (first_too_deep != npos) {
    const auto line =
        1 + std::count(xml.begin(), xml.begin() + static_cast<std::ptrdiff_t>(first_too_deep), '\n');
    Refuse(source, "XML elements nested " + std::to_string(deepest) + " deep (deeper than " +
                       std::to_string(max_depth) + " from line " + std::to_string(line) + "); the limit is " +
                       std::to_string(max_depth) + " (UrdfImportOptions::max_xml_depth)");
  }
}

namespace {

// urdfdom reports through console_bridge's global output handler. While one
// thread parses, the handler below collects that thread's messages and
// forwards everyone else's to the handler that was installed before. It is
// never destroyed: console_bridge keeps a "previous handler" pointer to it.
class CaptureHandler : public console_bridge::OutputHandler {
 public:
  using Sink = UrdfdomMessages;

  void log(const std::string& text, console_bridge::LogLevel level, const char* filename, int line) override {
    if (std::this_thread::get_id() != owner_.load()) {
      if (console_bridge::OutputHandler* previous = previous_.load())
        previous->log(text, level, filename, line);
      return;
    }
    if (level >= console_bridge::CONSOLE_BRIDGE_LOG_ERROR) {
      sink_->errors.push_back(text);
    } else if (level == console_bridge::CONSOLE_BRIDGE_LOG_WARN) {
      sink_->warnings.push_back(text);
    }
  }

  // Installs the handler for the calling thread until the guard dies.
  class Guard {
   public:
    explicit Guard(Sink& sink) : lock_(Mutex()) {
      CaptureHandler& h = Instance();
      h.sink_ = &sink;
      h.previous_.store(console_bridge::getOutputHandler());
      h.owner_.store(std::this_thread::get_id());
      console_bridge::useOutputHandler(&h);
    }
    ~Guard() {
      CaptureHandler& h = Instance();
      console_bridge::useOutputHandler(h.previous_.load());
      h.owner_.store(std::thread::id());
      h.sink_ = nullptr;
    }
    Guard(const Guard&) = delete;
    Guard& operator=(const Guard&) = delete;

   private:
    std::lock_guard<std::mutex> lock_;
  };

 private:
  static CaptureHandler& Instance() {
    static CaptureHandler* instance = new CaptureHandler;  // intentionally immortal
    return *instance;
  }
  static std::mutex& Mutex() {
    static std::mutex mutex;
    return mutex;
  }

  std::atomic<std::thread::id> owner_{};
  std::atomic<console_bridge::OutputHandler*> previous_{nullptr};
  Sink* sink_ = nullptr;
};

std::string At(const TiXmlElement& e) { return " (line " + std::to_string(e.Row()) + ")"; }

std::string Describe(const TiXmlElement& e) {
  const char* name = e.Attribute("name");
  std::string d = "<" + std::string(e.Value()) + ">";
  if (name != nullptr) d += " " + Quote(name);
  return d;
}

// The user's own block: a misspelt attribute must not pass silently.
void RequireOnlyAttributes(const TiXmlElement& e, std::initializer_list<const char*> allowed,
                           const std::string& source) {
  for (const TiXmlAttribute* a = e.FirstAttribute(); a != nullptr; a = a->Next()) {
    bool known = false;
    for (const char* name : allowed) known = known || std::string(a->Name()) == name;
    if (!known) {
      std::string expected;
      for (const char* name : allowed) expected += (expected.empty() ? "" : ", ") + std::string(name);
      Refuse(source, "<robotalk>: " + Describe(e) + At(e) + ": unknown attribute " + Quote(a->Name()) +
                         (expected.empty() ? " (it takes none)" : " (expected " + expected + ")"));
    }
  }
}

std::string RequiredAttribute(const TiXmlElement& e, const char* name, const std::string& source) {
  const char* value = e.Attribute(name);
  if (value == nullptr || *value == '\0') {
    Refuse(source, "<robotalk>: " + Describe(e) + At(e) + ": missing attribute " + Quote(name));
  }
  return value;
}

Eigen::Vector3d ParseTriple(const TiXmlElement& e, const char* attribute, const std::string& source) {
  const char* text = e.Attribute(attribute);
  Eigen::Vector3d v = Eigen::Vector3d::Zero();
  if (text == nullptr) return v;
  const char* p = text;
  for (int i = 0; i < 3; ++i) {
    char* end = nullptr;
    errno = 0;
    v[i] = StrtodC(p, &end);
    if (end == p || errno == ERANGE || !std::isfinite(v[i])) {
      Refuse(source, "<robotalk>: <" + std::string(e.Value()) + "> " + attribute + "=" + Quote(text) + At(e) +
                         " is not three finite numbers");
    }
    p = end;
  }
  while (*p == ' ' || *p == '\t' || *p == '\n' || *p == '\r') ++p;
  if (*p != '\0') {
    Refuse(source, "<robotalk>: <" + std::string(e.Value()) + "> " + attribute + "=" + Quote(text) + At(e) +
                       " has more than three numbers");
  }
  return v;
}

// URDF's rpy convention: fixed-axis roll about x, then pitch about y, then
// yaw about z, i.e. R = Rz(yaw) * Ry(pitch) * Rx(roll).
Eigen::Quaterniond FromRpy(const Eigen::Vector3d& rpy) {
  return (Eigen::AngleAxisd(rpy.z(), Eigen::Vector3d::UnitZ()) *
          Eigen::AngleAxisd(rpy.y(), Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(rpy.x(), Eigen::Vector3d::UnitX()))
      .normalized();
}

// An optional single <origin xyz rpy> child; `owner` takes no other children.
Pose ParseOriginChild(const TiXmlElement& owner, const std::string& source) {
  Pose pose;
  bool seen = false;
  for (const TiXmlElement* c = owner.FirstChildElement(); c != nullptr; c = c->NextSiblingElement()) {
    if (std::string(c->Value()) != "origin") {
      Refuse(source, "<robotalk>: " + Describe(owner) + At(owner) + ": unknown child element <" +
                         std::string(c->Value()) + "> (expected <origin>)");
    }
    if (seen) Refuse(source, "<robotalk>: " + Describe(owner) + At(owner) + ": more than one <origin>");
    seen = true;
    RequireOnlyAttributes(*c, {"xyz", "rpy"}, source);
    pose.translation = ParseTriple(*c, "xyz", source);
    pose.rotation = FromRpy(ParseTriple(*c, "rpy", source));
  }
  return pose;
}

void RequireNoChildren(const TiXmlElement& e, const std::string& source) {
  if (const TiXmlElement* c = e.FirstChildElement()) {
    Refuse(source, "<robotalk>: " + Describe(e) + At(e) + ": unexpected child element <" +
                       std::string(c->Value()) + ">");
  }
}

ServoTypes ParseServo(const TiXmlElement& e, const char* attribute, const std::string& source) {
  const std::string text = RequiredAttribute(e, attribute, source);
  try {
    return ServoTypes::Parse(text);
  } catch (const ModelError& error) {
    Refuse(source, "<robotalk>: " + Describe(e) + At(e) + ": " + error.what());
  }
}

}  // namespace

std::string ReadLimited(const std::string& path, std::size_t max_bytes, const std::string& who) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw UrdfError(who + ": cannot open '" + path + "'");
  const std::string limit =
      "the limit of " + std::to_string(max_bytes) + " bytes (UrdfImportOptions::max_file_bytes)";
  std::error_code ec;
  const std::uintmax_t size = std::filesystem::file_size(path, ec);
  if (!ec && size > max_bytes)
    throw UrdfError(path + ": " + std::to_string(size) + " bytes is more than " + limit);
  std::string text;
  std::vector<char> chunk(64 * 1024);
  while (in) {
    in.read(chunk.data(), static_cast<std::streamsize>(chunk.size()));
    text.append(chunk.data(), static_cast<size_t>(in.gcount()));
    if (text.size() > max_bytes) throw UrdfError(path + ": the text is longer than " + limit);
  }
  if (in.bad()) throw UrdfError(who + ": cannot read '" + path + "'");
  return text;
}

urdf::ModelInterfaceSharedPtr ParseQuietly(const std::string& xml, UrdfdomMessages& messages) {
  CaptureHandler::Guard guard(messages);
  try {
    return urdf::parseURDF(xml);
  } catch (const std::exception& e) {  // e.g. a malformed version attribute
    messages.errors.emplace_back(e.what());
    return nullptr;
  }
}

XmlScan ScanRobot(const TiXmlElement& robot, const std::string& source) {
  XmlScan scan;
  std::map<std::string, int> link_lines;
  for (const TiXmlElement* e = robot.FirstChildElement(); e != nullptr; e = e->NextSiblingElement()) {
    const std::string tag = e->Value();
    if (tag != "link" && tag != "joint") continue;
    const char* name = e->Attribute("name");
    if (name == nullptr || *name == '\0') Refuse(source, "<" + tag + ">" + At(*e) + " has no name");
    if (tag == "link") {
      auto [it, fresh] = link_lines.emplace(name, e->Row());
      if (!fresh) {
        Refuse(source, "duplicate link name " + Quote(name) + " (lines " + std::to_string(it->second) +
                           " and " + std::to_string(e->Row()) + ")");
      }
      scan.links.emplace_back(name);
      continue;
    }
    XmlJoint info;
    info.line = e->Row();
    if (const TiXmlElement* limit = e->FirstChildElement("limit")) {
      info.has_limit = true;
      info.has_lower = limit->Attribute("lower") != nullptr;
      info.has_upper = limit->Attribute("upper") != nullptr;
    }
    auto link_of = [&](const char* role) {
      const TiXmlElement* r = e->FirstChildElement(role);
      const char* link = r != nullptr ? r->Attribute("link") : nullptr;
      return std::string(link != nullptr ? link : "");
    };
    info.parent = link_of("parent");
    info.child = link_of("child");
    auto [it, fresh] = scan.joint_info.emplace(name, info);
    if (!fresh) {
      Refuse(source, "duplicate joint name " + Quote(name) + " (lines " + std::to_string(it->second.line) +
                         " and " + std::to_string(e->Row()) + ")");
    }
    scan.joints.emplace_back(name);
  }
  for (const std::string& joint : scan.joints) {
    const XmlJoint& info = scan.joint_info.at(joint);
    for (const auto& [role, link] : {std::pair{"parent", &info.parent}, std::pair{"child", &info.child}}) {
      if (link->empty()) {
        Refuse(source, "joint " + Quote(joint) + " (line " + std::to_string(info.line) + "): no <" + role +
                           " link=...>");
      }
      if (!link_lines.contains(*link)) {
        Refuse(source, "joint " + Quote(joint) + " (line " + std::to_string(info.line) + "): unknown " +
                           role + " link " + Quote(*link));
      }
    }
  }
  return scan;
}

Extensions ParseExtensions(const TiXmlElement& robot, const std::string& source) {
  Extensions ext;
  const TiXmlElement* block = robot.FirstChildElement("robotalk");
  if (block == nullptr) return ext;
  if (const TiXmlElement* second = block->NextSiblingElement("robotalk")) {
    Refuse(source, "more than one <robotalk> block (lines " + std::to_string(block->Row()) + " and " +
                       std::to_string(second->Row()) + ")");
  }
  RequireOnlyAttributes(*block, {"version"}, source);
  if (const char* version = block->Attribute("version"); version != nullptr && std::string(version) != "1") {
    Refuse(source,
           "<robotalk version=" + Quote(version) + ">" + At(*block) + ": unsupported version (expected 1)");
  }
  std::set<std::string> frame_names, servo_joints;
  for (const TiXmlElement* e = block->FirstChildElement(); e != nullptr; e = e->NextSiblingElement()) {
    const std::string tag = e->Value();
    if (tag == "control_frame") {
      RequireOnlyAttributes(*e, {"name", "link", "servo"}, source);
      Extensions::Frame frame;
      frame.name = RequiredAttribute(*e, "name", source);
      frame.link = RequiredAttribute(*e, "link", source);
      if (e->Attribute("servo") != nullptr) frame.servo = ParseServo(*e, "servo", source);
      frame.pose = ParseOriginChild(*e, source);
      frame.line = e->Row();
      if (!frame_names.insert(frame.name).second) {
        Refuse(source, "<robotalk>: duplicate control frame name " + Quote(frame.name) + At(*e));
      }
      ext.frames.push_back(std::move(frame));
    } else if (tag == "servo") {
      RequireOnlyAttributes(*e, {"joint", "types"}, source);
      RequireNoChildren(*e, source);
      Extensions::Servo servo;
      servo.joint = RequiredAttribute(*e, "joint", source);
      servo.types = ParseServo(*e, "types", source);
      servo.line = e->Row();
      if (!servo_joints.insert(servo.joint).second) {
        Refuse(source, "<robotalk>: joint " + Quote(servo.joint) + " has a second <servo>" + At(*e));
      }
      ext.servos.push_back(std::move(servo));
    } else if (tag == "base") {
      if (ext.base) {
        Refuse(source, "<robotalk>: more than one <base> (lines " + std::to_string(ext.base->line) + " and " +
                           std::to_string(e->Row()) + ")");
      }
      RequireOnlyAttributes(*e, {"link", "type"}, source);
      Extensions::Base base;
      if (const char* link = e->Attribute("link")) base.link = link;
      const std::string type = RequiredAttribute(*e, "type", source);
      try {
        base.type = ParseBaseType(type);
      } catch (const ModelError& error) {
        Refuse(source, "<robotalk>: <base>" + At(*e) + ": " + error.what());
      }
      base.pose = ParseOriginChild(*e, source);
      base.line = e->Row();
      ext.base = std::move(base);
    } else {
      Refuse(source, "<robotalk>: unknown element <" + tag + ">" + At(*e) +
                         " (expected <base>, <control_frame> or <servo>)");
    }
  }
  return ext;
}

}  // namespace robotalk::urdf_detail
