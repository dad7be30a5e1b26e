// Monte Carlo study reproducing the paper's Table 2 (pose measurement errors) and Fig. 6 (3-D errors after
// calibration) over seeded simulated runs, beside OpenCV's essential-matrix pose (true f_x), the two-view
// Cramer-Rao bound of the same setup, and the nominal model (does calibration help?).
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "pipeline/paper_pipeline.h"
#include "sim/sim_world.h"

namespace selfcal::pipeline {

struct TrajectorySpec {
  std::string name;
  std::vector<Eigen::VectorXd> joints;  // rad
};

struct StudyOptions {
  int runs = 200;
  std::vector<double> noise_levels_px = {0.0, 0.2, 0.5};  // 0: the bias of eq. (21); I and II of Table 1
  uint64_t seed = 1;           // run r uses world seed seed + r and noise seed seed + 1000003 r
  sim::SimOptions sim;
  PaperPipelineOptions pipeline;
  bool with_opencv = true;
  bool with_bound = true;
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
  std::string trajectory;
  double noise_px = 0;
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
};

struct StudyReport {
  std::vector<StudyCell> cells;  // trajectory-major, noise-minor
  int identifiable_parameters = 0;
  std::vector<std::string> fixed_parameters;
  double seconds_total = 0;
};

StudyReport RunStudy(const RobotModel& nominal, const std::vector<TrajectorySpec>& trajectories,
                     const StudyOptions& options);

}  // namespace selfcal::pipeline
