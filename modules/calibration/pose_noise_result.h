// A flange-pose set whose pose-noise solve (bundle/pose_noise_bundle.h) ran: that solve is the result, and
// everything the verdict and the report say comes from it (issue 35 item 7, "one solve behind every output").
//
//   PoseNoisePredictionModel  its model as heldout_reprojection.h predicts with: the hand-eye transform and
//                             intrinsics it solved, their covariance at the stated noises (the camera correction
//                             c and the estimated intrinsics), each predicted image's recorded flange pose
//                             carrying the modelled flange pose noise (PredictionModel::pose_error_at_flange)
//   PoseNoiseHeldOut          the verification poses predicted from their recorded flange poses with its dots
//   CrossValidatePoseNoise    without verification poses: each fold's pose-noise solve on the other poses
//                             (started from the whole solve, the same noise sizes: estimated once, from the
//                             whole set, when they were estimated) predicting the fold
//   PoseNoiseFitGeometry      the camera poses (recorded flange pose times its hand-eye transform) and the
//                             identification residuals of its fit (at the corrected flange poses), for the plots
//
// The held-out covariance of a detection: the pixel noise (stated), the flange pose noise through the projection
// (J_pose diag(s_t^2, s_r^2) J_pose^T, per image), the hand-eye transform's and intrinsics' covariance, and each
// dot's position error given those from its identification views at the pixel noise (the flange pose noise of
// the identification views is in the parameters' covariance, not in the dots': a dot seen in n views is taken as
// slightly more certain than it is, by roughly the pose noise's image size over sqrt(n)).
//
// `observations`: the set the pose-noise solve ran on (its camera the exact-pose bundle's, its yardsticks as
// CalibrateOptions::flange_scale says).
#pragma once

#include <cstdint>

#include "bundle/pose_noise_bundle.h"
#include "calibration/cross_validation.h"
#include "calibration/fit_geometry.h"
#include "calibration/heldout_reprojection.h"
#include "observations/observation_set.h"

namespace selfcal::calibration {

PredictionModel PoseNoisePredictionModel(const ObservationSet& observations, const bundle::PoseNoiseReport& solve,
                                         const bundle::PoseNoiseOptions& noise);

// Normalised with the stated pixel noise (taken as known).
HeldOutReprojection PoseNoiseHeldOut(const ObservationSet& observations, const bundle::PoseNoiseReport& solve,
                                     const bundle::PoseNoiseOptions& noise);

CrossValidationReport CrossValidatePoseNoise(const ObservationSet& observations, const bundle::PoseNoiseReport& full,
                                             const bundle::PoseNoiseOptions& noise, int folds, std::uint64_t seed);

FitGeometry PoseNoiseFitGeometry(const ObservationSet& observations, const bundle::PoseNoiseReport& solve);

}  // namespace selfcal::calibration
