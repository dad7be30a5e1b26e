// selfcal-full: every selfcal command (`selfcal` runs its fast-starting ones itself and hands the others
// here, main.cc). Subcommands only.
#include "app/cli_main.h"

int main(int argc, char** argv) {
  using namespace selfcal::app;
  return RunCommandLine(argc, argv, {{"calibrate", AddCalibrateCommand},
                                     {"simulate", AddSimulateCommand},
                                     {"study", AddStudyCommand},
                                     {"identifiability", AddIdentifiabilityCommand},
                                     {"make-trajectory", AddMakeTrajectoryCommand},
                                     {"identify-tracker", AddTrackerCommand},
                                     {"plan", AddPlanCommand},
                                     {"run", AddRunCommand},
                                     {"audit", AddAuditCommand},
                                     {"name-dots", AddNameDotsCommand},
                                     {"session", AddSessionCommand},
                                     {"detect", AddDetectCommand},
                                     {"report", AddReportCommand},
                                     {"compensate", AddCompensateCommand}});
}
