// Helpers shared by io's tests: a private temporary directory and whole-file read/write (test/support/temp_files.h),
// paths into the source tree.
#pragma once

#include <string>

#include "support/temp_files.h"

namespace selfcal::io::testing {

inline constexpr char kTempDirPrefix[] = "selfcal_io_test";
using TempDir = selfcal::testing::NamedTempDir<kTempDirPrefix>;
using namespace selfcal::testing;  // ReadFile, WriteFile and the other helpers of temp_files.h

inline std::string SourcePath(const std::string& relative) { return std::string(SELFCAL_SOURCE_DIR) + "/" + relative; }

}  // namespace selfcal::io::testing
