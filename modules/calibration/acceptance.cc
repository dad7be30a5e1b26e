#include "calibration/acceptance.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace selfcal::calibration {

const char* CheckStatusName(CheckStatus status) {
  switch (status) {
    case CheckStatus::kPassed: return "passed";
    case CheckStatus::kFailed: return "failed";
    case CheckStatus::kNotAvailable: return "not_available";
  }
  return "not_available";
}

bool Acceptance::Passed() const {
  for (const AcceptanceCheck& c : checks) {
    if (c.decisive && c.status == CheckStatus::kFailed) return false;
  }
  return true;
}

bool Acceptance::Verified() const {
  for (const AcceptanceCheck& c : checks) {
    if (c.status != CheckStatus::kNotAvailable) return true;
  }
  return false;
}

std::vector<std::string> Acceptance::Reasons() const {
  std::vector<std::string> reasons;
  for (const AcceptanceCheck& c : checks) {
    if (c.decisive && c.status == CheckStatus::kFailed) reasons.push_back(c.sentence);
  }
  return reasons;
}

namespace {

std::string Format(const char* format, double a, double b = 0, double c = 0, double d = 0, double e = 0) {
  char buffer[512];
  std::snprintf(buffer, sizeof buffer, format, a, b, c, d, e);
  return buffer;
}

AcceptanceCheck HeldOutTest(const AcceptanceInputs& in) {
  AcceptanceCheck check{"heldout_test", CheckStatus::kNotAvailable, ""};
  if (in.calibrated == nullptr || !in.calibrated->ok) {
    check.sentence = "no held-out reprojection test: no verification image has a dot that the identification images place";
    return check;
  }
  if (in.test_at_stated_noise == nullptr) {
    check.sentence = "no held-out reprojection test: " + in.no_test_reason;
    return check;
  }
  const HeldOutFigure& f = *in.test_at_stated_noise;
  const bool passed = f.test_passed;
  check.status = passed ? CheckStatus::kPassed : CheckStatus::kFailed;
  check.sentence =
      Format("the calibrated model predicts the dots of the verification images at %.3g px RMS; with the stated pixel "
             "noise of %.3g px that is a chi-square of %.6g over %.0f degrees of freedom, ",
             f.rms_px, in.stated_noise_px, f.chi_square, f.dof) +
      Format(passed ? "within its 95 %% limit of %.6g (p = %.2g)"
                    : "above its 95 %% limit of %.6g (p = %.2g): the model does not explain images it was not fitted "
                      "to (a parameter held at a wrong value, a wrong f_x or lens, a wrong joint sign, or a pixel noise "
                      "stated too small)",
             f.chi_square_limit, f.p_value);
  return check;
}

AcceptanceCheck BeatsNominalHeldOut(const AcceptanceInputs& in) {
  AcceptanceCheck check{"beats_nominal_heldout", CheckStatus::kNotAvailable, ""};
  if (!in.no_nominal_reason.empty()) {
    check.sentence = "no held-out comparison with a nominal model: " + in.no_nominal_reason;
    return check;
  }
  if (in.calibrated == nullptr || in.nominal == nullptr || !in.calibrated->ok || !in.nominal->ok) {
    check.sentence = "no held-out comparison with the nominal model: the verification images have no predicted dot";
    return check;
  }
  const double cal = in.calibrated->overall.rms_px, nom = in.nominal->overall.rms_px;
  const bool passed = cal < nom;
  check.status = passed ? CheckStatus::kPassed : CheckStatus::kFailed;
  check.sentence = Format(passed ? "on the verification images the calibrated model's reprojection RMS is %.3g px, the "
                                   "nominal model's %.3g px"
                                 : "on the verification images the calibrated model's reprojection RMS is %.3g px, not "
                                   "below the nominal model's %.3g px: the calibration made the robot's predictions worse",
                          cal, nom);
  return check;
}

AcceptanceCheck BeatsNominalDistances(const AcceptanceInputs& in) {
  AcceptanceCheck check{"beats_nominal_distances", CheckStatus::kNotAvailable, "no check distances in the set",
                        in.distances_decisive};
  if (in.distances_calibrated == nullptr || in.distances_nominal == nullptr ||
      in.distances_calibrated->checks.empty() || in.distances_nominal->checks.empty()) {
    return check;
  }
  // A figure only from distances measured by both models: with none measured the RMS is a 0 that means
  // nothing (issue 36: "the 40 check distances are measured at 0 mm RMS error" when none was).
  const double total = static_cast<double>(in.distances_calibrated->checks.size());
  const int cal_ok = in.distances_calibrated->num_ok, nom_ok = in.distances_nominal->num_ok;
  if (cal_ok == 0 || nom_ok == 0) {
    check.sentence = Format(cal_ok == 0 ? "none of the %.0f check distances could be measured with the calibrated model "
                                          "(their dots are not triangulated from the verification images): no check-"
                                          "distance figure"
                                        : "none of the %.0f check distances could be measured with the nominal model "
                                          "(their dots are not triangulated from the verification images): no "
                                          "comparison of check distances",
                            total);
    return check;
  }
  const std::string partial = cal_ok < total || nom_ok < total
                                  ? Format("%.0f of the %.0f check distances could be measured with the calibrated "
                                           "model, %.0f with the nominal model: ",
                                           cal_ok, total, nom_ok)
                                  : "";
  const double cal = in.distances_calibrated->rms_error_m * 1e3, nom = in.distances_nominal->rms_error_m * 1e3;
  const bool passed = cal < nom;
  check.status = passed ? CheckStatus::kPassed : CheckStatus::kFailed;
  check.sentence = partial + Format(passed ? "the %.0f check distances are measured at %.3g mm RMS error, %.3g mm with the nominal "
                                   "model"
                                 : in.distances_decisive
                                       ? "the %.0f check distances are measured at %.3g mm RMS error, not below the "
                                         "nominal model's %.3g mm: the calibrated model measures worse than the robot it "
                                         "started from"
                                       : "the %.0f check distances are measured at %.3g mm RMS error, not below the "
                                         "nominal model's %.3g mm (a figure: the held-out test above decides)",
                          static_cast<double>(cal_ok), cal, nom);
  return check;
}

AcceptanceCheck PlausibleCorrections(const AcceptanceInputs& in) {
  AcceptanceCheck check{"plausible_corrections", CheckStatus::kNotAvailable,
                        "no kinematic corrections to check (the paper's method re-identifies the model)"};
  if (in.robot == nullptr || in.corrections.size() != in.robot->num_parameters()) return check;
  const KinematicParameters params(in.robot->num_joints());
  // The largest correction relative to its bound, and the largest of each kind.
  int worst = -1;
  double worst_ratio = 0, largest_deg = 0, largest_mm = 0;
  for (int i = 0; i < params.size(); ++i) {
    const bool length = params.kind(i) == ParameterKind::kLength;
    const double size = std::abs(in.corrections[i]);
    if (!std::isfinite(size)) {
      worst = i;
      worst_ratio = INFINITY;
      break;
    }
    (length ? largest_mm : largest_deg) = std::max(length ? largest_mm : largest_deg, size * (length ? 1e3 : 180.0 / M_PI));
    const double ratio = size / (length ? kMaxLengthCorrectionM : kMaxAngularCorrectionRad);
    if (ratio > worst_ratio) {
      worst_ratio = ratio;
      worst = i;
    }
  }
  if (worst_ratio <= 1) {
    check.status = CheckStatus::kPassed;
    check.sentence = Format("every correction is within 45 deg and 100 mm of the robot description (largest %.3g deg, "
                            "%.3g mm)",
                            largest_deg, largest_mm);
    return check;
  }
  const bool length = params.kind(worst) == ParameterKind::kLength;
  check.status = CheckStatus::kFailed;
  check.sentence =
      params.name(worst) +
      Format(length ? " is corrected by %.4g mm: a calibration does not move a link by more than 100 mm"
                    : " is corrected by %.1f deg: a calibration does not turn a joint by more than 45 deg",
             std::abs(in.corrections[worst]) * (length ? 1e3 : 180.0 / M_PI)) +
      "; the robot description is wrong there (a joint's sign, zero, axis or length, or a parameter held at a wrong "
      "value), and the solve found an equivalent or compensating parameterisation instead. Fix the robot description";
  return check;
}

AcceptanceCheck HeldValues(const AcceptanceInputs& in) {
  AcceptanceCheck check{"held_values", CheckStatus::kNotAvailable, "no parameter held by request that the images can see"};
  if (in.held_values == nullptr || !in.held_values->tested) return check;
  const bundle::HeldValueTest& t = *in.held_values;
  const double limit = ChiSquareQuantile(kHeldOutTestLevel, t.dof);
  std::string names;
  for (const std::string& n : t.names) names += (names.empty() ? "" : ", ") + n;
  check.status = t.chi_square <= limit ? CheckStatus::kPassed : CheckStatus::kFailed;
  check.decisive = t.decisive;
  check.sentence = "the values held by request (" + names + ") against the images: score " +
                   Format("chi-square %.4g over %.0f degrees of freedom, ", t.chi_square, t.dof) +
                   Format(t.chi_square <= limit ? "within its 95 %% limit of %.4g" : "above its 95 %% limit of %.4g", limit) +
                   (t.chi_square <= limit ? "" : ": the images disagree with a held value, most with " + t.largest +
                                                     "; free it or correct it in the robot description or camera file");
  return check;
}

}  // namespace

Acceptance AcceptanceOf(const AcceptanceInputs& inputs) {
  Acceptance a;
  a.checks = {HeldOutTest(inputs), BeatsNominalHeldOut(inputs), BeatsNominalDistances(inputs),
              PlausibleCorrections(inputs), HeldValues(inputs)};
  return a;
}

PaperHeldOut PaperHeldOutOf(const ObservationSet& obs, const PaperPipelineReport& paper) {
  PaperHeldOut out;
  PredictionModel calibrated;
  calibrated.robot = paper.calibrated_robot;
  calibrated.rho = paper.calibrated_rho;
  calibrated.camera = obs.camera;
  calibrated.camera.fx_px = paper.fx_px;
  out.calibrated = HeldOutReprojectionOf(obs, calibrated, TriangulateIdentificationDots(obs, calibrated), {},
                                         obs.pixel_noise_px, 0);
  out.calibrated.noise_source = "the stated pixel noise";
  out.nominal = NominalHeldOutReprojection(obs, obs.pixel_noise_px, 0);
  out.nominal.noise_source = out.calibrated.noise_source;
  return out;
}

}  // namespace selfcal::calibration
