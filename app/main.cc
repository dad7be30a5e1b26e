// selfcal: self-calibration of a camera-equipped robot arm (Meng & Zhuang). Subcommands only.
#include <exception>
#include <iostream>

#include "app/cli_help.h"
#include "app/cli_output.h"
#include "app/cli_util.h"
#include "app/commands.h"
#include "base/status.h"

int main(int argc, char** argv) {
  CLI::App app{"selfcal: self-calibration of a camera-equipped robot arm from images of unknown dots"};
  app.set_version_flag("--version", SELFCAL_VERSION);
  app.require_subcommand(1);
  // Every option's default in --help (inherited by the subcommands added below).
  app.option_defaults()->always_capture_default();
  const std::pair<const char*, selfcal::app::Command> commands[] = {
      {"calibrate", selfcal::app::AddCalibrateCommand(app)},
      {"simulate", selfcal::app::AddSimulateCommand(app)},
      {"study", selfcal::app::AddStudyCommand(app)},
      {"identifiability", selfcal::app::AddIdentifiabilityCommand(app)},
      {"make-trajectory", selfcal::app::AddMakeTrajectoryCommand(app)},
      {"identify-tracker", selfcal::app::AddTrackerCommand(app)},
      {"plan", selfcal::app::AddPlanCommand(app)},
      {"run", selfcal::app::AddRunCommand(app)},
      {"audit", selfcal::app::AddAuditCommand(app)},
      {"name-dots", selfcal::app::AddNameDotsCommand(app)},
      {"session", selfcal::app::AddSessionCommand(app)},
      {"detect", selfcal::app::AddDetectCommand(app)},
      {"report", selfcal::app::AddReportCommand(app)},
      {"compensate", selfcal::app::AddCompensateCommand(app)}};
  selfcal::app::AddOutputFlags(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // CLI11 exits 0 for --help and --version; every real usage error maps to exit code 2, a mistyped
    // command or option with the nearest known name.
    if (e.get_exit_code() == 0) return app.exit(e);
    std::string message = selfcal::app::UnknownNameMessage(app, argc, argv);
    if (message.empty()) {
      app.exit(e);
      message = e.what();
    } else {
      std::cerr << message << "\n";
    }
    selfcal::app::PrintUsageErrorDocument(argc, argv, message);
    return static_cast<int>(selfcal::app::ExitCode::kUsage);
  }
  try {
    for (const auto& [name, command] : commands) {
      if (!app.got_subcommand(name)) continue;
      std::string full_name = name;
      for (const CLI::App* sub : app.get_subcommand(name)->get_subcommands()) full_name += " " + sub->get_name();
      return selfcal::app::RunWithOutputMode(full_name, command);
    }
  } catch (const std::exception& e) {
    // Nothing the user did explains an exception escaping a command: every expected failure is a Status
    // or an outcome. Say so, and exit with a code of its own rather than pretend the solver failed.
    std::cerr << "selfcal: internal error: " << e.what()
              << "\nThis is a bug in selfcal " << SELFCAL_VERSION
              << ": please report it with the command line and this message.\n";
    return static_cast<int>(selfcal::app::ExitCode::kInternal);
  }
  return static_cast<int>(selfcal::app::ExitCode::kUsage);
}
