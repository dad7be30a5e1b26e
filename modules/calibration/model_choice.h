// A flange-pose set whose flange pose noise was estimated, not stated, has two candidate results: the
// exact-pose bundle (the flange poses taken as recorded, their error part of each image's error model,
// bundle/error_model.h) and the pose-noise solve (each flange pose corrected under that noise,
// pose_noise_result.h). The independent per-image noise the second assumes is not what every cell has:
// a robot's pose error is mostly its kinematic model's, smooth over the workspace, and on real recordings
// the corrections it allows can trade with f_x (ROS-Industrial's dot grid: f_x 521 against 546 px, and the
// held-out poses predicted at 10.5 px where the exact-pose model gives about 1). Which solve predicts poses
// it never saw better is therefore measured: both are cross-validated on the identification poses with the
// same folds and seed, and the lower pooled held-out RMS is the result. A stated noise is the user's model
// and is not second-guessed, nor is a scale the yardsticks gave the pose-noise solve (the exact-pose solve
// scales by the flange translations alone; on ViSP's Franka set they disagree with the board by 1.13).
#pragma once

#include <cmath>
#include <cstdint>
#include <string>

#include "bundle/pose_noise_bundle.h"
#include "calibration/bundle_stage.h"
#include "calibration/cross_validation.h"
#include "observations/observation_set.h"

namespace selfcal::calibration {

struct ModelChoice {
  bool made = false;        // both cross-validations gave a figure; else the pose-noise solve stays the result
  std::string message;      // why not made: which cross-validation gave no figure, and why
  int folds = 0;
  std::uint64_t seed = 0;
  double exact_pose_rms_px = NAN, pose_noise_rms_px = NAN;  // pooled held-out RMS per coordinate
  bool pose_noise_chosen = true;
};

// The set's identification poses alone (verification poses and the check distances measured on them left
// out): what the choice cross-validates, so verification images stay a test the choice never saw.
ObservationSet IdentificationPosesOnly(const ObservationSet& obs);

// `exact_set` and `stage`: the exact-pose bundle's set and its converged stage; `noise_set`, `solve`, `noise`:
// the pose-noise solve's set, result and options (the noise it modelled). *exact_cv, *noise_cv: the two
// cross-validations (of the identification poses only).
ModelChoice ChooseFlangeModel(const ObservationSet& exact_set, const BundleStageReport& stage,
                              const BundleStageOptions& stage_options, const ObservationSet& noise_set,
                              const bundle::PoseNoiseReport& solve, const bundle::PoseNoiseOptions& noise, int folds,
                              std::uint64_t seed, CrossValidationReport* exact_cv, CrossValidationReport* noise_cv);

}  // namespace selfcal::calibration
