// selfcal calibrate INPUT --out DIR [--method bundle|paper]: parse, load, calibrate, write.
#include "app/calibrate_command.h"

#include <filesystem>
#include <iostream>

#include "app/cli_util.h"
#include "app/commands.h"
#include "app/session_command.h"
#include "io/observations_file.h"
#include "io/report_json.h"
#include "io/robot_config.h"
#include "report/calibration_report.h"

namespace selfcal::app {

namespace {

// The observations and what the report says of their origin.
struct LoadedInput {
  ObservationSet observations;
  report::ReportInput input;
  nlohmann::json session;  // the journal's counts, for a session
};

Result<LoadedInput> LoadInput(const CalibrateRequest& request) {
  LoadedInput loaded;
  if (IsSessionDirectory(request.input)) {
    nlohmann::json summary;
    Result<ObservationSet> obs = LoadSessionObservations(request.input, &summary);
    if (!obs.ok()) return obs.status();
    loaded.observations = std::move(obs).value();
    loaded.session = std::move(summary);
    const std::string manifest = (std::filesystem::path(request.input) / "session.json").string();
    loaded.input = {"session", request.input, FileHash(manifest)};
    return loaded;
  }
  Result<ObservationSet> obs = io::LoadObservations(request.input);
  if (!obs.ok()) return obs.status();
  loaded.observations = std::move(obs).value();
  loaded.input = {"observations", request.input, FileHash(request.input)};
  return loaded;
}

void PrintSessionCounts(const nlohmann::json& summary) {
  std::cout << "session: " << summary["samples_accepted"] << " of " << summary["poses_planned"] << " poses accepted, "
            << summary["resumes"] << " resumes";
  for (const char* key : {"skips_by_reason", "faults_by_kind", "halts_by_reason"}) {
    const char* word = key[0] == 's' ? "skipped" : key[0] == 'f' ? "fault" : "halted";
    for (const auto& [name, n] : summary[key].items()) std::cout << ", " << word << " " << name << " x" << n;
  }
  std::cout << "\n";
}

// Writes report.json, and calibrated_model.yaml when the verdict is "accepted" (K4).
Status WriteOutputs(const LoadedInput& loaded, const calibration::CalibrationReport& report, ExitCode code,
                    const std::string& out_dir) {
  const std::filesystem::path out(out_dir);
  const report::ReportContext context{loaded.input, static_cast<int>(code), loaded.session};
  const std::string report_path = (out / "report.json").string();
  if (Status s = io::WriteJsonFile(report::CalibrationReportJson(loaded.observations, report, context), report_path);
      !s.ok()) {
    return s;
  }
  std::cout << "report: " << report_path << "\n";
  if (!report.model) return Status::Ok();
  io::CalibratedModel model;
  model.model = report.model->robot;
  model.fx_px = report.model->fx_px;
  model.parameters = report.model->parameters;
  model.source = "selfcal calibrate " + loaded.input.path;
  model.provenance = {{"software_version", SELFCAL_VERSION},
                      {"input_sha256", loaded.input.sha256},
                      {"method", report.model->method_description}};
  const std::string model_path = (out / "calibrated_model.yaml").string();
  if (Status s = io::SaveCalibratedModel(model, model_path); !s.ok()) return s;
  std::cout << "calibrated model (" << calibration::MethodName(report.method) << "): " << model_path << "\n";
  return Status::Ok();
}

}  // namespace

void AddMethodOption(CLI::App* cmd, std::string* method) {
  cmd->add_option("--method", *method,
                  "bundle: the paper's pipeline, then the kinematic bundle adjustment started from it (the product); "
                  "paper: the paper's pipeline alone (the baseline)")
      ->check(CLI::IsMember({"bundle", "paper"}));
}

int CalibrateAndWrite(const CalibrateRequest& request, CalibrationRun* run) {
  Result<LoadedInput> loaded = LoadInput(request);
  if (!loaded.ok()) return Fail(loaded.status());
  if (Status s = EnsureDirectory(request.out_dir); !s.ok()) return Fail(s);
  const bool from_session = loaded->input.kind == "session";
  if (from_session) {
    // The session's observations as a file, for other tools and for re-solving without the images.
    const std::string derived = (std::filesystem::path(request.out_dir) / "observations.yaml").string();
    if (Status s = io::SaveObservations(loaded->observations, derived); !s.ok()) return Fail(s);
    std::cout << "session " << request.input << ": " << loaded->observations.poses.size() << " accepted samples\n";
  }
  calibration::CalibrateOptions options;
  options.method = request.method;
  options.paper.two_view.seed = request.seed;
  calibration::CalibrationReport report = calibration::Calibrate(loaded->observations, options);
  report::PrintCalibrationSummary(report, std::cout);
  const ExitCode code = ExitCodeFor(report.verdict);
  if (Status s = WriteOutputs(*loaded, report, code, request.out_dir); !s.ok()) return Fail(s);
  if (!report.accepted()) {
    std::cerr << "selfcal: " << ExitCodeName(code) << ": " << report.message << " (no calibrated model written)\n";
  }
  if (from_session) PrintSessionCounts(loaded->session);
  if (run != nullptr) *run = {std::move(loaded).value().observations, std::move(report)};
  return static_cast<int>(code);
}

Command AddCalibrateCommand(CLI::App& app) {
  auto request = std::make_shared<CalibrateRequest>();
  request->out_dir = "out/calibration";
  auto method = std::make_shared<std::string>("bundle");
  CLI::App* cmd = app.add_subcommand(
      "calibrate",
      "Calibrate from an observations file or a recorded session directory (offline: never touches a robot): the "
      "paper's pipeline, then the kinematic bundle adjustment");
  cmd->add_option("observations", request->input,
                  "Observations file (docs/observations-format.md) or session directory (docs/session-format.md)")
      ->required();
  cmd->add_option("--out", request->out_dir, "Output directory (created if missing)");
  cmd->add_option("--seed", request->seed, "Seed of the RANSAC sampling (results are deterministic per seed)");
  AddMethodOption(cmd, method.get());
  return [request, method]() {
    request->method = MethodFromName(*method);
    return CalibrateAndWrite(*request);
  };
}

}  // namespace selfcal::app
