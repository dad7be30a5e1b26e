#include "calibration/paper_pipeline.h"

#include <chrono>
#include <cmath>
#include <sstream>

namespace selfcal::calibration {

const char* OutcomeName(Outcome outcome) {
  switch (outcome) {
    case Outcome::kNotRun: return "not_run";
    case Outcome::kSuccess: return "success";
    case Outcome::kInvalidInput: return "invalid_input";
    case Outcome::kDegenerate: return "degenerate";
    case Outcome::kScaleUnresolved: return "scale_unresolved";
    case Outcome::kUnconverged: return "unconverged";
    case Outcome::kSolverFailure: return "solver_failure";
  }
  return "unknown";
}

namespace {

using Clock = std::chrono::steady_clock;
double SecondsSinceStart(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// The yardstick's ends as seen from the given poses, with camera poses from a model.
std::vector<identification::YardstickView> YardstickViews(const ObservationSet& obs, const std::vector<int>& poses,
                                                          const RobotModel& robot, const Eigen::VectorXd& rho) {
  std::vector<identification::YardstickView> views;
  for (const KnownDistance& y : obs.yardsticks) {
    identification::YardstickView v;
    v.length_m = y.length_m;
    for (int p : poses) {
      const PoseObservation& pose = obs.poses[p];
      const Rigid3 base_from_cam = PointsFromCamAt(robot, rho, pose);
      auto a = pose.dots_px.find(y.dot_a);
      auto b = pose.dots_px.find(y.dot_b);
      if (a != pose.dots_px.end()) {
        v.end_a.base_from_cam.push_back(base_from_cam);
        v.end_a.pixels.push_back(a->second);
      }
      if (b != pose.dots_px.end()) {
        v.end_b.base_from_cam.push_back(base_from_cam);
        v.end_b.pixels.push_back(b->second);
      }
    }
    views.push_back(std::move(v));
  }
  return views;
}

}  // namespace

VerificationSummary VerifyDistances(const ObservationSet& obs, const std::vector<int>& pose_indices,
                                    const RobotModel& robot, const Eigen::VectorXd& rho, double fx_px,
                                    const std::vector<KnownDistance>& distances) {
  VerificationSummary summary;
  std::vector<Rigid3> cams;
  for (int p : pose_indices) cams.push_back(PointsFromCamAt(robot, rho, obs.poses[p]));
  auto triangulate = [&](int dot) {
    identification::PointTrack track;
    for (size_t k = 0; k < pose_indices.size(); ++k) {
      const auto& dots = obs.poses[pose_indices[k]].dots_px;
      auto it = dots.find(dot);
      if (it == dots.end()) continue;
      track.base_from_cam.push_back(cams[k]);
      track.pixels.push_back(it->second);
    }
    return identification::TriangulatePoint(obs.camera, fx_px, track, obs.pixel_noise_px);
  };
  double sum = 0, sum2 = 0;
  for (const KnownDistance& known : distances) {
    DistanceCheck check;
    check.known = known;
    const auto a = triangulate(known.dot_a);
    const auto b = triangulate(known.dot_b);
    if (a.ok && b.ok) {
      check.ok = true;
      check.measured_m = (a.point - b.point).norm();
      check.error_m = std::abs(check.measured_m - known.length_m);
      ++summary.num_ok;
      sum += check.error_m;
      sum2 += check.error_m * check.error_m;
      summary.max_error_m = std::max(summary.max_error_m, check.error_m);
    }
    summary.checks.push_back(check);
  }
  if (summary.num_ok > 0) {
    summary.mean_error_m = sum / summary.num_ok;
    summary.rms_error_m = std::sqrt(sum2 / summary.num_ok);
  }
  return summary;
}

namespace {

// K3: excitation is a property of the joint angles alone: checked before any image is used. False, with
// the report's outcome and message, when the identification poses do not excite the parameters.
bool CheckExcitation(const RobotModel& robot, const Eigen::VectorXd& rho_nominal,
                     const std::vector<Eigen::VectorXd>& all_joints, const PaperPipelineOptions& options,
                     PaperPipelineReport* report) {
  report->identifiability =
      identification::AnalyzeIdentifiability(robot, rho_nominal, all_joints, 0, options.identifiability);
  if (report->identifiability.condition_number <= options.max_condition_number) return true;
  report->outcome = Outcome::kDegenerate;
  std::ostringstream msg;
  msg << "insufficient excitation: the identification poses give a condition number of "
      << report->identifiability.condition_number << " (limit " << options.max_condition_number
      << "); move the joints further apart between poses";
  report->message = msg.str();
  return false;
}

// Step 2, the factor method on each pair (reference, i) with the tbar_i of eq. (21), and f_x as the mean
// of the pairs that observe it.
void EstimatePairs(const ObservationSet& obs, const std::vector<int>& id_poses, const Eigen::VectorXd& rho_nominal,
                   const Rigid3& nominal_ref_from_base, const PaperPipelineOptions& options,
                   PaperPipelineReport* report) {
  const RobotModel& robot = obs.robot;
  const int ref = id_poses.front();
  double fx_sum = 0;
  ProgressScope progress(options.progress, static_cast<int64_t>(id_poses.size()) - 1, "two-view pairs");
  for (size_t k = 1; k < id_poses.size(); ++k, progress.Advance()) {
    const int i = id_poses[k];
    PoseMeasurement m;
    m.pose_index = i;
    m.pose_id = obs.poses[i].id;
    const Matches matches = MatchById(obs.poses[ref], obs.poses[i]);
    twoview::TwoViewOptions two_view_options = options.two_view;
    two_view_options.seed = options.two_view.seed + static_cast<uint64_t>(k);
    m.two_view = twoview::EstimateTwoView(two_view_options, obs.camera, matches.pixels_a, matches.pixels_b);
    m.nominal_translation = (nominal_ref_from_base * BaseFromCam(robot, rho_nominal, obs.poses[i].joints_rad)).translation;
    if (m.two_view.outcome == twoview::Outcome::kSuccess && m.two_view.fx_observable) {
      fx_sum += m.two_view.fx_px;
      ++report->fx_pairs;
    }
    report->measurements.push_back(std::move(m));
  }
  report->fx_px = report->fx_pairs > 0 ? fx_sum / report->fx_pairs : obs.camera.fx_px;
}

// Pairs whose f_x was unobservable were solved with the prior: solve them again with the camera's f_x
// as the observable pairs measured it.
void SolveAgainWithMeasuredFx(const ObservationSet& obs, int ref, const PaperPipelineOptions& options,
                              PaperPipelineReport* report) {
  if (report->fx_pairs == 0 || !options.two_view.estimate_focal) return;
  CameraIntrinsics camera = obs.camera;
  camera.fx_px = report->fx_px;
  for (size_t k = 0; k < report->measurements.size(); ++k) {
    PoseMeasurement& m = report->measurements[k];
    if (m.two_view.fx_observable) continue;
    const Matches matches = MatchById(obs.poses[ref], obs.poses[m.pose_index]);
    twoview::TwoViewOptions two_view_options = options.two_view;
    two_view_options.seed = options.two_view.seed + static_cast<uint64_t>(k + 1);
    two_view_options.estimate_focal = false;
    m.two_view = twoview::EstimateTwoView(two_view_options, camera, matches.pixels_a, matches.pixels_b);
    m.fx_from_other_pairs = true;
  }
}

// The measured motions of the usable pairs: camera-centre directions and their tbar_i.
struct Motions {
  std::vector<Eigen::Vector3d> directions, nominal_translations;
};

// Marks the pairs the two-view solve succeeded on as used and gives their measured rotations.
Motions UsableMotions(PaperPipelineReport* report) {
  Motions motions;
  for (PoseMeasurement& m : report->measurements) {
    if (m.two_view.outcome != twoview::Outcome::kSuccess) continue;
    // (R, t) is cam_i_from_cam_ref; the measurement is its inverse, the camera centre's direction -R^T t.
    const Eigen::Matrix3d r_ref_from_i = m.two_view.rotation.transpose();
    motions.directions.push_back(-(r_ref_from_i * m.two_view.translation_direction).normalized());
    motions.nominal_translations.push_back(m.nominal_translation);
    m.measured_cam_ref_from_cam.rotation = r_ref_from_i;
    m.used = true;
  }
  return motions;
}

// The report's degenerate outcome when too few pairs are usable, with every unused pair's reason.
void TooFewMotions(size_t usable, const PaperPipelineOptions& options, PaperPipelineReport* report) {
  report->outcome = Outcome::kDegenerate;
  std::ostringstream msg;
  msg << "only " << usable << " usable pose measurements (need " << options.min_pose_measurements << ")";
  for (const PoseMeasurement& m : report->measurements) {
    if (!m.used) msg << "; pose " << m.pose_id << ": " << twoview::OutcomeName(m.two_view.outcome) << " " << m.two_view.message;
  }
  report->message = msg.str();
}

// Step 3: identification over the identifiable parameters from the eq. (21)-scaled relative poses, then
// reweighted by the residuals. False, with the report's outcome and message, when nothing is
// identifiable or the solve failed.
bool IdentifyParameters(const ObservationSet& obs, const Eigen::VectorXd& rho_nominal, size_t num_all_joints,
                        const std::vector<Eigen::Vector3d>& scaled, const PaperPipelineOptions& options,
                        PaperPipelineReport* report) {
  const RobotModel& robot = obs.robot;
  const auto start_identification = Clock::now();
  std::vector<Eigen::VectorXd> joints;
  std::vector<identification::RelativePoseMeasurement> relative;
  const int ref_in_joints = 0;  // the reference pose goes first
  joints.push_back(obs.poses[report->reference_pose].joints_rad);
  size_t used_index = 0;
  for (PoseMeasurement& m : report->measurements) {
    if (!m.used) continue;
    m.measured_cam_ref_from_cam.translation = scaled[used_index];
    m.scale = scaled[used_index].norm();
    ++used_index;
    joints.push_back(obs.poses[m.pose_index].joints_rad);
    relative.push_back({static_cast<int>(joints.size()) - 1, m.measured_cam_ref_from_cam, true});
  }
  // The K3 analysis already covered these poses when every pair was usable (same poses, same order).
  if (joints.size() != num_all_joints) {
    report->identifiability =
        identification::AnalyzeIdentifiability(robot, rho_nominal, joints, ref_in_joints, options.identifiability);
  }
  if (report->identifiability.free_indices.empty()) {
    report->outcome = Outcome::kDegenerate;
    report->message = "no kinematic parameter is identifiable from these poses";
    return false;
  }
  identification::IdentificationOptions id_options = options.identification;
  report->identification = identification::IdentifyFromRelativePoses(
      robot, rho_nominal, report->identifiability.free_indices, joints, ref_in_joints, relative, id_options);
  for (int round = 0; round < options.reweighting_rounds; ++round) {
    const identification::IdentificationReport& last = report->identification;
    if (last.outcome != identification::Outcome::kConverged || !(last.rms_position_m > 0) ||
        !(last.rms_rotation_rad > 0)) {
      break;
    }
    // Floors keep noise-free data from driving a weight to infinity.
    id_options.sigma_position_m = std::max(last.rms_position_m, 1e-9);
    id_options.sigma_rotation_rad = std::max(last.rms_rotation_rad, 1e-12);
    identification::IdentificationReport reweighted = identification::IdentifyFromRelativePoses(
        robot, rho_nominal, report->identifiability.free_indices, joints, ref_in_joints, relative, id_options);
    if (reweighted.outcome != identification::Outcome::kConverged) break;  // keep the converged solve
    report->identification = std::move(reweighted);
  }
  report->seconds_identification = SecondsSinceStart(start_identification);
  if (report->identification.outcome == identification::Outcome::kFailure ||
      report->identification.outcome == identification::Outcome::kInvalidInput) {
    report->outcome = Outcome::kSolverFailure;
    report->message = "identification failed: " + report->identification.message;
    return false;
  }
  return true;
}

// Steps 4 and 5: the yardstick's metric scale from the identification views, then the held-out 3-D
// errors before (nominal model, prior f_x) and after; the report's final outcome.
void ScaleAndVerify(const ObservationSet& obs, const std::vector<int>& id_poses,
                    const std::vector<int>& verification_poses, const Eigen::VectorXd& rho_nominal,
                    const PaperPipelineOptions& options, PaperPipelineReport* report) {
  const RobotModel& robot = obs.robot;
  report->calibrated_robot = ApplyParameters(robot, report->identification.rho);
  report->calibrated_rho = KinematicParameters::Nominal(report->calibrated_robot);
  report->yardstick = identification::EstimateYardstickScale(
      obs.camera, report->fx_px, YardstickViews(obs, id_poses, report->calibrated_robot, report->calibrated_rho),
      obs.pixel_noise_px, options.yardstick_max_relative_sigma);
  if (report->yardstick.ok) {
    ScaleLengths(report->yardstick.scale, &report->calibrated_robot, &report->calibrated_rho);
  }
  if (!verification_poses.empty() && !obs.check_distances.empty()) {
    report->verification_nominal =
        VerifyDistances(obs, verification_poses, robot, rho_nominal, obs.camera.fx_px, obs.check_distances);
    report->verification_calibrated = VerifyDistances(obs, verification_poses, report->calibrated_robot,
                                                      report->calibrated_rho, report->fx_px, obs.check_distances);
  }
  if (!report->yardstick.ok) {
    report->outcome = Outcome::kScaleUnresolved;
    report->message = "metric scale unresolved: " + report->yardstick.message;
  } else if (report->identification.outcome != identification::Outcome::kConverged) {
    report->outcome = Outcome::kUnconverged;
    report->message = "identification did not converge: " + report->identification.termination;
  } else {
    report->outcome = Outcome::kSuccess;
  }
}

}  // namespace

PaperPipelineReport RunPaperPipeline(const ObservationSet& obs, const PaperPipelineOptions& options) {
  const auto start = Clock::now();
  PaperPipelineReport report;
  const std::string problems = obs.Validate() + options.two_view.Validate() + options.identification.Validate();
  if (!problems.empty()) {
    report.outcome = Outcome::kInvalidInput;
    report.message = "invalid input:\n" + problems;
    return report;
  }
  if (obs.robot.mount == CameraMount::kEyeToHand) {
    // Its steps 3-4 fit the camera motions through the arm to the camera (identification/): eye-in-hand.
    report.outcome = Outcome::kNotRun;
    report.message = kPaperNotEyeToHand;
    return report;
  }
  const std::vector<int> id_poses = obs.PosesWithRole(PoseRole::kIdentification);
  const std::vector<int> verification_poses = obs.PosesWithRole(PoseRole::kVerification);
  if (id_poses.size() < 2) {
    report.outcome = Outcome::kDegenerate;
    report.message = "fewer than two identification poses";
    return report;
  }
  const RobotModel& robot = obs.robot;
  const Eigen::VectorXd rho_nominal = KinematicParameters::Nominal(robot);
  const int ref = id_poses.front();
  report.reference_pose = ref;
  const Rigid3 nominal_ref_from_base = BaseFromCam(robot, rho_nominal, obs.poses[ref].joints_rad).Inverse();
  std::vector<Eigen::VectorXd> all_joints;
  for (int i : id_poses) all_joints.push_back(obs.poses[i].joints_rad);
  if (!CheckExcitation(robot, rho_nominal, all_joints, options, &report)) return report;

  // Step 2: the factor method on each pair (reference, i), eq. (21) for the scales.
  const auto start_two_view = Clock::now();
  EstimatePairs(obs, id_poses, rho_nominal, nominal_ref_from_base, options, &report);
  SolveAgainWithMeasuredFx(obs, ref, options, &report);
  const Motions motions = UsableMotions(&report);
  report.seconds_two_view = SecondsSinceStart(start_two_view);
  if (static_cast<int>(motions.directions.size()) < options.min_pose_measurements) {
    TooFewMotions(motions.directions.size(), options, &report);
    return report;
  }
  // k_1 = ||tbar_1||: the nominal metric length of the first motion, so the nominal model is a good start.
  const std::vector<Eigen::Vector3d> scaled = identification::ScaleByNominalRatios(
      motions.directions, motions.nominal_translations, motions.nominal_translations.front().norm());

  // Steps 3 to 5.
  if (!IdentifyParameters(obs, rho_nominal, all_joints.size(), scaled, options, &report)) return report;
  ScaleAndVerify(obs, id_poses, verification_poses, rho_nominal, options, &report);
  report.seconds_total = SecondsSinceStart(start);
  return report;
}

}  // namespace selfcal::calibration
