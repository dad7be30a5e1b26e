// The selfcal subcommands. Each registers its options on the CLI11 app and returns the process exit code
// (RELIABILITY.md design rule 2) when run.
#pragma once

#include <functional>

#include <CLI/CLI.hpp>

namespace selfcal::app {

using Command = std::function<int()>;

Command AddCalibrateCommand(CLI::App& app);
Command AddSimulateCommand(CLI::App& app);
Command AddStudyCommand(CLI::App& app);
Command AddIdentifiabilityCommand(CLI::App& app);
Command AddMakeTrajectoryCommand(CLI::App& app);
Command AddTrackerCommand(CLI::App& app);
Command AddPlanCommand(CLI::App& app);
Command AddRunCommand(CLI::App& app);
Command AddAuditCommand(CLI::App& app);
Command AddNameDotsCommand(CLI::App& app);
Command AddSessionCommand(CLI::App& app);
Command AddDetectCommand(CLI::App& app);
Command AddReportCommand(CLI::App& app);
Command AddCompensateCommand(CLI::App& app);

}  // namespace selfcal::app
