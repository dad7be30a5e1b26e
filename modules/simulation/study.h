// Monte Carlo study reproducing the paper's Table 2 (pose measurement errors) and Fig. 6 (3-D errors after
// calibration) over seeded simulated runs, beside OpenCV's essential-matrix pose (true f_x), the two-view
// Cramer-Rao bound of the same setup, and the nominal model (does calibration help?). Beyond the paper: the
// kinematic bundle adjustment (calibration/bundle_stage.h) on the same data, against the truth and its own
// Cramer-Rao bound (bundle::BundleCramerRao), with the coverage of its reported sigmas. With
// sim.flat_sheet the dots lie on one plane: the paper pipeline fails there (its rows count only the runs
// it completed) while the bundle adjustment starts from the nominal model.
//
// Eye-to-hand (the nominal model's mount, kinematics/robot_model.h): the simulated cell of sim/sim_world.h,
// a camera fixed in the base frame and a plate of dots on the flange, every truth and relative pose in the
// points' frame (PointsFromCam). The paper pipeline is not run there (it assumes the camera on the flange:
// calibration::kPaperNotEyeToHand, StudyReport::paper_pipeline_note); its rows stay empty and count no
// failure, and the bundle starts from the nominal arm with the fixed camera from the images.
#pragma once

#include <cmath>
#include <map>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "base/progress.h"
#include "calibration/bundle_stage.h"
#include "calibration/paper_pipeline.h"
#include "calibration/predicted_error.h"
#include "simulation/rendered_observations.h"
#include "sim/sim_world.h"

namespace selfcal::simulation {

struct TrajectorySpec {
  std::string name;
  std::vector<Eigen::VectorXd> joints;  // rad
};

// A row of observations measured on rendered images (simulation/rendered_observations.h) instead of
// projected points: grey-level noise and blur of the images; assumed_noise_px is the centroid noise the
// solvers are told (and the bound is computed with).
struct RenderedLevel {
  std::string name;          // e.g. "img-I"; cells are labelled "<trajectory>/<name>"
  double noise_std_grey = 0;
  double blur_sigma_px = 0;
  double assumed_noise_px = 0.05;
};

struct StudyOptions {
  int runs = 200;
  std::vector<double> noise_levels_px = {0.0, 0.2, 0.5};  // 0: the bias of eq. (21); I and II of Table 1
  uint64_t seed = 1;           // run r uses world seed seed + r and noise seed seed + 1000003 r
  sim::SimOptions sim;         // sim.flat_sheet: dots on one plane (`selfcal study --flat-sheet`)
  calibration::PaperPipelineOptions pipeline;
  bool with_opencv = true;
  bool with_bound = true;      // the two-view bound and, with the bundle, the bundle's bound
  bool with_bundle = true;     // the kinematic bundle adjustment rows
  calibration::BundleStageOptions bundle;
  // Rows on rendered images, after the point rows of each trajectory (same worlds). Rendering needs
  // dots that do not touch in any view: set sim.separation_dot_radius_m (the app does) for such rows.
  std::vector<RenderedLevel> rendered_levels;
  RenderedObservationOptions rendered;  // dot radius, detector, match radius (render noise/blur per level)
  ProgressSink* progress = nullptr;     // the runs (trajectories x runs), for a person watching; null: none
  // Runs computed at once on this many threads (0: std::thread::hardware_concurrency). The runs are
  // independent and seeded and are merged in run order: the report is the same for every value (apart
  // from the wall times it holds).
  int jobs = 0;
};

// Running sample statistics.
struct Stat {
  std::vector<double> values;
  void Add(double v) { values.push_back(v); }
  int count() const { return static_cast<int>(values.size()); }
  double Mean() const;
  double Sd() const;    // sample standard deviation
  double Rms() const;
  double Max() const;
  double Percentile(double p) const;  // p in [0, 100]
};

struct StudyCell {
  std::string trajectory;  // "<trajectory>/<rendered level>" for rendered rows
  double noise_px = 0;     // point rows: the pixel noise; rendered rows: the level's assumed_noise_px
  bool rendered = false;
  CentroidErrors centroids;  // rendered rows: the detector's centroids against the truth, pooled
  int runs = 0, runs_failed = 0;
  std::vector<std::string> failures;  // first few messages

  // Table 2, the paper's pipeline: per pose measurement (pair reference -> i), with the eq. (21) scale and
  // k_1 set from the true first motion (a perfect yardstick), as the paper's pose errors assume.
  Stat position_mm, orientation_1e4rad, fx_px;
  Stat position_true_scale_mm;  // direction error only: true ||t_i||
  Stat scale_ratio_error;       // |(||tbar_i||/||tbar_1||) / (||t_i||/||t_1||) - 1|: the eq. (21) bias
  // Same pairs, OpenCV findEssentialMat + recoverPose with the true f_x, same eq. (21) scaling.
  Stat opencv_position_mm, opencv_orientation_1e4rad, opencv_position_true_scale_mm;
  // Two-view Cramer-Rao bound, per pair: RMS values (sqrt of the trace of the covariance).
  Stat bound_position_mm_fx_unknown, bound_orientation_1e4rad_fx_unknown, bound_fx_px;
  Stat bound_position_mm_fx_known, bound_orientation_1e4rad_fx_known;
  // Fig. 6: 3-D error of every check distance on the verification poses (pooled over runs).
  Stat error3d_nominal_mm, error3d_calibrated_mm;
  // Predicted vs true relative poses reference -> verification pose.
  Stat pose_position_nominal_mm, pose_position_calibrated_mm;
  Stat pose_orientation_nominal_1e4rad, pose_orientation_calibrated_1e4rad;
  Stat fx_final_error_px;       // |f_x used by the calibrated model - true|
  Stat yardstick_scale_error;   // |s * (true scale of the measurements) - 1|
  Stat seconds_per_calibration;

  // Beyond the paper: the kinematic bundle adjustment on the same observations, started from the paper
  // pipeline's result (the nominal model when it failed). Runs that did not converge count as failed.
  int bundle_runs = 0, bundle_runs_failed = 0;
  std::vector<std::string> bundle_failures;  // first few messages
  // (a) Relative poses reference -> identification pose i predicted by the bundle's model vs the truth
  // (comparable to the Table 2 rows, which measure the same poses), and |f_x - true|.
  Stat bundle_position_mm, bundle_orientation_1e4rad, bundle_fx_px;
  // (b) The bundle's Cramer-Rao bound at the truth for the same quantities: per pose sqrt(trace cov).
  Stat bundle_bound_position_mm, bundle_bound_orientation_1e4rad, bundle_bound_fx_px;
  // (c) Fig. 6 with the bundle's model: 3-D error of every check distance on the verification poses, and
  // the verification relative poses (with their bound).
  Stat bundle_error3d_mm, bundle_pose_position_mm, bundle_pose_orientation_1e4rad;
  Stat bundle_bound_pose_position_mm, bundle_bound_pose_orientation_1e4rad;
  // (c') The predicted std of that 3-D error (calibration/predicted_error.h), per check distance pooled over
  // runs: from each run's own covariance and pixel noise (total, part (a) parameters, part (b) pixels), and
  // the bound: the same propagation of the bundle's Cramer-Rao covariance with the truth's model and f_x.
  // Compare bundle_error3d_mm.Rms() with their Rms() (the quadratic mean: E[error^2] = mean variance).
  Stat bundle_predicted3d_mm, bundle_predicted3d_parameters_mm, bundle_predicted3d_pixels_mm;
  Stat bundle_bound3d_mm, bundle_bound3d_parameters_mm;
  // (d) Coverage, pooled over runs: free parameters and f_x whose truth lies within +-2 reported sigma of
  // the estimate (runs with noise > 0 whose gauge is the truth's: (h)).
  int bundle_intervals = 0, bundle_covered = 0;
  double BundleCoverage() const { return bundle_intervals > 0 ? static_cast<double>(bundle_covered) / bundle_intervals : std::nan(""); }
  // (f) Per free parameter (by name, mm or deg): the bundle's error against the truth (same-gauge runs) and
  // the Cramer-Rao std at the truth; RMS error / RMS bound per parameter says whether it is efficient.
  std::map<std::string, Stat> bundle_parameter_error, bundle_parameter_bound;
  // (e) Wall time of one bundle solve (the screen's refits included).
  Stat bundle_seconds;
  // (g) |estimate - truth| of every free length (mm) and angle (deg) parameter, pooled over the runs whose
  // gauge is the truth's, at every noise level (0 included: the zero-noise row's exactness is their max).
  Stat bundle_length_error_mm, bundle_angle_error_deg;
  // (h) Weak parameters the bundle held at the robot description's value (BundleReport::weak), by name: in
  // how many runs, and the runs that held any. The truth moved them: such a run's gauge is not the truth's,
  // and (d), (f), (g) leave it out. bundle_runs_in_truths_gauge: the converged runs they score.
  std::map<std::string, int> bundle_weak_held;
  int bundle_runs_weak_held = 0, bundle_runs_in_truths_gauge = 0;

  // Adds the runs of `later` (the same trajectory and level) after this cell's: counts summed, samples
  // appended in order, failure messages kept up to the first few. Merging the cells of single runs in
  // run order gives the cell the runs would have filled one after the other.
  void Append(const StudyCell& later);
};

struct StudyReport {
  std::vector<StudyCell> cells;  // trajectory-major, noise-minor
  int identifiable_parameters = 0;
  std::vector<std::string> fixed_parameters;
  int bundle_free_parameters = 0;  // kinematic, f_x not counted
  std::vector<std::string> bundle_fixed_parameters;
  bool flat_sheet = false;
  CameraMount configuration = CameraMount::kEyeInHand;  // the nominal model's mount
  // Empty when the paper pipeline ran; otherwise why it was not run (eye-to-hand), and its rows are empty.
  std::string paper_pipeline_note;
  double seconds_total = 0;
};

// The threads RunStudy uses: options.jobs, or the hardware's concurrency when that is 0.
int StudyJobs(const StudyOptions& options);

StudyReport RunStudy(const RobotModel& nominal, const std::vector<TrajectorySpec>& trajectories,
                     const StudyOptions& options);

}  // namespace selfcal::simulation
