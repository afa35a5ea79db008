// MeshCatalog: the mesh files a robot's URDF (--urdf NAME=PATH) names, each
// resolved to a file robotalk-web may serve, or with the reason it cannot
// (docs/web.md, "Meshes").
//
// A mesh filename is resolved as ROS does:
//   package://PKG/REL  -> DIR/REL, DIR the folder of package PKG found in the
//                         package paths (--package-path, then ROS_PACKAGE_PATH):
//                         a path that is PKG itself (its package.xml names PKG,
//                         or its folder is called PKG), a sub-folder called
//                         PKG, or a folder below whose package.xml names PKG;
//   file:///ABS, /ABS  -> ABS;
//   REL                -> the URDF's folder / REL.
// Only an existing regular file whose real path (symbolic links followed)
// lies under a package path or under the URDF's folder is served: "../"
// segments or a link that leave those folders are refused, naming the path.
//
// The page gets the catalog as JSON at /meshes/NAME and each resolved file
// at its `url`, /mesh/NAME/INDEX/BASENAME; it draws the configuration's
// shapes for the links whose meshes did not resolve.
//
// Thread safety: pure functions and a value type. Errors: none thrown; an
// unreadable URDF gives a catalog with `error` set.
#pragma once

#include <nlohmann/json.hpp>

#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace robotalk::web {

struct MeshEntry {
  std::string link;            ///< the URDF link whose <visual> names it
  std::string uri;             ///< the filename as the URDF writes it
  std::filesystem::path file;  ///< the resolved file (real path); empty when unresolved
  std::string url;             ///< where the bridge serves it; empty when unresolved
  std::string error;           ///< why it is not served ("" when resolved)
};

struct MeshCatalog {
  std::string robot;
  std::string error;  ///< the URDF could not be read or parsed ("" otherwise)
  std::vector<MeshEntry> meshes;

  /// {"robot", "error", "meshes": [{link, uri, url (null if unresolved), error}]}.
  nlohmann::json Json() const;
  /// The file of a /mesh/ROBOT/ request's rest: "INDEX/BASENAME" the mesh
  /// itself, "INDEX/REL" a file below the mesh's folder that it refers to
  /// (a glTF's .bin, a texture); nullopt otherwise.
  std::optional<std::filesystem::path> File(std::string_view rest) const;
  std::size_t unresolved() const;
};

/// Package name -> folder over `roots` (first root wins; see the file comment).
/// Missing roots are skipped; the crawl stops at a package and 6 levels deep.
std::map<std::string, std::filesystem::path> FindPackages(const std::vector<std::string>& roots);

/// Resolves the <visual> meshes of `urdf_path` for robot `robot`.
MeshCatalog ResolveMeshes(const std::string& robot, const std::string& urdf_path,
                          const std::vector<std::string>& package_paths);

}  // namespace robotalk::web
