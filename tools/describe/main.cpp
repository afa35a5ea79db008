// robotalk-describe: prints a URDF robot as RoboTalk sees it.
//   robotalk-describe [--json] [--strict] [--merge-chains] [--max-bytes N] [--max-depth N] FILE.urdf
#include "describe_format.h"
#include "robotalk/error.h"
#include "robotalk/log_writer.h"  // EscapeControls, OpenStandardDescriptors
#include "robotalk/option_reader.h"
#include "robotalk/urdf_import.h"

#include <cerrno>
#include <climits>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <iostream>
#include <optional>
#include <string>

#ifndef ROBOTALK_VERSION
#define ROBOTALK_VERSION "unknown"
#endif

namespace {

constexpr const char* kUsage =
    "usage: robotalk-describe [--json] [--strict] [--merge-chains] [--name NAME] [--max-bytes N]\n"
    "                         [--max-depth N] FILE.urdf\n"
    "Prints the RoboTalk motion specification of a URDF robot: links with masses,\n"
    "joints with dofs and limits, control frames, servo types, total mass.\n"
    "  --json          one JSON object (one line) on stdout instead of tables\n"
    "  --strict        treat every import warning as an error\n"
    "  --merge-chains  merge massless joint chains into multi-dof joints (pan-tilt -> 2 dofs)\n"
    "  --name NAME     robot name to use instead of <robot name=...>\n"
    "  --version       the version\n"
    "  --max-bytes N   refuse files larger than N bytes (default 16 MiB)\n"
    "  --max-depth N   refuse XML nested deeper than N elements (default 100)\n"
    "Exit status: 0 on success, 1 if the file cannot be imported, 2 on a usage error.\n";

// A positive decimal integer no larger than `max`, or nullopt.
std::optional<unsigned long long> PositiveNumber(const char* text, unsigned long long max) {
  char* end = nullptr;
  errno = 0;
  const unsigned long long v = std::strtoull(text, &end, 10);
  if (end == text || *end != '\0' || errno != 0 || text[0] == '-' || v == 0 || v > max) return std::nullopt;
  return v;
}

}  // namespace

int main(int argc, char** argv) {
  robotalk::OpenStandardDescriptors();  // first: nothing of ours on descriptors 0-2
  bool json = false;
  robotalk::UrdfImportOptions options;
  std::string path;
  try {
    robotalk::OptionReader r(argc, argv);
    while (r.Next()) {
      const std::string& arg = r.word();
      if (arg == "--json") {
        json = true;
      } else if (arg == "--strict") {
        options.strict = true;
      } else if (arg == "--merge-chains") {
        options.merge_massless_chains = true;
      } else if (arg == "--name") {
        options.robot_name = r.Value();
      } else if (arg == "--max-bytes" || arg == "--max-depth") {
        const bool bytes = arg == "--max-bytes";
        const std::string& text = r.Value();
        const auto v = PositiveNumber(text.c_str(), bytes ? SIZE_MAX : INT_MAX);
        if (!v) {
          std::cerr << "robotalk-describe: " << arg << " '" << text << "' is not a positive integer\n";
          return 2;
        }
        if (bytes) {
          options.max_file_bytes = static_cast<std::size_t>(*v);
        } else {
          options.max_xml_depth = static_cast<int>(*v);
        }
      } else if (r.IsVersion()) {
        std::cout << "robotalk-describe " << ROBOTALK_VERSION << "\n";
        return 0;
      } else if (r.IsHelp()) {
        std::cout << kUsage;
        return 0;
      } else if (!arg.empty() && arg[0] == '-') {
        r.Unknown();
      } else if (path.empty()) {
        path = arg;
      } else {
        std::cerr << "robotalk-describe: more than one file given ('" << path << "', '" << arg << "')\n";
        return 2;
      }
    }
  } catch (const robotalk::UsageError& e) {
    std::cerr << "robotalk-describe: " << e.what() << "\n" << kUsage;
    return 2;
  }
  if (path.empty()) {
    std::cerr << kUsage;
    return 2;
  }
  try {
    robotalk::UrdfImportResult result = robotalk::LoadUrdfFile(path, options);
    if (json) {
      robotalk::PrintModelJson(result.model, result.warnings, std::cout);
    } else {
      for (const std::string& w : result.warnings)
        std::cerr << "warning: " << robotalk::EscapeControls(w) << "\n";
      robotalk::PrintModelTable(result.model, std::cout);
    }
  } catch (const std::exception& e) {
    // One line, no terminal control, whatever the message holds (a name of
    // the file's, written with a character reference).
    std::cerr << "robotalk-describe: error: " << robotalk::EscapeControls(e.what()) << "\n";
    return 1;
  }
  return 0;
}
