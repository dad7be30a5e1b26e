// Helpers shared by io's tests: a private temporary directory and whole-file read/write (test/support/temp_files.h),
// paths into the source tree.
#pragma once

#include <string>

#include <gtest/gtest.h>

#include "base/status.h"
#include "support/temp_files.h"

namespace selfcal::io::testing {

inline constexpr char kTempDirPrefix[] = "selfcal_io_test";
using TempDir = selfcal::testing::NamedTempDir<kTempDirPrefix>;
using namespace selfcal::testing;  // ReadFile, WriteFile and the other helpers of temp_files.h

// An error whose message holds `part`.
inline ::testing::AssertionResult MessageHas(const Status& s, const std::string& part) {
  if (s.ok()) return ::testing::AssertionFailure() << "OK, expected an error with `" << part << "`";
  if (s.message().find(part) == std::string::npos) {
    return ::testing::AssertionFailure() << "`" << part << "` not in:\n" << s.message();
  }
  return ::testing::AssertionSuccess();
}

inline std::string SourcePath(const std::string& relative) { return std::string(SELFCAL_SOURCE_DIR) + "/" + relative; }

}  // namespace selfcal::io::testing
