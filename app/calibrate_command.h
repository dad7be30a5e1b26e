// The calibrate command's three steps, shared with `simulate`: load (an observations file or a session
// directory), run the calibration facade (calibration/calibrate.h), write what it returns (report.json
// always, calibrated_model.yaml only when accepted) and map its verdict to the exit code.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "calibration/calibrate.h"
#include "observations/observation_set.h"

namespace selfcal::app {

// "paper" -> kPaper, anything else the default kBundle (CLI11 has checked the name).
inline calibration::Method MethodFromName(const std::string& name) {
  return calibration::ParseMethod(name).value_or(calibration::Method::kBundle);
}

// Registers `--method bundle|paper` (default: whatever *method holds, "bundle").
void AddMethodOption(CLI::App* cmd, std::string* method);

// Registers --fix and --free (comma-separated parameter names and groups).
void AddParameterMaskOptions(CLI::App* cmd, std::vector<std::string>* fix, std::vector<std::string>* free);

struct CalibrateRequest {
  std::string input;  // observations file or session directory
  std::string out_dir;
  uint64_t seed = 1;  // RANSAC sampling of the two-view step
  calibration::Method method = calibration::Method::kBundle;
  std::vector<std::string> fix{}, free{};  // parameter names and groups (bundle::BundleOptions::held_parameters)
  std::string scale_from = "auto";     // flange-pose sets: "auto", "flange" or "yardstick" (CalibrateOptions)
  // Weak directions: the manufacturing tolerances above which a poorly determined joint parameter is held at
  // the robot description's value (bundle::BundleOptions::weak_length_tolerance_m; 0: never held).
  double weak_tolerance_mm = 5.0, weak_tolerance_deg = 0.5;
  bool pixel_noise_only = false;  // no estimated pose error in the covariance
  // Without verification poses: k-fold cross-validation over the identification poses (0: not run);
  // folds_given: named on the command line, so that too few poses for it is an error, not a note.
  int folds = 4;
  bool folds_given = false;
  // A camera file (io/camera_file.h) whose intrinsics replace the observations' camera, and the camera
  // chosen in a ViSP file (empty: its only one; also the name written to write_camera_visp).
  std::string camera_file{}, camera_name{};
  // Where to write the calibrated intrinsics (empty: not written), only when accepted.
  std::string write_camera_opencv{}, write_camera_visp{};
  bool html = true;  // also write report.html beside report.json (--no-html: not)
  // The robot config the data was recorded with, for the exports in its convention and names (simulate
  // sets it; empty: the input's own robot: a session's robot.yaml, an observations file's robot).
  std::string robot_config{};
  // Further observations files of the same arm (--also), pooled with `input`, each recording a scene of its
  // own named by its file name (observations/pool_recordings.h).
  std::vector<std::string> also{};
};

// What a calibration read and returned, for callers that compare it with a truth (`simulate`).
struct CalibrationRun {
  ObservationSet observations;
  calibration::CalibrationReport report;
  bool solved = false;  // the calibration ran and its report was written (report holds its verdict)
};

// The last line of `calibrate` (docs/cli-output.md): the verdict, the held-out figure it rests on and the
// files written; for a command that stopped before a verdict, the exit code's name.
std::string CalibrationFinalLine(const CalibrationRun& run, int exit_code);

// The names calibrate (and simulate, through it) may write into its output directory: one that holds any
// of them is refused without --force (output_options.h).
std::vector<std::string> CalibrationOutputFiles();

// Loads request.input (a session directory when it holds session.json), calibrates, writes into
// request.out_dir; returns the process exit code. *run (optional) receives the observations and report.
int CalibrateAndWrite(const CalibrateRequest& request, CalibrationRun* run = nullptr);

}  // namespace selfcal::app
