#include "mesh_catalog.h"

#include <tinyxml.h>

#include <charconv>
#include <fstream>
#include <sstream>
#include <system_error>
#include <variant>

namespace robotalk::web {
namespace {

namespace fs = std::filesystem;

constexpr int kMaxCrawlDepth = 6;

bool StartsWith(std::string_view s, std::string_view prefix) { return s.substr(0, prefix.size()) == prefix; }

// The <name> of DIR/package.xml, or "" when there is none.
std::string PackageXmlName(const fs::path& dir) {
  std::error_code ec;
  if (!fs::is_regular_file(dir / "package.xml", ec)) return "";
  TiXmlDocument doc;
  if (!doc.LoadFile((dir / "package.xml").string().c_str())) return "";
  const TiXmlElement* root = doc.RootElement();
  const TiXmlElement* name = root ? root->FirstChildElement("name") : nullptr;
  return name && name->GetText() ? name->GetText() : "";
}

void Crawl(const fs::path& dir, int depth, std::map<std::string, fs::path>& found) {
  if (const std::string name = PackageXmlName(dir); !name.empty()) {
    found.try_emplace(name, dir);
    return;  // as rospack: no packages inside a package
  }
  if (depth >= kMaxCrawlDepth) return;
  std::error_code ec;
  for (fs::directory_iterator it(dir, fs::directory_options::skip_permission_denied, ec), end;
       !ec && it != end; it.increment(ec)) {
    const std::string leaf = it->path().filename().string();
    if (!leaf.empty() && leaf[0] == '.') continue;
    std::error_code dir_ec;
    if (it->is_directory(dir_ec) && !it->is_symlink(dir_ec)) Crawl(it->path(), depth + 1, found);
  }
}

std::optional<fs::path> Canonical(const fs::path& p) {
  std::error_code ec;
  fs::path c = fs::canonical(p, ec);
  if (ec) return std::nullopt;
  return c;
}

bool Under(const fs::path& file, const fs::path& dir) {
  auto f = file.begin();
  for (auto d = dir.begin(); d != dir.end(); ++d, ++f) {
    if (d->empty()) continue;  // a trailing separator
    if (f == file.end() || *f != *d) return false;
  }
  return true;
}

struct Resolver {
  std::vector<fs::path> roots;  // canonical package paths, in order
  fs::path urdf_dir;            // canonical
  std::map<std::string, fs::path> packages;
  std::string searched;  // for messages

  // The file `uri` names, or the reason it has none.
  std::variant<fs::path, std::string> Locate(const std::string& uri) const {
    if (StartsWith(uri, "package://")) {
      const std::string rest = uri.substr(10);
      const auto slash = rest.find('/');
      if (slash == std::string::npos || slash == 0 || slash + 1 == rest.size())
        return std::string("not a package://PACKAGE/PATH");
      const std::string pkg = rest.substr(0, slash);
      const auto it = packages.find(pkg);
      if (it == packages.end())
        return "package '" + pkg + "' not found in " + searched +
               " (give its parent folder with --package-path or ROS_PACKAGE_PATH)";
      return it->second / rest.substr(slash + 1);
    }
    if (StartsWith(uri, "file://")) return fs::path(uri.substr(7));
    if (uri.find("://") != std::string::npos)
      return "scheme of '" + uri + "' not supported (package://, file://, or a path)";
    if (!uri.empty() && uri[0] == '/') return fs::path(uri);
    return urdf_dir / uri;
  }

  void Resolve(MeshEntry& m, const std::string& robot, std::size_t index) const {
    const auto located = Locate(m.uri);
    if (const auto* why = std::get_if<std::string>(&located)) {
      m.error = *why;
      return;
    }
    const fs::path& path = std::get<fs::path>(located);
    const auto real = Canonical(path);
    std::error_code ec;
    if (!real || !fs::is_regular_file(*real, ec)) {
      m.error = "no such file: " + path.lexically_normal().string();
      return;
    }
    bool allowed = Under(*real, urdf_dir);
    for (const fs::path& r : roots) allowed = allowed || Under(*real, r);
    if (!allowed) {
      m.error = "refused: " + path.lexically_normal().string() + " (" + real->string() +
                ") is outside the package paths and the URDF's folder; robotalk-web serves no file there";
      return;
    }
    m.file = *real;
    m.url = "/mesh/" + robot + "/" + std::to_string(index) + "/" + real->filename().string();
  }
};

}  // namespace

std::map<std::string, fs::path> FindPackages(const std::vector<std::string>& roots) {
  std::map<std::string, fs::path> found;
  for (const std::string& root : roots) {
    const auto dir = Canonical(root);
    std::error_code ec;
    if (!dir || !fs::is_directory(*dir, ec)) continue;
    // The root itself may be the package (by its package.xml, or by its name).
    if (const std::string name = PackageXmlName(*dir); !name.empty()) {
      found.try_emplace(name, *dir);
      continue;
    }
    found.try_emplace(dir->filename().string(), *dir);
    std::map<std::string, fs::path> below;
    Crawl(*dir, 0, below);
    for (auto& [name, path] : below) found.try_emplace(name, path);
    // A plain sub-folder named like the package (meshes copied without their package.xml).
    for (fs::directory_iterator it(*dir, fs::directory_options::skip_permission_denied, ec), end;
         !ec && it != end; it.increment(ec)) {
      std::error_code dir_ec;
      if (it->is_directory(dir_ec)) found.try_emplace(it->path().filename().string(), it->path());
    }
  }
  return found;
}

MeshCatalog ResolveMeshes(const std::string& robot, const std::string& urdf_path,
                          const std::vector<std::string>& package_paths) {
  MeshCatalog catalog;
  catalog.robot = robot;
  Resolver r;
  const auto urdf = Canonical(urdf_path);
  TiXmlDocument doc;
  if (!urdf || !doc.LoadFile(urdf->string().c_str())) {
    catalog.error =
        "cannot read the URDF '" + urdf_path + "'" + (urdf ? std::string(": ") + doc.ErrorDesc() : "");
    return catalog;
  }
  r.urdf_dir = urdf->parent_path();
  for (const std::string& p : package_paths) {
    if (auto c = Canonical(p)) r.roots.push_back(*c);
  }
  r.packages = FindPackages(package_paths);
  r.searched = package_paths.empty() ? std::string("the package paths (none given)") : "the package paths";
  for (std::size_t i = 0; i < package_paths.size(); ++i) r.searched += (i ? ", " : " ") + package_paths[i];
  const TiXmlElement* root = doc.RootElement();
  for (const TiXmlElement* link = root ? root->FirstChildElement("link") : nullptr; link;
       link = link->NextSiblingElement("link"))
    if (const char* name = link->Attribute("name")) catalog.links.emplace_back(name);
  for (const char* element : {"visual", "collision"}) {
    for (const TiXmlElement* link = root ? root->FirstChildElement("link") : nullptr; link;
         link = link->NextSiblingElement("link")) {
      const char* link_name = link->Attribute("name");
      for (const TiXmlElement* e = link->FirstChildElement(element); e; e = e->NextSiblingElement(element)) {
        const TiXmlElement* geometry = e->FirstChildElement("geometry");
        const TiXmlElement* mesh = geometry ? geometry->FirstChildElement("mesh") : nullptr;
        const char* filename = mesh ? mesh->Attribute("filename") : nullptr;
        if (!filename) continue;
        MeshEntry m{.link = link_name ? link_name : "", .uri = filename, .collision = element[0] == 'c'};
        r.Resolve(m, robot, catalog.meshes.size());
        catalog.meshes.push_back(std::move(m));
      }
    }
  }
  try {
    catalog.shapes = LoadUrdfShapes(urdf->string());
  } catch (const std::exception& e) {
    catalog.geometry_error = e.what();
  }
  return catalog;
}

const MeshEntry* MeshCatalog::MeshOf(const UrdfShape& shape) const {
  if (shape.kind != UrdfShape::Kind::kMesh) return nullptr;
  for (const MeshEntry& m : meshes) {
    if (m.link == shape.link && m.collision == shape.collision && m.uri == shape.mesh) return &m;
  }
  return nullptr;
}

nlohmann::json MeshCatalog::Json() const {
  nlohmann::json list = nlohmann::json::array();
  for (const MeshEntry& m : meshes) {
    list.push_back({{"link", m.link},
                    {"uri", m.uri},
                    {"url", m.url.empty() ? nlohmann::json(nullptr) : nlohmann::json(m.url)},
                    {"error", m.error},
                    {"collision", m.collision}});
  }
  return {{"robot", robot}, {"error", error}, {"meshes", list}};
}

std::optional<fs::path> MeshCatalog::File(std::string_view rest) const {
  const auto slash = rest.find('/');
  if (slash == std::string_view::npos) return std::nullopt;
  std::size_t index = 0;
  const auto [end, ec] = std::from_chars(rest.data(), rest.data() + slash, index);
  if (ec != std::errc() || end != rest.data() + slash || index >= meshes.size()) return std::nullopt;
  const MeshEntry& m = meshes[index];
  const std::string_view name = rest.substr(slash + 1);
  if (m.file.empty() || name.empty()) return std::nullopt;
  if (name == m.file.filename().string()) return m.file;
  // A file the mesh refers to (a glTF's .bin, an .obj's .mtl, a texture):
  // only from the mesh's own folder or below it, and no hidden file.
  if (name.front() == '.' || name.find("/.") != std::string_view::npos) return std::nullopt;
  const auto companion = Canonical(m.file.parent_path() / name);
  std::error_code file_ec;
  if (!companion || !Under(*companion, m.file.parent_path()) || !fs::is_regular_file(*companion, file_ec))
    return std::nullopt;
  return companion;
}

std::size_t MeshCatalog::unresolved() const {
  std::size_t n = 0;
  for (const MeshEntry& m : meshes) n += m.file.empty();
  return n;
}

}  // namespace robotalk::web
