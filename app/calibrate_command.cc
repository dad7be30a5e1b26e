// selfcal calibrate OBSERVATIONS --out DIR [--method bundle|paper]: the paper's pipeline on an
// observations file (docs/observations-format.md), then (by default) the kinematic bundle adjustment
// started from its result; writes the chosen method's calibrated model (YAML) and a report (JSON).
#include "app/calibrate_command.h"

#include "app/session_command.h"

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
  std::string method = "bundle";
};

}  // namespace

void AddMethodOption(CLI::App* cmd, std::string* method) {
  cmd->add_option("--method", *method,
                  "bundle: the paper's pipeline, then the kinematic bundle adjustment started from it (the product); "
                  "paper: the paper's pipeline alone (the baseline)")
      ->check(CLI::IsMember({"bundle", "paper"}));
}

int CalibrateAndWrite(const ObservationSet& obs, const std::string& source_path, const std::string& out_dir,
                      uint64_t seed, Method method, CalibrationResult* result_out) {
  CalibrationResult result;
  result.method = method;
  pipeline::PaperPipelineOptions options;
  options.two_view.seed = seed;
  // The paper pipeline always runs: it is the baseline and the bundle adjustment's start.
  result.paper = pipeline::RunPaperPipeline(obs, options);
  const pipeline::PaperPipelineReport& paper = result.paper;
  std::cout << "paper pipeline (Meng & Zhuang):\n";
  PrintCalibrationSummary(paper, std::cout);
  nlohmann::json json = CalibrationReportJson(obs, paper);
  json["paper_pipeline"] = {{"outcome", pipeline::OutcomeName(paper.outcome)},
                            {"message", paper.message},
                            {"exit_code", static_cast<int>(ExitCodeFor(paper.outcome))},
                            {"description", json["method"]}};
  ExitCode code = ExitCodeFor(paper.outcome);
  std::string message = paper.message;
  if (method == Method::kBundle) {
    result.bundle = pipeline::RunBundleStage(obs, paper, pipeline::BundleStageOptions());
    result.bundle_run = true;
    std::cout << "\n";
    PrintBundleSummary(result.bundle, std::cout);
    json["bundle"] = BundleReportJson(obs, result.bundle);
    json["timing_s"]["bundle"] = result.bundle.bundle.seconds;
    json["outcome"] = bundle::OutcomeName(result.bundle.bundle.outcome);
    code = ExitCodeFor(result.bundle.bundle.outcome);
    message = result.bundle.bundle.message;
  }
  json["method"] = method == Method::kBundle ? "bundle" : "paper";
  json["message"] = message;
  json["input"] = {{"path", source_path}, {"sha256", FileSha256(source_path)}};
  json["exit_code"] = static_cast<int>(code);
  json["accepted"] = code == ExitCode::kOk;
  const std::string report_path = (std::filesystem::path(out_dir) / "report.json").string();
  if (Status s = io::WriteJsonFile(json, report_path); !s.ok()) return Fail(s);
  std::cout << "report: " << report_path << "\n";
  // K4: a model is written only for an accepted result; failures leave the diagnostics (report) only.
  if (code == ExitCode::kOk) {
    const std::string model_path = (std::filesystem::path(out_dir) / "calibrated_model.yaml").string();
    io::CalibratedModel model;
    if (method == Method::kBundle) {
      model.model = result.bundle.calibrated_robot;
      model.fx_px = result.bundle.bundle.fx_px;
      model.parameters = result.bundle.bundle.rho;  // on the nominal model of the observations file
    } else {
      model.model = paper.calibrated_robot;
      model.fx_px = paper.fx_px;
    }
    model.source = "selfcal calibrate " + source_path;
    model.provenance = {{"software_version", SELFCAL_VERSION},
                        {"sha256", FileSha256(source_path)},
                        {"method", method == Method::kBundle ? "kinematic bundle adjustment" : "paper pipeline"}};
    if (Status s = io::SaveCalibratedModel(model, model_path); !s.ok()) return Fail(s);
    std::cout << "calibrated model (" << json["method"].get<std::string>() << "): " << model_path << "\n";
  } else {
    std::cerr << "selfcal: " << ExitCodeName(code) << ": " << message << " (no calibrated model written)\n";
  }
  if (result_out != nullptr) *result_out = std::move(result);
  return static_cast<int>(code);
}

Command AddCalibrateCommand(CLI::App& app) {
  auto args = std::make_shared<CalibrateArgs>();
  CLI::App* cmd = app.add_subcommand(
      "calibrate",
      "Calibrate from an observations file or a recorded session directory (offline: never touches a robot): the "
      "paper's pipeline, then the kinematic bundle adjustment");
  cmd->add_option("observations", args->observations,
                  "Observations file (docs/observations-format.md) or session directory (docs/session-format.md)")
      ->required();
  cmd->add_option("--out", args->out, "Output directory (created if missing)");
  cmd->add_option("--seed", args->seed, "Seed of the RANSAC sampling (results are deterministic per seed)");
  AddMethodOption(cmd, &args->method);
  return [args]() {
    if (IsSessionDirectory(args->observations)) {
      return CalibrateSession(args->observations, args->out, args->seed, ParseMethod(args->method), nullptr, nullptr);
    }
    Result<ObservationSet> obs = io::LoadObservations(args->observations);
    if (!obs.ok()) return Fail(obs.status());
    if (Status s = EnsureDirectory(args->out); !s.ok()) return Fail(s);
    return CalibrateAndWrite(*obs, args->observations, args->out, args->seed, ParseMethod(args->method), nullptr);
  };
}

}  // namespace selfcal::app
