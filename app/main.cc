// selfcal: self-calibration of a camera-equipped robot arm (Meng & Zhuang). Subcommands only.
//
// This executable holds the commands that must start fast (calibrate re-solves sessions offline, plan and
// report follow it in scripts) and links only the libraries they use: no camera, display, video, image
// codec or robot stack. Every other command, and `selfcal --help`, is handed to `selfcal-full` beside
// it (main_full.cc), with the same arguments.
#include <cstring>

#include "app/cli_main.h"
#include "base/process_heap.h"

int main(int argc, char** argv) {
  using namespace selfcal::app;
  const std::vector<CommandEntry> fast = {{"calibrate", AddCalibrateCommand},
                                          {"plan", AddPlanCommand},
                                          {"report", AddReportCommand},
                                          {"compensate", AddCompensateCommand}};
  const bool version = argc >= 2 && std::strcmp(argv[1], "--version") == 0;
  bool here = version;
  for (const CommandEntry& entry : fast) here = here || (argc >= 2 && std::strcmp(argv[1], entry.name) == 0);
  if (!here) return RunFullExecutable(argv);
  if (!version) selfcal::PrepareProcessHeap();  // page faults were a fifth of a calibration's CPU (base/process_heap.h)
  return RunCommandLine(argc, argv, fast);
}
