// What a command shows besides its files: `--json` (exactly one JSON document on stdout, human text
// gone), `--quiet` and the progress line of long steps on stderr (report/terminal_progress.h, quiet when
// stderr is not a terminal). Set up once by main(); the commands fill the document and hand Progress()
// to the library entry points. docs/cli-output.md describes the document.
#pragma once

#include <string>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "app/exit_codes.h"
#include "base/progress.h"

namespace selfcal::app {

inline constexpr const char* kCliResultFormat = "selfcal-cli-result";
inline constexpr int kCliResultVersion = 1;

// Adds --json and --quiet to every subcommand of `app` (and theirs), except one that already has an
// option of that name (audit's --json FILE).
void AddOutputFlags(CLI::App& app);

// Whether --json was given (after parsing).
bool JsonMode();

// The terminal's progress line, or null when it is quiet: hand it to the library's options.
ProgressSink* Progress();

// Erases the progress line before other text goes to the terminal (the session's log lines).
void ClearProgressLine();

// The command's JSON document: {format, version, command, exit_code, outcome, files, error, ...}. A
// command adds its figures under its own keys and its files with AddOutputFile.
nlohmann::json& OutputDocument();

// A file the command wrote, under `role` (e.g. "report", "calibrated_model").
void AddOutputFile(const std::string& role, const std::string& path);

// The files this command wrote, short: "wrote DIR/: a, b, c" for the directory holding most of them and
// the others by their path; "nothing written" when none.
std::string WrittenFilesText();

// The last line of a command's stdout (docs/cli-output.md): `headline` (the verdict or outcome word and
// the figure it rests on) and WrittenFilesText(), separated by "; ".
void PrintFinalLine(const std::string& headline);

// The outcome's name when more precise than the exit code's (a verdict, a run outcome).
void SetOutcome(const std::string& outcome);

// The error message of a failed command (Fail() records it).
void RecordError(const std::string& message);

// Runs `command` as `name` in the output mode main() parsed: with --json, stdout (the file descriptor,
// so that no library's print slips through) goes to /dev/null while it runs and the document is printed
// after; the progress line is drawn on stderr when it is a terminal. Returns the command's exit code.
int RunWithOutputMode(const std::string& name, const std::function<int()>& command);

// The document of a command line that did not parse (exit 2), printed when argv holds --json.
void PrintUsageErrorDocument(int argc, char** argv, const std::string& message);

}  // namespace selfcal::app
