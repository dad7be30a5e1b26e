#include "base/install_layout.h"

#include <algorithm>
#include <cstdlib>
#include <filesystem>

// Set for this file only by modules/base/CMakeLists.txt: the install layout relative to the bin directory,
// and where this build's source and build trees are (used by a program run from its build tree only).
#ifndef SELFCAL_DATA_FROM_BIN
#error "SELFCAL_DATA_FROM_BIN (the data directory relative to the bin directory) must be defined"
#endif

namespace selfcal {

namespace {

namespace fs = std::filesystem;

// Whether `path` is `dir` or inside it (both made absolute and normal, symlinks resolved where they exist).
bool IsInside(const fs::path& path, const fs::path& dir) {
  std::error_code ec;
  const fs::path p = fs::weakly_canonical(path, ec);
  const fs::path d = fs::weakly_canonical(dir, ec);
  if (d.empty() || p.empty()) return false;
  return std::mismatch(d.begin(), d.end(), p.begin(), p.end()).first == d.end();
}

bool SourceFallbackAllowed() {
  const char* off = std::getenv("SELFCAL_NO_SOURCE_FALLBACK");
  return off == nullptr || *off == '\0' || std::string(off) == "0";
}

}  // namespace

InstallLayout LayoutOf(const std::string& executable, const std::string& source_dir, const std::string& build_dir,
                       bool source_fallback) {
  InstallLayout layout;
  if (executable.empty()) return layout;
  const fs::path exe_dir = fs::path(executable).parent_path();
  layout.executable_dir = exe_dir.string();
  const fs::path data_dir = (exe_dir / SELFCAL_DATA_FROM_BIN).lexically_normal();
  layout.data_dirs.push_back({data_dir.string(), "installed with the program"});
  layout.library_dirs.push_back((exe_dir / SELFCAL_LIBRARY_FROM_BIN).lexically_normal().string());
  layout.library_dirs.push_back(exe_dir.string());  // the build tree's layout: the library beside the program
  layout.build_tree = !build_dir.empty() && IsInside(exe_dir, build_dir);
  if (layout.build_tree && source_fallback) {
    layout.data_dirs.push_back({source_dir, "the source tree of this build"});
    layout.data_dirs.push_back({build_dir, "this build tree"});
  }
  return layout;
}

const InstallLayout& ProgramLayout() {
  static const InstallLayout layout = [] {
    std::error_code ec;
    const fs::path self = fs::read_symlink("/proc/self/exe", ec);
    return LayoutOf(ec ? std::string() : self.string(), SELFCAL_LAYOUT_SOURCE_DIR, SELFCAL_LAYOUT_BUILD_DIR,
                    SourceFallbackAllowed());
  }();
  return layout;
}

std::string FindDataFile(const std::string& path) {
  std::error_code ec;  // a symlink loop or an unreadable folder: not found here, the reader says why
  if (path.empty() || fs::exists(path, ec) || fs::path(path).is_absolute()) return path;
  for (const SearchedPlace& place : ProgramLayout().data_dirs) {
    const fs::path candidate = fs::path(place.directory) / path;
    if (fs::exists(candidate, ec)) return candidate.string();
  }
  return path;
}

std::string DescribeDataDirectories() {
  std::string text;
  for (const SearchedPlace& place : ProgramLayout().data_dirs) {
    text += (text.empty() ? "" : "; ") + place.directory + " (" + place.what + ")";
  }
  return text.empty() ? "no data directory (the program's own path could not be read)" : text;
}

}  // namespace selfcal
