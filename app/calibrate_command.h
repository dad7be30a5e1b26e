// Shared by `calibrate` and `simulate`: run the calibration on a loaded observation set and write the
// report (and, when accepted, the chosen method's calibrated model) into a directory.
#pragma once

#include <cstdint>
#include <string>

#include <CLI/CLI.hpp>

#include "observations/observation_set.h"
#include "pipeline/bundle_stage.h"
#include "pipeline/paper_pipeline.h"

namespace selfcal::app {

enum class Method { kBundle, kPaper };
inline Method ParseMethod(const std::string& name) { return name == "paper" ? Method::kPaper : Method::kBundle; }

// Registers `--method bundle|paper` (default: whatever *method holds, "bundle").
void AddMethodOption(CLI::App* cmd, std::string* method);

struct CalibrationResult {
  Method method = Method::kBundle;
  pipeline::PaperPipelineReport paper;  // always run: the baseline and the bundle's start
  bool bundle_run = false;
  pipeline::BundleStageReport bundle;   // when method == kBundle
};

// Returns the process exit code of the chosen method's outcome; *result (optional) receives both reports.
int CalibrateAndWrite(const ObservationSet& observations, const std::string& source_path, const std::string& out_dir,
                      uint64_t seed, Method method, CalibrationResult* result);

}  // namespace selfcal::app
