#include "simulation/study.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <exception>
#include <mutex>
#include <numeric>
#include <thread>

namespace selfcal::simulation {

double Stat::Mean() const {
  if (values.empty()) return std::nan("");
  return std::accumulate(values.begin(), values.end(), 0.0) / values.size();
}
double Stat::Sd() const {
  if (values.size() < 2) return std::nan("");
  const double m = Mean();
  double s = 0;
  for (double v : values) s += (v - m) * (v - m);
  return std::sqrt(s / (values.size() - 1));
}
double Stat::Rms() const {
  if (values.empty()) return std::nan("");
  double s = 0;
  for (double v : values) s += v * v;
  return std::sqrt(s / values.size());
}
double Stat::Max() const {
  if (values.empty()) return std::nan("");
  return *std::max_element(values.begin(), values.end());
}
double Stat::Percentile(double p) const {
  if (values.empty()) return std::nan("");
  std::vector<double> sorted = values;
  std::sort(sorted.begin(), sorted.end());
  const double pos = p / 100.0 * (sorted.size() - 1);
  const size_t lo = static_cast<size_t>(std::floor(pos));
  const size_t hi = std::min(lo + 1, sorted.size() - 1);
  return sorted[lo] + (pos - lo) * (sorted[hi] - sorted[lo]);
}

namespace {

constexpr size_t kFailuresKept = 5;

void AppendStat(Stat* into, const Stat& later) {
  into->values.insert(into->values.end(), later.values.begin(), later.values.end());
}

void AppendFailures(std::vector<std::string>* into, const std::vector<std::string>& later) {
  for (const std::string& f : later) {
    if (into->size() < kFailuresKept) into->push_back(f);
  }
}

}  // namespace

void StudyCell::Append(const StudyCell& later) {
  runs += later.runs;
  runs_failed += later.runs_failed;
  AppendFailures(&failures, later.failures);
  centroids.Append(later.centroids);
  Stat StudyCell::*const stats[] = {
      &StudyCell::position_mm, &StudyCell::orientation_1e4rad, &StudyCell::fx_px, &StudyCell::position_true_scale_mm,
      &StudyCell::scale_ratio_error, &StudyCell::opencv_position_mm, &StudyCell::opencv_orientation_1e4rad,
      &StudyCell::opencv_position_true_scale_mm, &StudyCell::bound_position_mm_fx_unknown,
      &StudyCell::bound_orientation_1e4rad_fx_unknown, &StudyCell::bound_fx_px, &StudyCell::bound_position_mm_fx_known,
      &StudyCell::bound_orientation_1e4rad_fx_known, &StudyCell::error3d_nominal_mm, &StudyCell::error3d_calibrated_mm,
      &StudyCell::pose_position_nominal_mm, &StudyCell::pose_position_calibrated_mm,
      &StudyCell::pose_orientation_nominal_1e4rad, &StudyCell::pose_orientation_calibrated_1e4rad,
      &StudyCell::fx_final_error_px, &StudyCell::yardstick_scale_error, &StudyCell::seconds_per_calibration,
      &StudyCell::bundle_position_mm, &StudyCell::bundle_orientation_1e4rad, &StudyCell::bundle_fx_px,
      &StudyCell::bundle_bound_position_mm, &StudyCell::bundle_bound_orientation_1e4rad, &StudyCell::bundle_bound_fx_px,
      &StudyCell::bundle_error3d_mm, &StudyCell::bundle_pose_position_mm, &StudyCell::bundle_pose_orientation_1e4rad,
      &StudyCell::bundle_bound_pose_position_mm, &StudyCell::bundle_bound_pose_orientation_1e4rad,
      &StudyCell::bundle_predicted3d_mm, &StudyCell::bundle_predicted3d_parameters_mm,
      &StudyCell::bundle_predicted3d_pixels_mm, &StudyCell::bundle_bound3d_mm, &StudyCell::bundle_bound3d_parameters_mm,
      &StudyCell::bundle_seconds, &StudyCell::bundle_length_error_mm, &StudyCell::bundle_angle_error_deg};
  for (Stat StudyCell::*stat : stats) AppendStat(&(this->*stat), later.*stat);
  bundle_runs += later.bundle_runs;
  bundle_runs_failed += later.bundle_runs_failed;
  AppendFailures(&bundle_failures, later.bundle_failures);
  bundle_intervals += later.bundle_intervals;
  bundle_covered += later.bundle_covered;
  for (const auto& [name, stat] : later.bundle_parameter_error) AppendStat(&bundle_parameter_error[name], stat);
  for (const auto& [name, stat] : later.bundle_parameter_bound) AppendStat(&bundle_parameter_bound[name], stat);
  for (const auto& [name, count] : later.bundle_weak_held) bundle_weak_held[name] += count;
  bundle_runs_weak_held += later.bundle_runs_weak_held;
  bundle_runs_in_truths_gauge += later.bundle_runs_in_truths_gauge;
}

namespace {

// The report's fields the runs set (the first run's that set them), with whether this run set them.
struct RunHeader {
  bool paper_set = false, bundle_set = false;
  int identifiable_parameters = 0;
  std::vector<std::string> fixed_parameters;
  int bundle_free_parameters = 0;
  std::vector<std::string> bundle_fixed_parameters;
};
constexpr double k1e4 = 1e4;

// Scores one pipeline run against the simulator's truth and adds to the cell.
void ScoreRun(const sim::SimResult& world, const ObservationSet& obs, const calibration::PaperPipelineReport& report,
              const StudyOptions& options, StudyCell* cell) {
  const sim::SimTruth& truth = world.truth;
  const int ref = report.reference_pose;
  const Rigid3 true_ref_from_base = truth.base_from_cam[ref].Inverse();
  // k_1 from the true first motion: the pipeline used ||tbar_1||, rescale by ||t_1|| / ||tbar_1||.
  double k_correction = 1.0;
  for (const calibration::PoseMeasurement& m : report.measurements) {
    if (!m.used) continue;
    const Rigid3 true_rel = true_ref_from_base * truth.base_from_cam[m.pose_index];
    k_correction = true_rel.translation.norm() / m.nominal_translation.norm();
    break;
  }
  double ratio_first_true = 0, ratio_first_nominal = 0;
  bool first = true;
  std::vector<Eigen::Vector3d> dots_in_ref;
  for (const Eigen::Vector3d& p : truth.dots_in_base) dots_in_ref.push_back(true_ref_from_base * p);
  for (const calibration::PoseMeasurement& m : report.measurements) {
    const Rigid3 true_rel = true_ref_from_base * truth.base_from_cam[m.pose_index];  // cam_ref_from_cam_i
    if (m.used) {
      const Eigen::Vector3d t_meas = k_correction * m.measured_cam_ref_from_cam.translation;
      cell->position_mm.Add(kMmPerM * (t_meas - true_rel.translation).norm());
      const Eigen::Vector3d t_true_scale = true_rel.translation.norm() * m.measured_cam_ref_from_cam.translation.normalized();
      cell->position_true_scale_mm.Add(kMmPerM * (t_true_scale - true_rel.translation).norm());
      cell->orientation_1e4rad.Add(k1e4 * RotationAngle(m.measured_cam_ref_from_cam.rotation.transpose() * true_rel.rotation));
      if (m.two_view.fx_observable) cell->fx_px.Add(std::abs(m.two_view.fx_px - truth.camera_true.fx_px));
      if (first) {
        ratio_first_true = true_rel.translation.norm();
        ratio_first_nominal = m.nominal_translation.norm();
        first = false;
      } else {
        const double nominal_ratio = m.nominal_translation.norm() / ratio_first_nominal;
        const double true_ratio = true_rel.translation.norm() / ratio_first_true;
        cell->scale_ratio_error.Add(std::abs(nominal_ratio / true_ratio - 1.0));
      }
    }
    if (options.with_opencv && obs.poses.size() > 0) {
      CameraIntrinsics camera = obs.camera;
      camera.fx_px = truth.camera_true.fx_px;
      const Matches matches = MatchById(obs.poses[ref], obs.poses[m.pose_index]);
      twoview::TwoViewOptions cv_options = options.pipeline.two_view;
      const twoview::TwoViewReport cv = twoview::EstimateTwoViewOpenCv(cv_options, camera, matches.pixels_a, matches.pixels_b);
      if (cv.outcome == twoview::Outcome::kSuccess) {
        const Eigen::Matrix3d r = cv.rotation.transpose();
        const Eigen::Vector3d dir = -(r * cv.translation_direction).normalized();
        const Eigen::Vector3d t_meas = k_correction * m.nominal_translation.norm() * dir;
        cell->opencv_position_mm.Add(kMmPerM * (t_meas - true_rel.translation).norm());
        cell->opencv_position_true_scale_mm.Add(kMmPerM * (true_rel.translation.norm() * dir - true_rel.translation).norm());
        cell->opencv_orientation_1e4rad.Add(k1e4 * RotationAngle(r.transpose() * true_rel.rotation));
      }
    }
    if (options.with_bound && obs.pixel_noise_px > 0 && cell->noise_px > 0) {
      const Rigid3 cam_i_from_ref = true_rel.Inverse();
      for (bool fx_unknown : {true, false}) {
        const twoview::TwoViewBound bound =
            twoview::TwoViewCramerRao(truth.camera_true, cam_i_from_ref, dots_in_ref, cell->noise_px, fx_unknown);
        if (!bound.ok) continue;
        // Position error of the measurement cam_ref_from_cam_i = -R^T t: with ||t|| exact, its direction
        // error has the same angle as t's (rotation error enters too; the t term dominates).
        const double position = kMmPerM * true_rel.translation.norm() * bound.translation_dir_rms_rad();
        const double orientation = k1e4 * bound.rotation_rms_rad();
        if (fx_unknown) {
          cell->bound_position_mm_fx_unknown.Add(position);
          cell->bound_orientation_1e4rad_fx_unknown.Add(orientation);
          cell->bound_fx_px.Add(std::sqrt(bound.fx_variance));
        } else {
          cell->bound_position_mm_fx_known.Add(position);
          cell->bound_orientation_1e4rad_fx_known.Add(orientation);
        }
      }
    }
  }
  for (const calibration::DistanceCheck& c : report.verification_nominal.checks) {
    if (c.ok) cell->error3d_nominal_mm.Add(kMmPerM * c.error_m);
  }
  for (const calibration::DistanceCheck& c : report.verification_calibrated.checks) {
    if (c.ok) cell->error3d_calibrated_mm.Add(kMmPerM * c.error_m);
  }
  const Eigen::VectorXd rho_nominal = KinematicParameters::Nominal(obs.robot);
  const Rigid3 nominal_ref_from_base = PointsFromCam(obs.robot, rho_nominal, obs.poses[ref].joints_rad).Inverse();
  const Rigid3 calibrated_ref_from_base =
      PointsFromCam(report.calibrated_robot, report.calibrated_rho, obs.poses[ref].joints_rad).Inverse();
  for (int v : obs.PosesWithRole(PoseRole::kVerification)) {
    const Rigid3 true_rel = true_ref_from_base * truth.base_from_cam[v];
    const Rigid3 nominal_rel = nominal_ref_from_base * PointsFromCam(obs.robot, rho_nominal, obs.poses[v].joints_rad);
    const Rigid3 calibrated_rel = calibrated_ref_from_base *
                                  PointsFromCam(report.calibrated_robot, report.calibrated_rho, obs.poses[v].joints_rad);
    const PoseDifference before = ComparePoses(true_rel, nominal_rel);
    const PoseDifference after = ComparePoses(true_rel, calibrated_rel);
    cell->pose_position_nominal_mm.Add(kMmPerM * before.position_m);
    cell->pose_position_calibrated_mm.Add(kMmPerM * after.position_m);
    cell->pose_orientation_nominal_1e4rad.Add(k1e4 * before.rotation_rad);
    cell->pose_orientation_calibrated_1e4rad.Add(k1e4 * after.rotation_rad);
  }
  cell->fx_final_error_px.Add(std::abs(report.fx_px - truth.camera_true.fx_px));
  // The measurements carried lengths 1/k_correction times the truth; a right yardstick scale undoes that.
  if (report.yardstick.ok) cell->yardstick_scale_error.Add(std::abs(report.yardstick.scale / k_correction - 1.0));
  cell->seconds_per_calibration.Add(report.seconds_total);
}

// The bundle's Cramer-Rao bound at the truth. Its propagation covers the held-out poses of the geometry;
// copies of the identification poses (ref excluded) appended as held-out poses give the bound of the
// relative poses the Table 2 rows measure (the bound reads only their joint angles).
bundle::CramerRaoReport BundleBound(const sim::SimResult& world, const ObservationSet& obs, double sigma_px,
                                    const bundle::BundleOptions& options, int* num_identification_copies) {
  ObservationSet geometry = obs;
  const std::vector<int> id_poses = obs.PosesWithRole(PoseRole::kIdentification);
  *num_identification_copies = 0;
  for (size_t k = 1; k < id_poses.size(); ++k) {
    PoseObservation copy;
    copy.id = "identification:" + obs.poses[id_poses[k]].id;
    copy.role = PoseRole::kVerification;
    copy.joints_rad = obs.poses[id_poses[k]].joints_rad;
    geometry.poses.push_back(std::move(copy));
    ++*num_identification_copies;
  }
  bundle::BundleTruth truth;
  truth.rho = world.truth.rho_true;
  truth.camera = world.truth.camera_true;
  for (size_t d = 0; d < world.truth.dots_in_base.size(); ++d) {
    truth.dots_in_base[static_cast<int>(d)] = world.truth.dots_in_base[d];
  }
  return bundle::BundleCramerRao(geometry, truth, sigma_px, options);
}

// Whether the truth is in the bundle's gauge: every entry it held fixed equal to the truth's. A weak
// parameter held at the description (BundleReport::weak) is not: the truth moved it, and the bias of holding
// it goes into the free parameters, beyond their sigmas and bound (the run is counted in bundle_weak_held).
// If so, adds each free parameter's |error| to the cell.
bool ScoreAgainstTheTruth(const bundle::BundleReport& b, const sim::SimTruth& truth, const KinematicParameters& params,
                          StudyCell* cell) {
  bool gauge_is_truths = true;
  for (int i = 0; i < b.rho.size() && gauge_is_truths; ++i) {
    const bool free = std::find(b.free_indices.begin(), b.free_indices.end(), i) != b.free_indices.end();
    if (!free && b.rho[i] != truth.rho_true[i]) gauge_is_truths = false;
  }
  for (const bundle::WeakParameter& w : b.weak) ++cell->bundle_weak_held[w.name];
  if (!b.weak.empty()) ++cell->bundle_runs_weak_held;
  if (!gauge_is_truths) return false;
  ++cell->bundle_runs_in_truths_gauge;
  for (int i : b.free_indices) {
    const double error = std::abs(b.rho[i] - truth.rho_true[i]);
    if (params.kind(i) == ParameterKind::kLength) {
      cell->bundle_length_error_mm.Add(kMmPerM * error);
    } else {
      cell->bundle_angle_error_deg.Add(RadToDeg(error));
    }
  }
  return true;
}

// Runs the bundle stage on one observation set and scores it against the truth; adds to the cell.
void ScoreBundle(const sim::SimResult& world, const ObservationSet& obs, const calibration::PaperPipelineReport& paper,
                 const StudyOptions& options, StudyCell* cell, RunHeader* study) {
  const sim::SimTruth& truth = world.truth;
  ++cell->bundle_runs;
  const calibration::BundleStageReport stage = calibration::RunBundleStage(obs, paper, options.bundle);
  const bundle::BundleReport& b = stage.bundle;
  if (b.outcome != bundle::Outcome::kConverged) {
    ++cell->bundle_runs_failed;
    if (cell->bundle_failures.size() < kFailuresKept) {
      cell->bundle_failures.push_back(std::string(bundle::OutcomeName(b.outcome)) + ": " + b.message);
    }
    return;
  }
  if (study->bundle_free_parameters == 0) {
    study->bundle_set = true;
    study->bundle_free_parameters = static_cast<int>(b.free_indices.size());
    study->bundle_fixed_parameters = b.fixed_names;
  }
  cell->bundle_seconds.Add(b.seconds);
  const RobotModel& robot = obs.robot;
  const std::vector<int> id_poses = obs.PosesWithRole(PoseRole::kIdentification);
  const int ref = id_poses.front();
  const Rigid3 true_ref_from_base = truth.base_from_cam[ref].Inverse();
  const Rigid3 model_ref_from_base = PointsFromCam(robot, b.rho, obs.poses[ref].joints_rad).Inverse();
  auto relative_error = [&](int pose) {
    const Rigid3 model = model_ref_from_base * PointsFromCam(robot, b.rho, obs.poses[pose].joints_rad);
    return ComparePoses(true_ref_from_base * truth.base_from_cam[pose], model);
  };
  for (size_t k = 1; k < id_poses.size(); ++k) {
    const PoseDifference d = relative_error(id_poses[k]);
    cell->bundle_position_mm.Add(kMmPerM * d.position_m);
    cell->bundle_orientation_1e4rad.Add(k1e4 * d.rotation_rad);
  }
  cell->bundle_fx_px.Add(std::abs(b.fx_px - truth.camera_true.fx_px));
  for (int v : obs.PosesWithRole(PoseRole::kVerification)) {
    const PoseDifference d = relative_error(v);
    cell->bundle_pose_position_mm.Add(kMmPerM * d.position_m);
    cell->bundle_pose_orientation_1e4rad.Add(k1e4 * d.rotation_rad);
  }
  for (const calibration::DistanceCheck& c : stage.verification.checks) {
    if (c.ok) cell->bundle_error3d_mm.Add(kMmPerM * c.error_m);
  }
  const KinematicParameters params(obs.robot.num_joints());
  const bool gauge_is_truths = ScoreAgainstTheTruth(b, truth, params, cell);
  if (cell->noise_px <= 0) return;  // no noise: no sigma to cover with, no bound
  if (stage.predicted_error.ok) {
    for (const calibration::PredictedDistanceError& e : stage.predicted_error.distances) {
      if (!e.ok) continue;
      cell->bundle_predicted3d_mm.Add(kMmPerM * e.std_m);
      cell->bundle_predicted3d_parameters_mm.Add(kMmPerM * e.parameters_std_m);
      cell->bundle_predicted3d_pixels_mm.Add(kMmPerM * e.pixels_std_m);
    }
  }
  // Coverage needs the truth in the bundle's gauge, and the bundle's sigmas.
  const bool same_gauge = b.covariance_available && gauge_is_truths;
  auto in_report_units = [&](int i, double v) { return params.kind(i) == ParameterKind::kLength ? kMmPerM * v : RadToDeg(v); };
  if (same_gauge) {
    for (int i : b.free_indices) {
      cell->bundle_parameter_error[params.name(i)].Add(in_report_units(i, b.rho[i] - truth.rho_true[i]));
      ++cell->bundle_intervals;
      cell->bundle_covered += std::abs(b.rho[i] - truth.rho_true[i]) <= 2 * b.stddev[i] ? 1 : 0;
    }
    if (b.intrinsics_estimated[kFx]) {
      ++cell->bundle_intervals;
      cell->bundle_covered += std::abs(b.fx_px - truth.camera_true.fx_px) <= 2 * b.fx_stddev ? 1 : 0;
    }
  }
  if (!options.with_bound) return;
  int copies = 0;
  const bundle::CramerRaoReport bound = BundleBound(world, obs, cell->noise_px, options.bundle.bundle, &copies);
  if (!bound.ok) return;
  const size_t first_copy = bound.position_bound_m.size() - static_cast<size_t>(copies);
  for (size_t k = 0; k < bound.position_bound_m.size(); ++k) {
    if (k >= first_copy) {
      cell->bundle_bound_position_mm.Add(kMmPerM * bound.position_bound_m[k]);
      cell->bundle_bound_orientation_1e4rad.Add(k1e4 * bound.orientation_bound_rad[k]);
    } else {
      cell->bundle_bound_pose_position_mm.Add(kMmPerM * bound.position_bound_m[k]);
      cell->bundle_bound_pose_orientation_1e4rad.Add(k1e4 * bound.orientation_bound_rad[k]);
    }
  }
  if (std::isfinite(bound.fx_stddev)) cell->bundle_bound_fx_px.Add(bound.fx_stddev);
  for (int i : bound.free_indices) {
    if (std::isfinite(bound.stddev[i])) cell->bundle_parameter_bound[params.name(i)].Add(in_report_units(i, bound.stddev[i]));
  }
  // The 3-D error bound: the Cramer-Rao covariance propagated with the truth's model and f_x (the free
  // set is the solve's, chosen at the nominal model). A held f_x: zero variance.
  const int nf = static_cast<int>(bound.free_indices.size());
  if (bound.covariance_free.rows() >= nf) {
    Eigen::MatrixXd sigma = Eigen::MatrixXd::Zero(nf + 1, nf + 1);
    sigma.topLeftCorner(nf, nf) = bound.covariance_free.topLeftCorner(nf, nf);
    if (bundle::EstimatedIntrinsicsOf(options.bundle.bundle, robot.num_joints())[kFx]) {
      sigma = bound.covariance_free.topLeftCorner(nf + 1, nf + 1);
    }
    const calibration::PredictedDistanceErrors b3d =
        calibration::PredictDistanceErrors(obs, obs.PosesWithRole(PoseRole::kVerification), obs.robot, truth.rho_true,
                              truth.camera_true.fx_px, bound.free_indices, sigma, cell->noise_px, obs.check_distances);
    for (const calibration::PredictedDistanceError& e : b3d.distances) {
      if (!e.ok) continue;
      cell->bundle_bound3d_mm.Add(kMmPerM * e.std_m);
      cell->bundle_bound3d_parameters_mm.Add(kMmPerM * e.parameters_std_m);
    }
  }
}

// The study's cells of one trajectory, empty: the point rows, then the rendered rows.
std::vector<StudyCell> EmptyCells(const TrajectorySpec& trajectory, const StudyOptions& options) {
  const size_t num_point_cells = options.noise_levels_px.size();
  std::vector<StudyCell> cells(num_point_cells + options.rendered_levels.size());
  for (size_t l = 0; l < cells.size(); ++l) {
    if (l < num_point_cells) {
      cells[l].trajectory = trajectory.name;
      cells[l].noise_px = options.noise_levels_px[l];
    } else {
      const RenderedLevel& level = options.rendered_levels[l - num_point_cells];
      cells[l].trajectory = trajectory.name + "/" + level.name;
      cells[l].noise_px = level.assumed_noise_px;
      cells[l].rendered = true;
    }
  }
  return cells;
}

// What one run adds to the cells of its trajectory and to the report's header.
struct RunResult {
  std::vector<StudyCell> cells;
  RunHeader header;
};

// Run `run` of one trajectory: its world, then every cell's observations, pipeline and bundle. Depends
// only on its arguments (seeds from options.seed and run), so runs may go in any order on any thread.
RunResult RunOne(const RobotModel& nominal, const TrajectorySpec& trajectory, const StudyOptions& options, int run) {
  RunResult result;
  result.cells = EmptyCells(trajectory, options);
  std::vector<StudyCell>& cells = result.cells;
  const size_t num_point_cells = options.noise_levels_px.size();
  sim::SimOptions sim_options = options.sim;
  sim_options.world_seed = options.seed + static_cast<uint64_t>(run);
  const sim::SimResult world = sim::Simulate(nominal, trajectory.joints, sim_options);
  for (size_t l = 0; l < cells.size(); ++l) {
    StudyCell& cell = cells[l];
    ++cell.runs;
    if (!world.ok) {
      ++cell.runs_failed;
      cell.failures.push_back("simulation: " + world.message);
      if (options.with_bundle) {
        ++cell.bundle_runs;
        ++cell.bundle_runs_failed;
      }
      continue;
    }
    const uint64_t noise_seed = options.seed * 7919 + 1000003ULL * static_cast<uint64_t>(run) + l;
    ObservationSet obs;
    if (!cell.rendered) {
      obs = sim::Reobserve(world, cell.noise_px, noise_seed);
    } else {
      const RenderedLevel& level = options.rendered_levels[l - num_point_cells];
      RenderedObservationOptions rendered = options.rendered;
      rendered.render.noise_std_grey = level.noise_std_grey;
      rendered.render.blur_sigma_px = level.blur_sigma_px;
      rendered.assumed_noise_px = level.assumed_noise_px;
      obs = ObserveRendered(world, rendered, noise_seed, &cell.centroids);
    }
    calibration::PaperPipelineReport report = calibration::RunPaperPipeline(obs, options.pipeline);
    bool score_paper = true;
    if (nominal.mount == CameraMount::kEyeToHand && report.outcome == calibration::Outcome::kNotRun) {
      score_paper = false;  // not a failure: the paper's method does not apply (StudyReport::paper_pipeline_note)
    } else if (report.outcome != calibration::Outcome::kSuccess) {
      ++cell.runs_failed;
      cell.failures.push_back(std::string(calibration::OutcomeName(report.outcome)) + ": " + report.message);
      score_paper = !report.measurements.empty() && report.calibrated_rho.size() > 0;
    }
    if (score_paper) {
      if (result.header.identifiable_parameters == 0) {
        result.header.paper_set = true;
        result.header.identifiable_parameters = report.identifiability.rank;
        result.header.fixed_parameters = report.identifiability.fixed_names;
      }
      ScoreRun(world, obs, report, options, &cell);
    }
    if (options.with_bundle) ScoreBundle(world, obs, report, options, &cell, &result.header);
  }
  return result;
}

// Computes `count` results on `jobs` threads (the calling thread among them), each index once; the
// first exception thrown is rethrown here after every thread has ended.
template <typename Result, typename Compute>
std::vector<Result> ComputeInParallel(int count, int jobs, const Compute& compute) {
  std::vector<Result> results(static_cast<size_t>(count));
  std::mutex mutex;
  int next = 0;
  std::exception_ptr error;
  auto work = [&]() {
    for (;;) {
      int index = 0;
      {
        std::lock_guard<std::mutex> lock(mutex);
        if (next >= count || error) return;
        index = next++;
      }
      try {
        Result r = compute(index);
        std::lock_guard<std::mutex> lock(mutex);
        results[static_cast<size_t>(index)] = std::move(r);
      } catch (...) {
        std::lock_guard<std::mutex> lock(mutex);
        if (!error) error = std::current_exception();
      }
    }
  };
  std::vector<std::thread> threads;
  for (int t = 1; t < std::min(jobs, count); ++t) threads.emplace_back(work);
  work();
  for (std::thread& t : threads) t.join();
  if (error) std::rethrow_exception(error);
  return results;
}

}  // namespace

int StudyJobs(const StudyOptions& options) {
  if (options.jobs > 0) return options.jobs;
  return std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
}

StudyReport RunStudy(const RobotModel& nominal, const std::vector<TrajectorySpec>& trajectories,
                     const StudyOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  StudyReport study;
  study.flat_sheet = options.sim.flat_sheet;
  study.configuration = nominal.mount;
  if (nominal.mount == CameraMount::kEyeToHand) study.paper_pipeline_note = calibration::kPaperNotEyeToHand;
  ProgressScope progress(options.progress, static_cast<int64_t>(trajectories.size()) * options.runs, "study runs");
  std::mutex progress_mutex;
  RunHeader header;
  for (const TrajectorySpec& trajectory : trajectories) {
    std::vector<StudyCell> cells = EmptyCells(trajectory, options);
    const std::vector<RunResult> runs =
        ComputeInParallel<RunResult>(options.runs, StudyJobs(options), [&](int run) {
          RunResult result = RunOne(nominal, trajectory, options, run);
          std::lock_guard<std::mutex> lock(progress_mutex);
          progress.Advance();
          return result;
        });
    for (const RunResult& run : runs) {  // in run order: the report of runs made one after the other
      for (size_t l = 0; l < cells.size(); ++l) cells[l].Append(run.cells[l]);
      if (run.header.paper_set && header.identifiable_parameters == 0) {
        header.identifiable_parameters = run.header.identifiable_parameters;
        header.fixed_parameters = run.header.fixed_parameters;
      }
      if (run.header.bundle_set && header.bundle_free_parameters == 0) {
        header.bundle_free_parameters = run.header.bundle_free_parameters;
        header.bundle_fixed_parameters = run.header.bundle_fixed_parameters;
      }
    }
    study.cells.insert(study.cells.end(), cells.begin(), cells.end());
  }
  study.identifiable_parameters = header.identifiable_parameters;
  study.fixed_parameters = header.fixed_parameters;
  study.bundle_free_parameters = header.bundle_free_parameters;
  study.bundle_fixed_parameters = header.bundle_fixed_parameters;
  study.seconds_total = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return study;
}

}  // namespace selfcal::simulation
