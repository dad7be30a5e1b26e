#include "calibration/calibrate.h"

namespace selfcal::calibration {

const char* MethodName(Method method) { return method == Method::kPaper ? "paper" : "bundle"; }

std::optional<Method> ParseMethod(std::string_view name) {
  if (name == "bundle") return Method::kBundle;
  if (name == "paper") return Method::kPaper;
  return std::nullopt;
}

const char* VerdictName(Verdict verdict) {
  switch (verdict) {
    case Verdict::kAccepted: return "accepted";
    case Verdict::kInvalidInput: return "invalid_input";
    case Verdict::kDegenerate: return "degenerate";
    case Verdict::kScaleUnresolved: return "scale_unresolved";
    case Verdict::kUnconverged: return "unconverged";
    case Verdict::kSolverFailure: return "solver_failure";
  }
  return "solver_failure";
}

Verdict VerdictFor(Outcome outcome) {
  switch (outcome) {
    case Outcome::kSuccess: return Verdict::kAccepted;
    case Outcome::kInvalidInput: return Verdict::kInvalidInput;
    case Outcome::kDegenerate: return Verdict::kDegenerate;
    case Outcome::kScaleUnresolved: return Verdict::kScaleUnresolved;
    case Outcome::kUnconverged: return Verdict::kUnconverged;
    case Outcome::kSolverFailure:
    case Outcome::kNotRun: return Verdict::kSolverFailure;
  }
  return Verdict::kSolverFailure;
}

Verdict VerdictFor(bundle::Outcome outcome) {
  switch (outcome) {
    case bundle::Outcome::kConverged: return Verdict::kAccepted;
    case bundle::Outcome::kInvalidInput: return Verdict::kInvalidInput;
    case bundle::Outcome::kDegenerate: return Verdict::kDegenerate;
    case bundle::Outcome::kScaleUnresolved: return Verdict::kScaleUnresolved;
    case bundle::Outcome::kNoConvergence: return Verdict::kUnconverged;
    case bundle::Outcome::kFailure:
    case bundle::Outcome::kNotRun: return Verdict::kSolverFailure;
  }
  return Verdict::kSolverFailure;
}

const VerificationSummary& CalibrationReport::verification_calibrated() const {
  return bundle ? bundle->verification : paper.verification_calibrated;
}

const VerificationSummary& CalibrationReport::verification_nominal() const {
  return bundle ? bundle->verification_nominal : paper.verification_nominal;
}

CalibrationReport Calibrate(const ObservationSet& observations, const CalibrateOptions& options) {
  CalibrationReport report;
  report.method = options.method;
  report.paper = RunPaperPipeline(observations, options.paper);
  report.verdict = VerdictFor(report.paper.outcome);
  report.message = report.paper.message;
  if (options.method == Method::kBundle) {
    report.bundle = RunBundleStage(observations, report.paper, options.bundle);
    report.verdict = VerdictFor(report.bundle->bundle.outcome);
    report.message = report.bundle->bundle.message;
  }
  if (!report.accepted()) return report;  // K4: no model for a result that is not to be applied
  CalibratedModel model;
  if (report.bundle) {
    model.robot = report.bundle->calibrated_robot;
    model.fx_px = report.bundle->bundle.fx_px;
    model.parameters = report.bundle->bundle.rho;
    model.method_description = "kinematic bundle adjustment";
  } else {
    model.robot = report.paper.calibrated_robot;
    model.fx_px = report.paper.fx_px;
    model.method_description = "paper pipeline";
  }
  report.model = std::move(model);
  return report;
}

}  // namespace selfcal::calibration
