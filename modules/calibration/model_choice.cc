#include "calibration/model_choice.h"

#include <algorithm>
#include <utility>

#include "calibration/pose_noise_result.h"

namespace selfcal::calibration {

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
  const auto figure = [](const CrossValidationReport& cv) {
    return cv.ran && cv.pooled.num_residuals > 0 && cv.folds_tested == cv.folds ? cv.pooled.rms_px : NAN;
  };
  choice.exact_pose_rms_px = figure(*exact_cv);
  choice.pose_noise_rms_px = figure(*noise_cv);
  if (!std::isfinite(choice.exact_pose_rms_px) || !std::isfinite(choice.pose_noise_rms_px)) {
    choice.message = "not made: " + std::string(!std::isfinite(choice.exact_pose_rms_px)
                                                    ? "the exact-pose solve's cross-validation: " + exact_cv->message
                                                    : "the pose-noise solve's cross-validation: " + noise_cv->message) +
                     " (the pose-noise solve is the result)";
    return choice;
  }
  choice.made = true;
  choice.pose_noise_chosen = choice.pose_noise_rms_px <= choice.exact_pose_rms_px;
  return choice;
}

}  // namespace selfcal::calibration
