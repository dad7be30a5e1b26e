#include "app/cli_output.h"

#include <fcntl.h>
#include <sys/ioctl.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <map>
#include <memory>
#include <vector>

#include "report/terminal_progress.h"

namespace selfcal::app {

namespace {

struct OutputState {
  bool json = false;
  bool quiet = false;
  nlohmann::json document = nlohmann::json::object();
  std::vector<std::string> files;  // the paths of AddOutputFile in the order written
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

void AddOutputFile(const std::string& role, const std::string& path) {
  State().document["files"][role] = path;
  std::vector<std::string>& files = State().files;
  if (std::find(files.begin(), files.end(), path) == files.end()) files.push_back(path);
}

std::string WrittenFilesText() {
  const std::vector<std::string>& files = State().files;
  if (files.empty()) return "nothing written";
  std::map<std::string, int> per_directory;
  for (const std::string& path : files) ++per_directory[std::filesystem::path(path).parent_path().string()];
  std::string directory = per_directory.begin()->first;
  for (const auto& [name, n] : per_directory) {
    if (n > per_directory[directory]) directory = name;
  }
  // Names in the order written; a name beside one of the same stem is shortened to its extension
  // ("report.json/html").
  std::vector<std::string> names;
  std::string others;
  for (const std::string& path : files) {
    const std::filesystem::path p(path);
    if (p.parent_path().string() != directory) {
      others += ", " + path;
      continue;
    }
    const std::string stem = p.stem().string() + ".";
    auto same_stem = std::find_if(names.begin(), names.end(), [&](const std::string& name) {
      return name.compare(0, stem.size(), stem) == 0;
    });
    if (same_stem != names.end() && p.has_extension()) {
      *same_stem += "/" + p.extension().string().substr(1);
    } else {
      names.push_back(p.filename().string() + (std::filesystem::is_directory(p) ? "/" : ""));
    }
  }
  std::string listed;
  for (const std::string& name : names) listed += (listed.empty() ? "" : ", ") + name;
  return "wrote " + (directory.empty() ? std::string() : directory + "/: ") + listed + others;
}

void PrintFinalLine(const std::string& headline) {
  ClearProgressLine();
  std::cout << headline << "; " << WrittenFilesText() << "\n" << std::flush;
}

void SetOutcome(const std::string& outcome) { State().document["outcome"] = outcome; }

void RecordError(const std::string& message) {
  nlohmann::json& error = State().document["error"];
  error = error.is_string() ? error.get<std::string>() + "\n" + message : message;
}

int RunWithOutputMode(const std::string& name, const std::function<int()>& command) {
  OutputState& state = State();
  state.document = EmptyDocument(name);
  state.files.clear();
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
