// The verdict's acceptance checks on a calibration that converged: a model is accepted only when it
// explains images it was not fitted to and predicts them better than the nominal model did.
//
//   heldout_test             the held-out reprojection test (heldout_reprojection.h) of the chosen model,
//                            normalised with the stated pixel noise and, when the bundle estimated one,
//                            each verification image's pose error (bundle/error_model.h), at kHeldOutTestLevel
//   cross_validation_test    without verification poses: the k-fold held-out test (cross_validation.h), every
//                            fold's chi-square at the stated noise and its estimated pose error summed, at
//                            kHeldOutTestLevel
//   beats_nominal_heldout    its held-out reprojection RMS below the nominal model's, or not significantly
//                            worse where the nominal model is already good: a one-sided paired t-test of the
//                            poses' mean square errors at 95 % (three verification poses at least)
//   beats_nominal_distances  the 3-D RMS error of the check distances below the nominal model's (only
//                            when the set has check distances). It decides only for a model without a
//                            covariance (the paper's method): for the bundle, whose held-out test carries
//                            the prediction's uncertainty, it is a figure, because a correct model at its
//                            own uncertainty measures worse than a lucky nominal model (measured: 4 of 50
//                            correct simulated calibrations, each within its predicted distance error).
//   held_values              the parameters held by request (--fix) agree with the images: the score test
//                            of bundle/error_model.h at kHeldOutTestLevel (a held value the data disagree
//                            with leaves a pose error behind that the held-out test would take as noise)
//   yardstick_scale          a joint-angle set's yardstick against the robot description's link lengths
//                            (yardstick_scale.h): the free lengths uniformly within kMaxScaleDeviation (1 %)
//                            of the description's, or within 3 sigma; refused beyond both (a wrong
//                            yardstick length or wrong ends scale the whole arm and change no image)
//   plausible_corrections    no angular correction of the kinematic model beyond kMaxAngularCorrectionRad
//                            (45 deg) and no length correction beyond kMaxLengthCorrectionM (100 mm): a
//                            calibration corrects a description by small amounts, and a model
//                            that needs a half-turn has absorbed a wrong joint sign, zero or axis into an
//                            equivalent parameterisation (measured: 2 of 50 simulated sets with joint 4's
//                            readings negated converged so, with j4.alpha and j5.theta corrected by
//                            multiples of 180 deg and the images fitted at their noise; on the UR5e, whose
//                            parallel axes let lengths trade against angles, a 0.5 deg error held fixed
//                            converged with link lengths of metres)
//
// A check that cannot be made (no verification pose, a model without a covariance, flange poses with a
// stated noise the test does not model) is kNotAvailable and says why; it refuses nothing. A model that
// passes and yet had no held-out test made (HeldOutTested false: neither held-out test nor the comparison
// with the nominal model on held-out images) is "untested" (calibrate.h), not accepted. The stated
// noise is the test's scale because a wrong model inflates the noise estimated from its own residuals
// (measured: a 1 mm link error held fixed raised the estimate from 0.20 to 0.28 px, which hid the error
// from a test normalised by it).
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "bundle/error_model.h"
#include "calibration/cross_validation.h"
#include "calibration/heldout_reprojection.h"
#include "calibration/paper_pipeline.h"
#include "calibration/yardstick_scale.h"

namespace selfcal::calibration {

enum class CheckStatus { kPassed, kFailed, kNotAvailable };
const char* CheckStatusName(CheckStatus status);  // "passed", "failed", "not_available"

struct AcceptanceCheck {
  std::string name;      // heldout_test, cross_validation_test, beats_nominal_heldout, ...
  CheckStatus status = CheckStatus::kNotAvailable;
  std::string sentence;  // the figures and what they mean, in words
  bool decisive = true;  // false: reported, refuses nothing
};

struct Acceptance {
  std::vector<AcceptanceCheck> checks;
  bool Passed() const;                   // no decisive check failed
  bool Verified() const;                 // at least one check was made
  // A decisive held-out check passed: the held-out test, the cross-validation test, or the comparison with
  // the nominal model on verification images.
  bool HeldOutTested() const;
  std::vector<std::string> Reasons() const;  // the sentences of the failed decisive checks
};

struct AcceptanceInputs {
  const HeldOutReprojection* calibrated = nullptr;  // the chosen model's held-out figures (null: none)
  const HeldOutReprojection* nominal = nullptr;     // the nominal model's
  // Why no nominal model is to be compared with (empty: there is one): a flange-pose set that names no
  // hand-eye transform has no nominal model, only the solver's own start, which is no one's model.
  std::string no_nominal_reason;
  // The chosen model's overall figure at the stated noise; null with a reason when the test does not apply.
  const HeldOutFigure* test_at_stated_noise = nullptr;
  std::string no_test_reason;
  double stated_noise_px = 0;
  const VerificationSummary* distances_calibrated = nullptr;  // null or empty: no check distances
  const VerificationSummary* distances_nominal = nullptr;
  bool distances_decisive = true;
  // Why the set's check distances were not measured (empty: none in the set, or measured): they are
  // triangulated from the verification poses, and a set may name none.
  std::string no_distances_reason;
  // The bundle's kinematic corrections: the parameters' names, kinds and corrections (estimate - nominal);
  // empty for the paper's method.
  const RobotModel* robot = nullptr;
  Eigen::VectorXd corrections;
  // The k-fold cross-validation (null or not run: none; it runs only without verification poses).
  const CrossValidationReport* cross_validation = nullptr;
  std::string no_cross_validation_reason = "not run";  // when cross_validation is null
  // The score test of the parameters held by request (bundle/error_model.h); null: none.
  const bundle::HeldValueTest* held_values = nullptr;
  // The yardstick against the description's lengths (a joint-angle set's bundle); null: not a joint set.
  const YardstickScale* yardstick_scale = nullptr;
};

inline constexpr double kMaxAngularCorrectionRad = 0.7853981633974483;  // 45 deg
inline constexpr double kMaxLengthCorrectionM = 0.1;

Acceptance AcceptanceOf(const AcceptanceInputs& inputs);

// The held-out figures of the paper pipeline's model and of the nominal model, both taken as exact (the
// paper's method gives no covariance) with their dots triangulated from the identification images,
// normalised with the stated pixel noise.
struct PaperHeldOut {
  HeldOutReprojection calibrated, nominal;
};
PaperHeldOut PaperHeldOutOf(const ObservationSet& observations, const PaperPipelineReport& paper);

}  // namespace selfcal::calibration
