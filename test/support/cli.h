// The selfcal binary from a CLI test (test/integration): SELFCAL_BINARY and SELFCAL_SOURCE_DIR are the
// test target's compile definitions, expanded where this header is included.
#pragma once

#include <unistd.h>

#include <filesystem>
#include <sstream>
#include <string>

#include "support/run_binary.h"
#include "support/temp_files.h"

namespace selfcal::testing {

// Whether a command's output (or any text) contains `part`.
inline bool Contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

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

// The first `n` poses of the shipped PUMA arc as a plan file, the first `identify` of them identifying.
inline void WriteShortPlan(const std::filesystem::path& path, int n, int identify) {
  std::istringstream in(ReadFile(std::string(SELFCAL_SOURCE_DIR) + "/config/trajectories/initial_puma560.yaml"));
  std::string text, line;
  int poses = 0;
  while (std::getline(in, line)) {
    const bool pose = line.rfind("  - [", 0) == 0;
    if (pose && poses++ >= n) continue;
    if (line.rfind("poses_rad:", 0) == 0) text += "num_identification_poses: " + std::to_string(identify) + "\n";
    text += line + "\n";
  }
  WriteFile(path.string(), text);
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
