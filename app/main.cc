// selfcal: self-calibration of a camera-equipped robot arm (Meng & Zhuang). Subcommands only.
#include <exception>
#include <iostream>

#include "app/cli_util.h"
#include "app/commands.h"
#include "base/status.h"

int main(int argc, char** argv) {
  CLI::App app{"selfcal: self-calibration of a camera-equipped robot arm from images of unknown dots"};
  app.set_version_flag("--version", SELFCAL_VERSION);
  app.require_subcommand(1);
  const selfcal::app::Command calibrate = selfcal::app::AddCalibrateCommand(app);
  const selfcal::app::Command simulate = selfcal::app::AddSimulateCommand(app);
  const selfcal::app::Command study = selfcal::app::AddStudyCommand(app);
  const selfcal::app::Command identifiability = selfcal::app::AddIdentifiabilityCommand(app);
  const selfcal::app::Command make_trajectory = selfcal::app::AddMakeTrajectoryCommand(app);
  const selfcal::app::Command identify_tracker = selfcal::app::AddTrackerCommand(app);
  const selfcal::app::Command plan = selfcal::app::AddPlanCommand(app);
  const selfcal::app::Command run = selfcal::app::AddRunCommand(app);
  const selfcal::app::Command audit = selfcal::app::AddAuditCommand(app);
  const selfcal::app::Command name_dots = selfcal::app::AddNameDotsCommand(app);
  const selfcal::app::Command session = selfcal::app::AddSessionCommand(app);
  const selfcal::app::Command detect = selfcal::app::AddDetectCommand(app);
  const selfcal::app::Command report = selfcal::app::AddReportCommand(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // CLI11 exits 0 for --help and --version; every real usage error maps to exit code 2 (C9).
    const int code = app.exit(e);
    return code == 0 ? 0 : static_cast<int>(selfcal::app::ExitCode::kUsage);
  }
  try {
    for (const auto& [name, command] :
         {std::pair{"calibrate", calibrate}, {"simulate", simulate}, {"study", study},
          {"identifiability", identifiability}, {"make-trajectory", make_trajectory}, {"identify-tracker", identify_tracker}, {"plan", plan},
          {"run", run}, {"audit", audit}, {"name-dots", name_dots}, {"session", session}, {"detect", detect},
          {"report", report}}) {
      if (app.got_subcommand(name)) return command();
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
