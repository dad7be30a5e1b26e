// Running a program of the build from a CLI test: its exit code and everything it printed.
#pragma once

#include <sys/wait.h>

#include <cstdio>
#include <string>

namespace selfcal::testing {

// Runs `binary arguments` through the shell with stderr folded into stdout; returns the exit code (-1
// when it did not exit normally), the output in *output.
inline int RunBinary(const std::string& binary, const std::string& arguments, std::string* output) {
  output->clear();
  FILE* pipe = ::popen((binary + " " + arguments + " 2>&1").c_str(), "r");
  if (pipe == nullptr) return -1;
  char buffer[4096];
  for (size_t n; (n = std::fread(buffer, 1, sizeof(buffer), pipe)) > 0;) output->append(buffer, n);
  const int status = ::pclose(pipe);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

}  // namespace selfcal::testing
