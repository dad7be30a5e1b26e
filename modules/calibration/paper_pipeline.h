// The paper's pipeline end to end (section 4.1): for each identification pose i, the factor method on the
// pair (reference, i) gives R_i, the direction of t_i and f_x (step 2); eq. (21) gives each t_i one scale
// from the nominal position ratios; Levenberg-Marquardt identifies the kinematic parameters from those
// relative poses (step 3); the yardstick fixes the metric scale (step 4); held-out verification poses give
// the 3-D error of known distances (step 5).
//
// Works on an ObservationSet only: no files, no hardware, no truth.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "base/progress.h"
#include "identification/identifiability.h"
#include "identification/identification.h"
#include "identification/triangulation.h"
#include "observations/observation_set.h"
#include "twoview/two_view.h"

namespace selfcal::calibration {

enum class Outcome {
  kNotRun,
  kSuccess,
  kInvalidInput,      // the observation set fails validation
  kDegenerate,        // too few usable pose measurements, nothing identifiable
  kScaleUnresolved,   // S1/S3: no usable yardstick; the model is returned without metric scale
  kUnconverged,       // identification did not converge (K4): result not to be applied
  kSolverFailure,
};
const char* OutcomeName(Outcome outcome);

struct PaperPipelineOptions {
  twoview::TwoViewOptions two_view;
  identification::IdentificationOptions identification;
  identification::IdentifiabilityOptions identifiability;
  double yardstick_max_relative_sigma = 0.05;
  int min_pose_measurements = 6;
  // K3: refuse (kDegenerate, "insufficient excitation") when the column-normalised identification
  // Jacobian of the identification poses is worse conditioned than this, before any image is processed.
  double max_condition_number = 1e4;
  // Variance-component re-weighting: after a solve, the position and rotation weights are set to the
  // residual RMS of each kind and the solve repeated (0 = the fixed weights of `identification`). The
  // factor method's rotations and translations have very different accuracies from one setup to the next,
  // so fixed weights would let the worse kind dominate.
  int reweighting_rounds = 2;  // 6m > n: the paper's section 4.2 count, checked again by the rank
  ProgressSink* progress = nullptr;  // told each pair (reference, i) of step 2 done; null: nothing reported
};

// One measured relative pose (reference -> pose), the factor method's output and the eq. (21) scale.
struct PoseMeasurement {
  int pose_index = -1;
  std::string pose_id;
  twoview::TwoViewReport two_view;
  // f_x was unobservable from this pair (optical axes nearly intersecting): it was re-estimated with the
  // mean f_x of the observable pairs held fixed, f_x being one constant of the camera.
  bool fx_from_other_pairs = false;
  bool used = false;                 // entered the identification
  Rigid3 measured_cam_ref_from_cam;  // rotation and eq. (21)-scaled translation
  Eigen::Vector3d nominal_translation = Eigen::Vector3d::Zero();  // tbar_i of eq. (21)
  double scale = 0;                  // |k_i| = ||tbar_i|| (k_1 = ||tbar_1||: the nominal metric)
};

// 3-D error of one known distance (section 4.1 step 5).
struct DistanceCheck {
  KnownDistance known;
  bool ok = false;
  double measured_m = 0;
  double error_m = 0;  // |measured - known|
};

struct VerificationSummary {
  std::vector<DistanceCheck> checks;
  int num_ok = 0;
  double mean_error_m = 0, rms_error_m = 0, max_error_m = 0;
};

struct PaperPipelineReport {
  Outcome outcome = Outcome::kNotRun;
  std::string message;
  int reference_pose = -1;
  std::vector<PoseMeasurement> measurements;
  identification::IdentifiabilityReport identifiability;
  identification::IdentificationReport identification;
  identification::ScaleEstimate yardstick;
  double fx_px = 0;               // mean of the observable per-pair estimates (or the prior if none)
  int fx_pairs = 0;
  RobotModel calibrated_robot;    // nominal values replaced by the identified ones, metric
  Eigen::VectorXd calibrated_rho; // = Nominal(calibrated_robot) (zero corrections)
  VerificationSummary verification_nominal;     // before calibration: nominal model, prior f_x
  VerificationSummary verification_calibrated;  // after
  double seconds_two_view = 0, seconds_identification = 0, seconds_total = 0;
};

// An eye-to-hand set (observations.robot.mount) is not run (kNotRun, kPaperNotEyeToHand): the paper's steps
// 3-4 fit camera motions through the arm to a camera on the flange. Calibrate starts the bundle of such a
// set from the nominal model with the fixed camera from the images (bundle_stage.h).
inline constexpr const char* kPaperNotEyeToHand =
    "not run: the paper's method fits the camera's motions through the arm to a camera on the flange (eye-in-hand); "
    "eye-to-hand starts from the nominal model with the fixed camera from the images";
PaperPipelineReport RunPaperPipeline(const ObservationSet& observations, const PaperPipelineOptions& options);

// Triangulates the ends of each known distance from the given poses with a model and f_x.
VerificationSummary VerifyDistances(const ObservationSet& observations, const std::vector<int>& pose_indices,
                                    const RobotModel& robot, const Eigen::VectorXd& rho, double fx_px,
                                    const std::vector<KnownDistance>& distances);

}  // namespace selfcal::calibration
