// Helpers shared by io's tests: a private temporary directory and whole-file read/write (test/support/temp_files.h),
// paths into the source tree.
#pragma once

#include <string>

#include "support/temp_files.h"

namespace selfcal::io::testing {

class TempDir : public selfcal::testing::TempDir {
 public:
  TempDir() : selfcal::testing::TempDir("selfcal_io_test") {}
};
using selfcal::testing::ReadFile;
using selfcal::testing::WriteFile;

inline std::string SourcePath(const std::string& relative) { return std::string(SELFCAL_SOURCE_DIR) + "/" + relative; }

}  // namespace selfcal::io::testing
