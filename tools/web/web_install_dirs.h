// Where robotalk-web finds its page and npm modules when no option names them.
//
// An installation keeps them under share/robotalk/web/ ({www,node_modules},
// installed by tools/web/CMakeLists.txt) and robotalk-web finds that folder
// relative to its own binary (/proc/self/exe), so an installed tree can be
// moved anywhere. The binary in the build tree has no such folder beside it
// and serves from the source tree it was built from.
//
// Thread safety: pure functions (DefaultWebDirs reads the file system).
#pragma once

#include <filesystem>
#include <string>

namespace robotalk::web {

struct WebDirs {
  std::string www;           ///< the page's files (index.html, app.js, ...)
  std::string node_modules;  ///< the folder holding three/ and urdf-loader/
};

/// `exe_dir`/`data_from_bin` when it holds www/index.html (an installation:
/// `data_from_bin` is share/robotalk/web relative to the binaries' folder,
/// e.g. "../share/robotalk/web"), else `source_dir` (tools/web of the sources).
WebDirs DefaultWebDirs(const std::filesystem::path& exe_dir, const std::filesystem::path& data_from_bin,
                       const std::filesystem::path& source_dir);

/// The folder of the running binary (from /proc/self/exe), or "" when unknown.
std::filesystem::path RunningBinaryDir();

}  // namespace robotalk::web
