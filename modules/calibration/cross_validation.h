// A held-out figure for every calibration: when the observations name no verification pose, the
// identification poses are split into k folds (a seeded shuffle), the kinematic bundle adjustment is run
// again without each fold (started from the whole solve), and the fold's detections are predicted from its
// joint angles (or flange poses) alone (heldout_reprojection.h). The prediction error of poses the fit never
// saw, in px per coordinate and in mm at the scene (px times the median camera-to-dot distance over f_x).
//
// The held-out test at the stated pixel noise (with each fold's estimated pose error, bundle/error_model.h)
// per fold, and pooled over the folds: the sum of the folds' chi-squares against the sum of their degrees of
// freedom, the verdict's test when the set names no verification pose (acceptance.h).
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "calibration/bundle_stage.h"
#include "calibration/heldout_reprojection.h"
#include "observations/observation_set.h"

namespace selfcal::calibration {

struct CrossValidationFold {
  std::vector<std::string> held_out;  // pose ids
  bundle::Outcome outcome = bundle::Outcome::kNotRun;
  std::string message;                // the fold's bundle message when it did not converge
  HeldOutFigure figure;               // at the stated pixel noise
};

struct CrossValidationReport {
  bool ran = false;
  std::string message;  // why not, or a summary
  int folds = 0;
  std::uint64_t seed = 0;
  std::vector<CrossValidationFold> per_fold;
  // The pose error the folds' prediction carries beside the pixel noise, in words (the acceptance sentence).
  std::string pose_error = "the estimated pose error";
  double mm_per_px = NAN;        // at the scene: median camera-to-dot distance / f_x
  double rms_mm = NAN;           // pooled.rms_px * mm_per_px
  int folds_passed = 0;          // folds whose held-out test passed at the stated noise
  int folds_tested = 0;          // folds with a figure (converged, and predicting at least one detection)
  // Every fold's figure summed: predicted detections, RMS per coordinate, chi-square, dof, its 95 % limit, p.
  HeldOutFigure pooled;
};

// One fold's fit on `train` (the set with the fold's poses made verification poses) and its prediction of them:
// the fit's outcome and message, and when it converged the held-out reprojection of the fold's poses.
struct FoldFit {
  bundle::Outcome outcome = bundle::Outcome::kNotRun;
  std::string message;
  HeldOutReprojection heldout;
};
using FoldRunner = std::function<FoldFit(const ObservationSet& train)>;

// The folds of a k-fold cross-validation, each run by `run`, pooled (mm_per_px and rms_mm left NaN: the caller
// knows the scene's depth). Not run, as below, with verification poses, folds < 2 or too few poses.
CrossValidationReport CrossValidateWith(const ObservationSet& observations, int folds, std::uint64_t seed,
                                        const FoldRunner& run);

// k-fold cross-validation of `full` (the bundle stage of the whole set, converged): fold f holds out every
// k-th pose of the seeded order from f on. Not run (ran false, with the reason) when the set has
// verification poses, folds < 2, or fewer than two identification poses a fold.
CrossValidationReport CrossValidate(const ObservationSet& observations, const BundleStageReport& full,
                                    const BundleStageOptions& options, int folds, std::uint64_t seed);

}  // namespace selfcal::calibration
