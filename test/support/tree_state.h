// A directory tree's state, to show that a command changed nothing in it (a session after an offline
// command or a refused output path). Needs selfcal::base (SHA-256) linked by the test.
#pragma once

#include <sys/stat.h>

#include <filesystem>
#include <map>
#include <string>

#include <gtest/gtest.h>

#include "base/sha256.h"

namespace selfcal::testing {

// Every entry under `root`, directories included: its type and permissions, and for a file its size and
// SHA-256.
inline std::map<std::string, std::string> TreeState(const std::filesystem::path& root) {
  std::map<std::string, std::string> state;
  for (const auto& entry : std::filesystem::recursive_directory_iterator(root)) {
    struct stat info {};
    EXPECT_EQ(::lstat(entry.path().c_str(), &info), 0) << entry.path();
    std::string value = std::to_string(info.st_mode);
    if (S_ISREG(info.st_mode)) {
      value += " " + std::to_string(info.st_size) + " " + Sha256OfFile(entry.path().string()).value();
    }
    state[std::filesystem::relative(entry.path(), root).string()] = value;
  }
  return state;
}

}  // namespace selfcal::testing
