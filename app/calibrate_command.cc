// selfcal calibrate OBSERVATIONS --out DIR: the paper's pipeline on an observations file
// (docs/observations-format.md); writes the calibrated model (YAML) and a report (JSON).
#include <filesystem>
#include <iostream>

#include "app/cli_util.h"
#include "app/commands.h"
#include "app/report_format.h"
#include "io/report_json.h"
#include "io/observations_file.h"
#include "io/robot_config.h"

namespace selfcal::app {

namespace {

struct CalibrateArgs {
  std::string observations;
  std::string out = "out/calibration";
  uint64_t seed = 1;
};

}  // namespace

// Shared with `simulate`: run the pipeline on a loaded set and write the results into out_dir.
int CalibrateAndWrite(const ObservationSet& obs, const std::string& source_path, const std::string& out_dir,
                      uint64_t seed, pipeline::PaperPipelineReport* report_out) {
  pipeline::PaperPipelineOptions options;
  options.two_view.seed = seed;
  const pipeline::PaperPipelineReport report = pipeline::RunPaperPipeline(obs, options);
  PrintCalibrationSummary(report, std::cout);
  nlohmann::json json = CalibrationReportJson(obs, report);
  json["input"] = {{"path", source_path}, {"fnv1a64", FileHash(source_path)}};
  const ExitCode code = ExitCodeFor(report.outcome);
  json["exit_code"] = static_cast<int>(code);
  json["accepted"] = code == ExitCode::kOk;
  const std::string report_path = (std::filesystem::path(out_dir) / "report.json").string();
  if (Status s = io::WriteJsonFile(json, report_path); !s.ok()) return Fail(s);
  std::cout << "report: " << report_path << "\n";
  // K4: a model is written only for an accepted result; failures leave the diagnostics (report) only.
  if (code == ExitCode::kOk) {
    const std::string model_path = (std::filesystem::path(out_dir) / "calibrated_model.yaml").string();
    io::CalibratedModel model;
    model.model = report.calibrated_robot;
    model.fx_px = report.fx_px;
    model.source = "selfcal calibrate " + source_path;
    model.provenance = {{"software_version", SELFCAL_VERSION},
                        {"input_fnv1a64", FileHash(source_path)},
                        {"method", "paper pipeline"}};
    if (Status s = io::SaveCalibratedModel(model, model_path); !s.ok()) return Fail(s);
    std::cout << "calibrated model: " << model_path << "\n";
  } else {
    std::cerr << "selfcal: " << ExitCodeName(code) << ": " << report.message << " (no calibrated model written)\n";
  }
  if (report_out != nullptr) *report_out = report;
  return static_cast<int>(code);
}

Command AddCalibrateCommand(CLI::App& app) {
  auto args = std::make_shared<CalibrateArgs>();
  CLI::App* cmd = app.add_subcommand("calibrate", "Run the paper's pipeline on an observations file");
  cmd->add_option("observations", args->observations, "Observations file (docs/observations-format.md)")->required();
  cmd->add_option("--out", args->out, "Output directory (created if missing)");
  cmd->add_option("--seed", args->seed, "Seed of the RANSAC sampling (results are deterministic per seed)");
  return [args]() {
    Result<ObservationSet> obs = io::LoadObservations(args->observations);
    if (!obs.ok()) return Fail(obs.status());
    if (Status s = EnsureDirectory(args->out); !s.ok()) return Fail(s);
    return CalibrateAndWrite(*obs, args->observations, args->out, args->seed, nullptr);
  };
}

}  // namespace selfcal::app
