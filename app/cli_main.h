// The one command line of both selfcal executables: CLI11's parse, the usage errors, the dispatch to the
// command and its output mode, and the internal-error guard. `selfcal` (main.cc) holds the commands that
// start fast and hands every other command to `selfcal-full` (main_full.cc), which holds them all.
#pragma once

#include <vector>

#include <CLI/CLI.hpp>

#include "app/commands.h"

namespace selfcal::app {

struct CommandEntry {
  const char* name;
  Command (*add)(CLI::App& app);
};

// Registers `entries` on one CLI11 app, parses argv and runs the command given; the process exit code.
int RunCommandLine(int argc, char** argv, const std::vector<CommandEntry>& entries);

// Replaces this process by `selfcal-full` from this executable's directory with the same arguments;
// returns only when that fails, with a message naming the path and ExitCode::kInternal (an incomplete
// installation).
int RunFullExecutable(char** argv);

}  // namespace selfcal::app
