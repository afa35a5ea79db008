// Which file robotalk-web serves for a URL path, and as what type.
//
//   /                        -> <www>/index.html
//   /NAME                    -> <www>/NAME          (page files; no sub-folders)
//   /modules/three/...       -> <node_modules>/three/...
//   /modules/urdf-loader/... -> <node_modules>/urdf-loader/...
//   /urdf/ROBOT/REL          -> <folder of ROBOT's --urdf file>/REL (the URDF, its meshes)
//
// Anything else, any ".." segment, a backslash, a NUL or a percent escape is
// refused (nullopt), so no URL reaches outside those folders.
//
// Thread safety: pure functions.
#pragma once

#include "web_options.h"

#include <filesystem>
#include <optional>
#include <string>
#include <string_view>

namespace robotalk::web {

/// The file for a request target (its query string ignored), or nullopt.
std::optional<std::filesystem::path> ResolveWebPath(std::string_view target, const WebOptions& options);

/// The Content-Type for a file name by its extension ("application/octet-stream" if unknown).
std::string ContentTypeFor(const std::filesystem::path& file);

}  // namespace robotalk::web
