#include "calibration/model_choice.h"

#include <cmath>
#include <string>

#include "calibration/pose_noise_result.h"

namespace selfcal::calibration {

namespace {

// A cross-validation's pooled held-out RMS when every fold gave one, else NaN and *why says what it lacked.
double CompleteFigure(const CrossValidationReport& cv, std::string* why) {
  if (!cv.ran) {
    *why = cv.message;
  } else if (cv.folds_tested < cv.folds || cv.pooled.num_residuals == 0) {
    *why = std::to_string(cv.folds_tested) + " of " + std::to_string(cv.folds) + " folds gave a figure";
  } else {
    return cv.pooled.rms_px;
  }
  return NAN;
}

}  // namespace

ObservationSet IdentificationPosesOnly(const ObservationSet& obs) {
  ObservationSet out = obs;
  out.poses.clear();
  for (const PoseObservation& pose : obs.poses) {
    if (pose.role == PoseRole::kIdentification) out.poses.push_back(pose);
  }
  out.check_distances.clear();
  return out;
}

ModelChoice ChooseFlangeModel(const ObservationSet& exact_set, const BundleStageReport& stage,
                              const BundleStageOptions& stage_options, const ObservationSet& noise_set,
                              const bundle::PoseNoiseReport& solve, const bundle::PoseNoiseOptions& noise, int folds,
                              std::uint64_t seed, CrossValidationReport* exact_cv, CrossValidationReport* noise_cv) {
  ModelChoice choice;
  choice.folds = folds;
  choice.seed = seed;
  *exact_cv = CrossValidate(IdentificationPosesOnly(exact_set), stage, stage_options, folds, seed);
  *noise_cv = CrossValidatePoseNoise(IdentificationPosesOnly(noise_set), solve, noise, folds, seed);
  std::string exact_why, noise_why;
  choice.exact_pose_rms_px = CompleteFigure(*exact_cv, &exact_why);
  choice.pose_noise_rms_px = CompleteFigure(*noise_cv, &noise_why);
  if (!exact_why.empty() || !noise_why.empty()) {
    choice.message = !exact_why.empty() ? "the exact-pose solve's cross-validation: " + exact_why
                                        : "the pose-noise solve's cross-validation: " + noise_why;
    return choice;
  }
  choice.made = true;
  choice.pose_noise_chosen = choice.pose_noise_rms_px <= choice.exact_pose_rms_px;
  return choice;
}

}  // namespace selfcal::calibration
