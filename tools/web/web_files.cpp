#include "web_files.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <utility>

namespace robotalk::web {
namespace {

bool SafeRelative(std::string_view rel) {
  if (rel.empty() || rel.front() == '/') return false;
  if (rel.find_first_of(std::string_view("\\%\0", 3)) != std::string_view::npos) return false;
  size_t start = 0;
  while (start <= rel.size()) {
    const size_t end = std::min(rel.find('/', start), rel.size());
    const std::string_view seg = rel.substr(start, end - start);
    if (seg.empty() || seg == "." || seg == "..") return false;
    start = end + 1;
  }
  return true;
}

bool StartsWith(std::string_view s, std::string_view prefix) { return s.substr(0, prefix.size()) == prefix; }

}  // namespace

std::optional<std::filesystem::path> ResolveWebPath(std::string_view target, const WebOptions& options) {
  namespace fs = std::filesystem;
  target = target.substr(0, target.find('?'));
  if (target == "/") return fs::path(options.www_dir) / "index.html";
  if (!StartsWith(target, "/")) return std::nullopt;
  const std::string_view rel = target.substr(1);
  if (!SafeRelative(rel)) return std::nullopt;
  for (std::string_view module : {"three", "urdf-loader"}) {
    const std::string prefix = "modules/" + std::string(module) + "/";
    if (StartsWith(rel, prefix))
      return fs::path(options.node_modules_dir) / module / rel.substr(prefix.size());
  }
  if (StartsWith(rel, "urdf/")) {
    const std::string_view rest = rel.substr(5);
    const size_t slash = rest.find('/');
    if (slash == std::string_view::npos) return std::nullopt;
    const auto it = options.urdf.find(std::string(rest.substr(0, slash)));
    if (it == options.urdf.end()) return std::nullopt;
    // The --urdf file itself, nothing else of its folder (meshes go through
    // /mesh/, which serves only what the catalog resolved).
    if (rest.substr(slash + 1) != fs::path(it->second).filename().string()) return std::nullopt;
    return fs::path(it->second);
  }
  if (rel.find('/') != std::string_view::npos) return std::nullopt;
  return fs::path(options.www_dir) / rel;
}

std::string ContentTypeFor(const std::filesystem::path& file) {
  static const std::array<std::pair<const char*, const char*>, 11> kTypes{{
      {".html", "text/html; charset=utf-8"},
      {".js", "text/javascript; charset=utf-8"},
      {".mjs", "text/javascript; charset=utf-8"},
      {".css", "text/css; charset=utf-8"},
      {".json", "application/json"},
      {".png", "image/png"},
      {".svg", "image/svg+xml"},
      {".urdf", "application/xml"},
      {".xml", "application/xml"},
      {".stl", "model/stl"},
      {".dae", "model/vnd.collada+xml"},
  }};
  std::string ext = file.extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  for (const auto& [e, type] : kTypes) {
    if (ext == e) return type;
  }
  return "application/octet-stream";
}

}  // namespace robotalk::web
