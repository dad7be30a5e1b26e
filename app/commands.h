// The application (app/, ARCHITECTURE.md): only parse -> load -> one library entry point -> write, and the
// mapping of verdicts and error codes to exit codes (exit_codes.h). Two executables share one command line
// (cli_main.h): `selfcal` (main.cc) runs calibrate, plan, report and compensate itself, linked --as-needed
// against only what they use (no OpenCV, no ViSP, no robot or capture code; camera files through
// libselfcal_camera_formats.so, which io loads by dlopen, io/camera_formats.h), and hands every other command
// and --help to `selfcal-full` beside it (main_full.cc, every command) by execv with the same arguments.
// `selfcal-robot-sim` (robot_sim_main.cc) is the network protocol's loopback server around the simulated
// robot; `selfcal-ur-fake` (ur_fake_main.cc) the loopback fake of a Universal Robots controller for tests.
//   run (run_command_line.cc) robot + camera -> session directory (acquisition::RunSession)
//   calibrate                 observations file or session directory -> calibration::Calibrate -> report.json,
//                             report.html, image_residuals.csv and, when accepted, calibrated_model.yaml with the
//                             exports of model_exports.h (calibrated.urdf, calibrated_robot.yaml when the entered
//                             DH convention holds the model exactly, camera_static_transform.yaml and .launch.py,
//                             camera_info.yaml, ur_calibrated_kinematics.yaml for a UR arm); recorded joints
//                             outside the limits warned of by pose; --camera-file, --write-camera-opencv/-visp
//   simulate                  end to end on the simulated cell through a session (--points: the fast mode)
//   study, identifiability, make-trajectory, plan (and plan --check), report (report.json or a study document
//                             -> report.html; plotly.js located and read in report_command.cc)
//   identify-tracker          tracker_command.cc: also calibrated_model.yaml and calibrated.urdf (no J3 coupling)
//   compensate                target poses -> joint angles (compensation::Compensate); exit 7 beyond the limits
//   audit                     a simulated session's dot identities against the hidden truth
//   name-dots                 one frame named for the operator: yardstick and reference dots into the setup
//   detect                    images and robot poses (or a rosbag2 MCAP) -> observations file + contact sheet
//   session discard           removes a session directory that recorded nothing
// Shared by every command: --json, --quiet and the progress line (cli_output.h, docs/cli-output.md); every
// option naming a written path registered by AddOutputOption (output_options.h, which adds --force) and
// checked by session::CheckOutputPath before the command runs (SELFCAL_LIST_OUTPUT_OPTIONS=1 lists them for the
// tests); did-you-mean of mistyped commands and options (cli_help.h); every numeric option checked where CLI11
// reads it (cli_numbers.h: decimal integers, not negative, within 64 bits; finite numbers).
//
// The selfcal subcommands. Each registers its options on the CLI11 app and returns the process exit code
// (../shared/RELIABILITY.md design rule 2) when run.
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
