// Every option that names a path a command writes is registered here, so that one rule checks all of them
// before the command does any work (session/output_path.h: never inside a session, never over an input,
// never over an existing file without --force; docs/cli-output.md "Output paths"). A command that writes
// gets `--force` with its first file or directory output. RunCommandLine calls CheckOutputOptions for the
// command given and lists every registered option when SELFCAL_LIST_OUTPUT_OPTIONS is set (for the test
// that points each of them into a session; not in the help).
#pragma once

#include <functional>
#include <ostream>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "base/status.h"
#include "session/output_path.h"

namespace selfcal::app {

using session::OutputKind;

// Registers `name` on `cmd` like add_option and records it as an output of `kind` (kDirectory: the command
// writes `files` into it). Returns the option for further settings (->required()).
CLI::Option* AddOutputOption(CLI::App* cmd, const std::string& name, std::string* path, OutputKind kind,
                             const std::string& help, std::vector<std::string> files = {});

// For an output whose path, when not given, follows from other options (identify-tracker's --out: the
// report's directory): the path the check looks at, computed after parsing.
void SetOutputPathWhenEmpty(CLI::App* cmd, const std::string& name, std::function<std::string()> path);

// For inputs no single option names (identify-tracker's --data DIR --file NAME): the paths the check
// compares every output with, computed after parsing.
void AddInputPaths(CLI::App* cmd, std::function<std::vector<std::string>()> inputs);

// Checks the output options of `cmd` and of its chosen subcommands against the rule, the inputs being
// every other option's value (and its ResolveDataPath) that names an existing file. The first refusal.
Status CheckOutputOptions(const CLI::App& cmd);

// One line per registered output option of every command of `app`: "<command>\t<option>\t<kind>".
void ListOutputOptions(const CLI::App& app, std::ostream& out);

// The environment variable that makes RunCommandLine list the output options instead of running.
inline constexpr const char* kListOutputOptionsVariable = "SELFCAL_LIST_OUTPUT_OPTIONS";

}  // namespace selfcal::app
