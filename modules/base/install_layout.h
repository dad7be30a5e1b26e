#pragma once
// Where a selfcal program finds the files that ship with it. `cmake --install` (and the Debian package)
// lays them out under one prefix (GNUInstallDirs; the relative paths are fixed when CMake configures):
//
//   <prefix>/bin/selfcal, selfcal-full, selfcal-robot-sim
//   <prefix>/lib/selfcal/libselfcal_camera_formats.so   (loaded by `selfcal`, io/camera_formats.h)
//   <prefix>/share/selfcal/config/robots/, config/trajectories/
//   <prefix>/share/selfcal/plotly.min.js                 (inlined into report.html)
//   <prefix>/share/doc/selfcal/
//
// Every place is found from the running executable (/proc/self/exe), so a copied or moved prefix works
// and an installed program never reads the tree it was built from. A program run from its own build tree
// (its executable under the build directory CMake configured) also looks, after the installed layout, in
// the source tree's root (config/) and in the build directory (the minified plotly.js), unless the
// environment sets SELFCAL_NO_SOURCE_FALLBACK=1.
#include <string>
#include <vector>

namespace selfcal {

// One directory searched for a shipped file, and what it is (for messages that list what was searched).
struct SearchedPlace {
  std::string directory;
  std::string what;
};

// The places of one executable. `executable`: its absolute path; `source_fallback`: whether a program
// inside `build_dir` may also look in `source_dir` and `build_dir`.
struct InstallLayout {
  std::string executable_dir;                 // "" when the executable is unknown
  std::vector<SearchedPlace> data_dirs;       // config/..., plotly.min.js: in search order
  std::vector<std::string> library_dirs;      // selfcal's private libraries: in search order
  bool build_tree = false;                    // the executable is inside build_dir
};
InstallLayout LayoutOf(const std::string& executable, const std::string& source_dir, const std::string& build_dir,
                       bool source_fallback);

// The layout of the running program: LayoutOf(/proc/self/exe, this build's source and build directories,
// SELFCAL_NO_SOURCE_FALLBACK unset).
const InstallLayout& ProgramLayout();

// `path` as given when it exists or is absolute; else the first data directory holding it (so that the
// shipped defaults such as config/robots/puma560.yaml work from any directory); else `path` unchanged
// (its reader then says it is missing).
std::string FindDataFile(const std::string& path);

// The data directories searched, "DIR (what)" joined by "; ": for messages about a shipped file not found.
std::string DescribeDataDirectories();

}  // namespace selfcal
