#include "app/cli_output.h"

#include <fcntl.h>
#include <sys/ioctl.h>
#include <unistd.h>

#include <cstdio>
#include <cstring>
#include <iostream>
#include <memory>

#include "report/terminal_progress.h"

namespace selfcal::app {

namespace {

struct OutputState {
  bool json = false;
  bool quiet = false;
  nlohmann::json document = nlohmann::json::object();
  std::unique_ptr<report::TerminalProgress> progress;
};

OutputState& State() {
  static OutputState state;
  return state;
}

int TerminalColumns(int fd) {
  winsize size{};
  if (ioctl(fd, TIOCGWINSZ, &size) == 0 && size.ws_col > 20) return size.ws_col - 1;
  return 100;
}

nlohmann::json EmptyDocument(const std::string& command) {
  return {{"format", kCliResultFormat}, {"version", kCliResultVersion}, {"command", command},
          {"exit_code", nullptr},       {"outcome", nullptr},          {"files", nlohmann::json::object()},
          {"error", nullptr}};
}

// stdout's file descriptor pointed at /dev/null until Restore.
class MutedStdout {
 public:
  MutedStdout() {
    std::cout.flush();
    std::fflush(stdout);
    saved_ = dup(STDOUT_FILENO);
    const int null = open("/dev/null", O_WRONLY | O_CLOEXEC);
    if (saved_ >= 0 && null >= 0) dup2(null, STDOUT_FILENO);
    if (null >= 0) close(null);
  }
  ~MutedStdout() { Restore(); }
  void Restore() {
    if (saved_ < 0) return;
    std::cout.flush();
    std::fflush(stdout);
    dup2(saved_, STDOUT_FILENO);
    close(saved_);
    saved_ = -1;
  }

 private:
  int saved_ = -1;
};

void PrintDocument(const nlohmann::json& document) {
  // Controller and file text inside stays as JSON escapes it (control characters as \u00XX).
  std::cout << document.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) << "\n" << std::flush;
}

}  // namespace

void AddOutputFlags(CLI::App& app) {
  for (CLI::App* sub : app.get_subcommands([](CLI::App*) { return true; })) {
    if (sub->get_option_no_throw("--json") == nullptr) {
      sub->add_flag("--json", State().json,
                    "Print one JSON document on stdout (command, exit code, outcome, files, figures) instead of text "
                    "(docs/cli-output.md)");
    }
    if (sub->get_option_no_throw("--quiet") == nullptr) {
      sub->add_flag("--quiet", State().quiet, "No progress line on stderr");
    }
    AddOutputFlags(*sub);
  }
}

bool JsonMode() { return State().json; }

ProgressSink* Progress() { return State().progress.get(); }

void ClearProgressLine() {
  if (State().progress) State().progress->Clear();
}

nlohmann::json& OutputDocument() { return State().document; }

void AddOutputFile(const std::string& role, const std::string& path) { State().document["files"][role] = path; }

void SetOutcome(const std::string& outcome) { State().document["outcome"] = outcome; }

void RecordError(const std::string& message) {
  nlohmann::json& error = State().document["error"];
  error = error.is_string() ? error.get<std::string>() + "\n" + message : message;
}

int RunWithOutputMode(const std::string& name, const std::function<int()>& command) {
  OutputState& state = State();
  state.document = EmptyDocument(name);
  report::TerminalProgressOptions options;
  options.enabled = report::IsTerminal(STDERR_FILENO) && !state.quiet && !state.json;
  options.width = TerminalColumns(STDERR_FILENO);
  if (options.enabled) state.progress = std::make_unique<report::TerminalProgress>(std::cerr, options);
  if (!state.json) {
    const int code = command();
    state.progress.reset();
    return code;
  }
  MutedStdout muted;
  const int code = command();
  state.progress.reset();
  muted.Restore();
  state.document["exit_code"] = code;
  if (state.document["outcome"].is_null()) state.document["outcome"] = ExitCodeName(static_cast<ExitCode>(code));
  PrintDocument(state.document);
  return code;
}

void PrintUsageErrorDocument(int argc, char** argv, const std::string& message) {
  bool json = false;
  std::string command;
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--json") == 0) json = true;
    if (command.empty() && argv[i][0] != '-') command = argv[i];
  }
  if (!json) return;
  nlohmann::json document = EmptyDocument(command);
  document["exit_code"] = static_cast<int>(ExitCode::kUsage);
  document["outcome"] = ExitCodeName(ExitCode::kUsage);
  document["error"] = message;
  PrintDocument(document);
}

}  // namespace selfcal::app
