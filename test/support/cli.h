// The selfcal binary from a CLI test (test/integration): SELFCAL_BINARY and SELFCAL_SOURCE_DIR are the
// test target's compile definitions, expanded where this header is included.
#pragma once

#include <unistd.h>

#include <filesystem>
#include <string>

#include "support/run_binary.h"

namespace selfcal::testing {

// `selfcal arguments` in the test's working directory; stderr folded into stdout, which goes to *output
// when given. Returns the exit code (-1 when it did not exit normally).
inline int RunSelfcal(const std::string& arguments, std::string* output = nullptr) {
  std::string ignored;
  return RunBinary(SELFCAL_BINARY, arguments, output != nullptr ? output : &ignored);
}

#ifdef SELFCAL_SOURCE_DIR
// The same from the source tree, where the shipped config/ paths of the arguments resolve.
inline int RunSelfcalInSource(const std::string& arguments, std::string* output = nullptr) {
  std::string ignored;
  return RunBinary("cd " + std::string(SELFCAL_SOURCE_DIR) + " && " + SELFCAL_BINARY, arguments,
                   output != nullptr ? output : &ignored);
}
#endif

// An empty directory under the system's temporary directory, named after the suite, the process and
// `name`; whatever a previous run left there is removed first.
inline std::filesystem::path FreshDir(const std::string& suite, const std::string& name) {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("selfcal_" + suite + "_" + std::to_string(::getpid()) + "_" + name);
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

}  // namespace selfcal::testing
