// A loopback fake controller program run from a test (selfcal-ur-fake, selfcal-fanuc-fake): started with its
// stdout kept in a log file, waited for until its first line says where it listens, stopped with SIGTERM.
#pragma once

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "support/temp_files.h"

namespace selfcal::testing {

class LoopbackFake {
 public:
  // Runs `args` (the program first) with stdout into `log`; waits up to 2 s for `listening`, given the log
  // so far, to return true (it reads the ports from the first line).
  LoopbackFake(std::vector<std::string> args, const std::filesystem::path& log,
               const std::function<bool(const std::string&)>& listening)
      : log_(log) {
    const pid_t pid = ::fork();
    if (pid == 0) {
      std::FILE* out = std::fopen(log.c_str(), "w");
      ::dup2(::fileno(out), 1);
      std::vector<char*> argv;
      for (std::string& a : args) argv.push_back(a.data());
      argv.push_back(nullptr);
      ::execv(argv[0], argv.data());
      ::_exit(127);
    }
    pid_ = pid;
    for (int i = 0; i < 200 && !listening(ReadFile(log.string())); ++i) ::usleep(10000);
  }
  LoopbackFake(const LoopbackFake&) = delete;
  LoopbackFake& operator=(const LoopbackFake&) = delete;
  ~LoopbackFake() { Stop(); }

  // Stops the fake; returns everything it printed.
  std::string Stop() {
    if (pid_ > 0) {
      ::kill(pid_, SIGTERM);
      int status = 0;
      ::waitpid(pid_, &status, 0);
      pid_ = -1;
    }
    return ReadFile(log_.string());
  }

 private:
  std::filesystem::path log_;
  pid_t pid_ = -1;
};

}  // namespace selfcal::testing
