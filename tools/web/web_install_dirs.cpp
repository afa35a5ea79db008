#include "web_install_dirs.h"

#include <system_error>

namespace robotalk::web {

WebDirs DefaultWebDirs(const std::filesystem::path& exe_dir, const std::filesystem::path& data_from_bin,
                       const std::filesystem::path& source_dir) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (!exe_dir.empty()) {
    const fs::path installed = (exe_dir / data_from_bin).lexically_normal();
    if (fs::is_regular_file(installed / "www" / "index.html", ec))
      return {(installed / "www").string(), (installed / "node_modules").string()};
  }
  return {(source_dir / "www").string(), (source_dir / "node_modules").string()};
}

std::filesystem::path RunningBinaryDir() {
  std::error_code ec;
  const auto exe = std::filesystem::read_symlink("/proc/self/exe", ec);
  return ec ? std::filesystem::path() : exe.parent_path();
}

}  // namespace robotalk::web
