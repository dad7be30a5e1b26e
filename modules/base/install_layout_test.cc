#include "base/install_layout.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <string>

namespace selfcal {
namespace {

namespace fs = std::filesystem;

std::vector<std::string> Directories(const InstallLayout& layout) {
  std::vector<std::string> dirs;
  for (const SearchedPlace& place : layout.data_dirs) dirs.push_back(place.directory);
  return dirs;
}

// An installed program looks under its own prefix only, never in the tree it was built from.
TEST(InstallLayout, AnInstalledProgramFindsItsFilesUnderItsOwnPrefix) {
  const InstallLayout layout = LayoutOf("/opt/p/bin/selfcal", "/home/u/selfcal", "/home/u/selfcal/build/release", true);
  EXPECT_FALSE(layout.build_tree);
  EXPECT_EQ(layout.executable_dir, "/opt/p/bin");
  EXPECT_EQ(Directories(layout), std::vector<std::string>{"/opt/p/share/selfcal"});
  ASSERT_EQ(layout.library_dirs.size(), 2u);
  EXPECT_EQ(layout.library_dirs[0], "/opt/p/lib/selfcal");
  EXPECT_EQ(layout.library_dirs[1], "/opt/p/bin");
}

// A program in its build tree also finds the source tree's config/ and the build's plotly.min.js, after
// the installed layout; SELFCAL_NO_SOURCE_FALLBACK's `false` takes both away.
TEST(InstallLayout, ABuildTreeProgramFallsBackToTheSourceTree) {
  const fs::path root = fs::temp_directory_path() / "selfcal_install_layout_test";
  const std::string source = root.string(), build = (root / "build" / "release").string();
  const std::string exe = (root / "build" / "release" / "app" / "selfcal").string();
  const InstallLayout layout = LayoutOf(exe, source, build, true);
  EXPECT_TRUE(layout.build_tree);
  const std::string installed = (root / "build" / "release" / "share" / "selfcal").string();
  const std::vector<std::string> expected = {installed, source, build};
  EXPECT_EQ(Directories(layout), expected);
  const InstallLayout sealed = LayoutOf(exe, source, build, false);
  EXPECT_TRUE(sealed.build_tree);
  EXPECT_EQ(Directories(sealed), std::vector<std::string>{expected[0]});
}

// "Inside the build directory" compares whole path components: a prefix named like the build directory
// with a suffix (build/release-install) is not inside it.
TEST(InstallLayout, APrefixBesideTheBuildTreeIsNotTheBuildTree) {
  const InstallLayout layout = LayoutOf("/w/build/release-install/bin/selfcal", "/w", "/w/build/release", true);
  EXPECT_FALSE(layout.build_tree);
  EXPECT_EQ(Directories(layout), std::vector<std::string>{"/w/build/release-install/share/selfcal"});
}

TEST(InstallLayout, AnUnknownExecutableSearchesNothing) {
  const InstallLayout layout = LayoutOf("", "/w", "/w/build", true);
  EXPECT_TRUE(layout.data_dirs.empty());
  EXPECT_TRUE(layout.library_dirs.empty());
}

// This test program runs from the build tree: a shipped file's relative name is found in the source tree
// whatever the working directory; an absolute or missing path comes back unchanged.
TEST(InstallLayout, FindDataFileResolvesShippedNamesFromAnyDirectory) {
  ASSERT_TRUE(ProgramLayout().build_tree) << ProgramLayout().executable_dir;
  const std::string found = FindDataFile("config/robots/puma560.yaml");
  EXPECT_EQ(fs::path(found), fs::path(SELFCAL_SOURCE_DIR) / "config/robots/puma560.yaml");
  EXPECT_EQ(FindDataFile("/nonexistent/robot.yaml"), "/nonexistent/robot.yaml");
  EXPECT_EQ(FindDataFile("config/robots/no-such-robot.yaml"), "config/robots/no-such-robot.yaml");
  EXPECT_NE(DescribeDataDirectories().find("(the source tree of this build)"), std::string::npos)
      << DescribeDataDirectories();
}

}  // namespace
}  // namespace selfcal
