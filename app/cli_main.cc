#include "app/cli_main.h"

#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <filesystem>
#include <iostream>
#include <string>
#include <utility>

#include "app/cli_help.h"
#include "app/cli_numbers.h"
#include "app/cli_output.h"
#include "app/cli_util.h"
#include "app/output_options.h"

namespace selfcal::app {

int RunCommandLine(int argc, char** argv, const std::vector<CommandEntry>& entries) {
  CLI::App app{"selfcal: self-calibration of a camera-equipped robot arm from images of unknown dots"};
  app.set_version_flag("--version", SELFCAL_VERSION);
  app.require_subcommand(1);
  // Every option's default in --help (inherited by the subcommands added below).
  app.option_defaults()->always_capture_default();
  std::vector<std::pair<const char*, Command>> commands;
  for (const CommandEntry& entry : entries) commands.emplace_back(entry.name, entry.add(app));
  AddOutputFlags(app);
  if (argc == 1 && std::getenv(kListOutputOptionsVariable) != nullptr) {  // for the output-path test; not in the help
    ListOutputOptions(app, std::cout);
    return static_cast<int>(ExitCode::kOk);
  }
  CheckNumbersStrictly(app);
  // CLI11 answers --help before it looks at the other words, so `selfcal calibrat --help` would print
  // the top-level help and exit 0: a mistyped command or option beside --help is a usage error too.
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--") == 0) break;
    if (std::strcmp(argv[i], "--help") != 0 && std::strcmp(argv[i], "-h") != 0) continue;
    if (const std::string message = UnknownNameMessage(app, argc, argv); !message.empty()) {
      std::cerr << message << "\n";
      PrintUsageErrorDocument(argc, argv, message);
      return static_cast<int>(ExitCode::kUsage);
    }
    break;
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // CLI11 exits 0 for --help and --version; every real usage error maps to exit code 2, a mistyped
    // command or option with the nearest known name.
    if (e.get_exit_code() == 0) return app.exit(e);
    std::string message = UnknownNameMessage(app, argc, argv);
    if (message.empty()) {
      app.exit(e);
      message = e.what();
    } else {
      std::cerr << message << "\n";
    }
    PrintUsageErrorDocument(argc, argv, message);
    return static_cast<int>(ExitCode::kUsage);
  }
  try {
    for (const auto& [name, command] : commands) {
      if (!app.got_subcommand(name)) continue;
      std::string full_name = name;
      for (const CLI::App* sub : app.get_subcommand(name)->get_subcommands()) full_name += " " + sub->get_name();
      // Every output path is checked before the command does any work (output_options.h).
      const CLI::App& chosen = *app.get_subcommand(name);
      return RunWithOutputMode(full_name, [&chosen, &command]() {
        if (Status s = CheckOutputOptions(chosen); !s.ok()) return Fail(s);
        return command();
      });
    }
  } catch (const std::exception& e) {
    // Nothing the user did explains an exception escaping a command: every expected failure is a Status
    // or an outcome. Say so, and exit with a code of its own rather than pretend the solver failed.
    std::cerr << "selfcal: internal error: " << e.what() << "\nThis is a bug in selfcal " << SELFCAL_VERSION
              << ": please report it with the command line and this message.\n";
    return static_cast<int>(ExitCode::kInternal);
  }
  return static_cast<int>(ExitCode::kUsage);
}

int RunFullExecutable(char** argv) {
  std::error_code error;
  const std::filesystem::path self = std::filesystem::read_symlink("/proc/self/exe", error);
  const std::string full = (error ? std::filesystem::path(argv[0]) : self).parent_path() / "selfcal-full";
  ::execv(full.c_str(), argv);
  std::cerr << "selfcal: cannot start " << full << ": " << std::strerror(errno)
            << "\nselfcal runs calibrate, plan, report and compensate itself and every other command through "
               "selfcal-full, which must be installed beside it.\n";
  return static_cast<int>(ExitCode::kInternal);
}

}  // namespace selfcal::app
