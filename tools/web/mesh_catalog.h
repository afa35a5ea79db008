// MeshCatalog: a robot's URDF (--urdf NAME=PATH) as the bridge draws it: the
// mesh files it names, each resolved to a file robotalk-web may serve, or
// with the reason it cannot (docs/web.md, "Meshes"), and every link's
// <visual> and <collision> shapes (robotalk/urdf_geometry.h), which the
// Foxglove scene and the MCAP export draw (foxglove_messages.h). The page,
// the Foxglove endpoint and robotalk-logplay export --mcap all take a
// robot's geometry from here.
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
// shapes for the links whose meshes did not resolve. The <visual> meshes
// come first, in file order (the page's), then the <collision> ones.
//
// Thread safety: pure functions and a value type. Errors: none thrown; an
// unreadable URDF gives a catalog with `error` set.
#pragma once

#include "robotalk/urdf_geometry.h"

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
  bool collision = false;      ///< named by a <collision>; by a <visual> otherwise
};

struct MeshCatalog {
  std::string robot;
  std::string error;  ///< the URDF could not be read or parsed ("" otherwise)
  std::vector<MeshEntry> meshes;
  /// Every <visual> and <collision> shape (LoadUrdfShapes); empty with
  /// `geometry_error` set when urdfdom refused the file (the page, which reads
  /// the URDF itself, may still draw it).
  std::vector<UrdfShape> shapes;
  std::string geometry_error;
  /// The names of the URDF's <link>s, in file order (a link without any
  /// shape is one, and has no geometry to draw).
  std::vector<std::string> links;

  /// The entry of a kMesh shape (same link, element and filename); nullptr
  /// for another kind or a mesh the catalog does not list.
  const MeshEntry* MeshOf(const UrdfShape& shape) const;

  /// {"robot", "error", "meshes": [{link, uri, url (null if unresolved), error, collision}]}.
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

/// Resolves the <visual> and <collision> meshes of `urdf_path` for robot
/// `robot`, and reads its shapes.
MeshCatalog ResolveMeshes(const std::string& robot, const std::string& urdf_path,
                          const std::vector<std::string>& package_paths);

}  // namespace robotalk::web
