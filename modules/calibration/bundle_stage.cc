#include "calibration/bundle_stage.h"

#include <algorithm>
#include <chrono>
#include <cmath>

namespace selfcal::calibration {

const char* BundleStartName(BundleStart start) {
  switch (start) {
    case BundleStart::kNotRun: return "not_run";
    case BundleStart::kPaperPipeline: return "paper_pipeline";
    case BundleStart::kNominal: return "nominal";
  }
  return "unknown";
}

Eigen::VectorXd BundleStartFromPaper(const ObservationSet& obs, const PaperPipelineReport& paper, double* fx_px,
                                     BundleStart* start, std::string* note) {
  const Eigen::VectorXd nominal = KinematicParameters::Nominal(obs.robot);
  const bool usable = paper.outcome == Outcome::kSuccess && paper.calibrated_rho.size() == obs.robot.num_parameters() &&
                      paper.calibrated_robot.num_joints() == obs.robot.num_joints() &&
                      paper.calibrated_rho.allFinite() && std::isfinite(paper.fx_px) && paper.fx_px > 0;
  if (!usable) {
    // The paper's f_x comes from the same factor method that failed (on a flat sheet its pairs are
    // planar): the user's prior is the safer start.
    *fx_px = obs.camera.fx_px;
    if (start != nullptr) *start = BundleStart::kNominal;
    if (note != nullptr) {
      *note = std::string("nominal model and prior f_x (the paper pipeline ended ") + OutcomeName(paper.outcome) + ")";
    }
    return nominal;
  }
  Eigen::VectorXd rho = bundle::ExpressOnModel(obs.robot, paper.calibrated_robot, paper.calibrated_rho);
  // The paper's gauge (what it held fixed) went through its yardstick scaling; the bundle keeps its fixed
  // entries at their start, so put them back to nominal (unobservable: no image changes, exactly).
  const std::vector<int>& free = paper.identifiability.free_indices;
  for (int i = 0; i < rho.size(); ++i) {
    if (std::find(free.begin(), free.end(), i) == free.end()) rho[i] = nominal[i];
  }
  *fx_px = paper.fx_px;
  if (start != nullptr) *start = BundleStart::kPaperPipeline;
  if (note != nullptr) *note = "paper pipeline's calibrated model and f_x (its fixed entries at nominal)";
  return rho;
}

namespace {

double SecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// The held-out reprojection figures of the calibrated and the nominal model (see bundle_stage.h), every
// estimated intrinsic's uncertainty in the calibrated model's prediction.
void VerifyHeldOutReprojection(const ObservationSet& obs, BundleStageReport* report) {
  const bundle::BundleReport& b = report->bundle;
  double noise = 0;
  int noise_dof = 0;
  report->heldout = HeldOutReprojectionOfBundle(obs, b, &noise, &noise_dof);
  if (!b.covariance_available) report->heldout.message = "prediction uncertainty of the parameters left out: " + b.covariance_message;
  double stated = 0;
  int stated_dof = 0;
  report->heldout_at_stated_noise =
      HeldOutReprojectionOfBundle(obs, b, &stated, &stated_dof, obs.pixel_noise_px).overall;
  report->heldout_nominal = NominalHeldOutReprojection(obs, noise, noise_dof);
  report->heldout_nominal.noise_source = report->heldout.noise_source;
}

// A nominal start of a joint-angle set: its camera correction from the images (StartCameraFromImages). True
// when the images gave it.
bool CameraStartFromImages(const ObservationSet& obs, const BundleStageOptions& options, Eigen::VectorXd* rho,
                           std::string* note) {
  if (!options.camera_start_from_images || obs.UsesFlangePoses()) return false;
  const std::vector<int> held = bundle::HeldParameterIndices(options.bundle, obs.robot.num_joints());
  const int cam = KinematicParameters(obs.robot.num_joints()).CamOffset();
  for (int i = cam; i < cam + 6; ++i) {
    if (std::find(held.begin(), held.end(), i) != held.end()) return false;  // the mount is held: trusted
  }
  const HandEyeStartReport start = StartCameraFromImages(obs, options.hand_eye, rho);
  *note += start.ok ? "; camera correction from the images (hand-eye on the nominal flange poses, " +
                          std::to_string(start.rotation_pairs) + " rotation pairs)"
                    : "; camera at the robot description's mount (no hand-eye start from the images: " + start.message + ")";
  return start.ok;
}

// A camera start from the images that leads the bundle nowhere (the dots not triangulable from it, no
// convergence) is a wrong start, not a verdict on the data: the bundle is run again from the camera at the
// robot description's mount, and that run is kept when it converged.
void RetryAtTheDescribedMount(const ObservationSet& obs, const BundleStageOptions& options, BundleStageReport* report) {
  if (!report->camera_from_images || report->bundle.outcome == bundle::Outcome::kConverged ||
      report->bundle.outcome == bundle::Outcome::kInvalidInput) {
    return;
  }
  bundle::BundleReport again =
      bundle::RunBundleAdjustment(obs, KinematicParameters::Nominal(obs.robot), report->fx_start_px, options.bundle);
  if (again.outcome != bundle::Outcome::kConverged) return;
  again.seconds += report->bundle.seconds;
  report->start_note += std::string("; from the images' camera the bundle ended ") +
                        bundle::OutcomeName(report->bundle.outcome) +
                        ", so it started again from the camera at the robot description's mount";
  report->bundle = std::move(again);
  report->camera_from_images = false;
}

}  // namespace

HeldOutReprojection HeldOutReprojectionOfBundle(const ObservationSet& obs, const bundle::BundleReport& b,
                                                double* noise_px, int* noise_dof, double at_noise_px) {
  const bool estimated = std::isfinite(b.pixel_noise_estimate_px) && b.pixel_noise_estimate_px > 0;
  const bool model = b.error_model.estimated;
  const double fitted_px = model ? b.error_model.pixel_px : estimated ? b.pixel_noise_estimate_px : obs.pixel_noise_px;
  *noise_px = at_noise_px > 0 ? at_noise_px : fitted_px;
  *noise_dof = at_noise_px > 0 || !estimated ? 0 : b.residual_dof;
  PredictionModel calibrated;
  calibrated.robot = obs.robot;
  calibrated.rho = b.rho;
  calibrated.camera = WithIntrinsics(obs.camera, b.intrinsics);
  calibrated.free_indices = b.free_indices;
  calibrated.intrinsics_estimated = b.intrinsics_estimated;
  calibrated.yardstick_sigma_m = b.yardstick_sigma_m;
  if (b.covariance_available) {
    calibrated.covariance = b.covariance_free;
    if (*noise_px != fitted_px) {  // the pixel part scales with the pixel variance, the pose part does not
      const Eigen::Index n = b.covariance_free.rows();
      const Eigen::MatrixXd pose_part =
          b.covariance_pose_part.rows() == n ? b.covariance_pose_part : Eigen::MatrixXd::Zero(n, n);
      const double ratio = (*noise_px / fitted_px) * (*noise_px / fitted_px);
      calibrated.covariance = ratio * (b.covariance_free - pose_part) + pose_part;
    }
    if (b.covariance_pose_part.rows() == b.covariance_free.rows()) calibrated.covariance_pose_part = b.covariance_pose_part;
  }
  // A weak parameter is the description's value, as true as its manufacturing tolerance says.
  const KinematicParameters names(obs.robot.num_joints());
  for (const bundle::WeakParameter& w : b.weak) {
    const int index = names.IndexOf(w.name);
    if (index >= 0 && w.tolerance > 0) calibrated.held_prior.emplace_back(index, w.tolerance);
  }
  if (model) {
    calibrated.pose_translation_m = b.error_model.pose_translation_m;
    calibrated.pose_rotation_rad = b.error_model.pose_rotation_rad;
    calibrated.joint_rad = b.error_model.joint_rad > 0 ? b.error_model.joint_rad : 0.0;
    // The estimated sizes are only as good as the residuals they came from; a stated pixel noise is known.
    calibrated.relative_variance_covariance = b.error_model.relative_covariance;
    if (at_noise_px > 0) {
      calibrated.relative_variance_covariance.row(0).setZero();
      calibrated.relative_variance_covariance.col(0).setZero();
    }
  }
  ExcludedObservations excluded;
  for (const bundle::RemovedObservation& o : b.removed) excluded.insert({o.pose_id, o.dot_id});
  HeldOutReprojection heldout = HeldOutReprojectionOf(obs, calibrated, b.dots_in_base, excluded, *noise_px, *noise_dof);
  heldout.noise_source = at_noise_px > 0 ? "the stated pixel noise"
                         : estimated    ? "the bundle's estimate from its identification residuals"
                                        : "the stated pixel noise (the bundle has no redundancy to estimate it)";
  if (model && (b.error_model.pose_translation_m > 0 || b.error_model.pose_rotation_rad > 0 ||
                b.error_model.joint_rad > 0)) {
    heldout.noise_source += ", with each image's pose error as estimated";
  }
  return heldout;
}

BundleStageReport RunBundleStage(const ObservationSet& obs, const PaperPipelineReport& paper,
                                 const BundleStageOptions& options) {
  const auto clock_start = std::chrono::steady_clock::now();
  BundleStageReport report;
  Eigen::VectorXd rho_start =
      BundleStartFromPaper(obs, paper, &report.fx_start_px, &report.start, &report.start_note);
  // A held parameter is the robot description's value, not the paper pipeline's estimate of it: the bundle
  // keeps held entries at their start (`--fix kinematics` trusts the nominal kinematics).
  const std::vector<int> held = bundle::HeldParameterIndices(options.bundle, obs.robot.num_joints());
  if (!held.empty() && report.start == BundleStart::kPaperPipeline) {
    const Eigen::VectorXd nominal = KinematicParameters::Nominal(obs.robot);
    for (const int i : held) rho_start[i] = nominal[i];
    report.start_note += "; held parameters at nominal";
  }
  if (report.start == BundleStart::kNominal) {
    report.camera_from_images = CameraStartFromImages(obs, options, &rho_start, &report.start_note);
  }
  // A held f_x is the one the user stated (the observations' camera), not the paper's estimate.
  if (!bundle::EstimatedIntrinsicsOf(options.bundle, obs.robot.num_joints())[kFx]) {
    report.fx_start_px = obs.camera.fx_px;
    report.start_note += "; f_x held at the stated value";
  }
  report.bundle = bundle::RunBundleAdjustment(obs, rho_start, report.fx_start_px, options.bundle);
  const bool retry = options.retry_from_nominal && report.start == BundleStart::kPaperPipeline &&
                     (report.bundle.outcome == bundle::Outcome::kNoConvergence ||
                      report.bundle.outcome == bundle::Outcome::kFailure);
  if (retry) {
    const std::string first = bundle::OutcomeName(report.bundle.outcome);
    std::string note = "nominal model and prior f_x (the start from the paper pipeline's result ended " + first + ")";
    Eigen::VectorXd nominal = KinematicParameters::Nominal(obs.robot);
    report.camera_from_images = CameraStartFromImages(obs, options, &nominal, &note);
    bundle::BundleReport again = bundle::RunBundleAdjustment(obs, nominal, obs.camera.fx_px, options.bundle);
    again.seconds += report.bundle.seconds;
    report.bundle = std::move(again);
    report.start = BundleStart::kNominal;
    report.fx_start_px = obs.camera.fx_px;
    report.start_note = note;
  }
  RetryAtTheDescribedMount(obs, options, &report);
  const bundle::BundleReport& b = report.bundle;
  const std::vector<int> verification_poses = obs.PosesWithRole(PoseRole::kVerification);
  const bool valid = !verification_poses.empty() && obs.Validate().empty();
  const bool verify = valid && !obs.check_distances.empty();
  auto step = std::chrono::steady_clock::now();
  if (verify) {
    report.verification_nominal = VerifyDistances(obs, verification_poses, obs.robot, KinematicParameters::Nominal(obs.robot),
                                                  obs.camera.fx_px, obs.check_distances);
    report.seconds_verification += SecondsSince(step);
  }
  if (b.rho.size() == obs.robot.num_parameters() && b.rho.allFinite() && std::isfinite(b.fx_px) && b.fx_px > 0) {
    report.calibrated_robot = ApplyParameters(obs.robot, b.rho);
    report.calibrated_rho = KinematicParameters::Nominal(report.calibrated_robot);
    report.calibrated_camera = WithIntrinsics(obs.camera, b.intrinsics);
    step = std::chrono::steady_clock::now();
    if (valid) VerifyHeldOutReprojection(obs, &report);
    if (verification_poses.empty()) report.heldout.message = "the set names no verification pose";
    report.seconds_heldout = SecondsSince(step);
    step = std::chrono::steady_clock::now();
    report.fit_geometry = FitGeometryOf(obs, b);
    report.seconds_fit_geometry = SecondsSince(step);
    const double depth_m = MedianCameraToDotDistance(obs, report.fit_geometry, b.dots_in_base);
    if (report.heldout.ok && std::isfinite(depth_m)) {
      report.heldout.mm_per_px = depth_m * 1e3 / b.fx_px;
      report.heldout.rms_mm = report.heldout.overall.rms_px * report.heldout.mm_per_px;
    }
    if (verify) {
      ObservationSet calibrated = obs;
      calibrated.camera = report.calibrated_camera;
      step = std::chrono::steady_clock::now();
      report.verification = VerifyDistances(calibrated, verification_poses, obs.robot, b.rho, b.fx_px, obs.check_distances);
      report.seconds_verification += SecondsSince(step);
      step = std::chrono::steady_clock::now();
      if (b.covariance_available) {
        // Order free, then the estimated intrinsics, f_x first when estimated (the others not propagated).
        // A held f_x: zero variance.
        const int nf = static_cast<int>(b.free_indices.size());
        Eigen::MatrixXd sigma = Eigen::MatrixXd::Zero(nf + 1, nf + 1);
        sigma.topLeftCorner(nf, nf) = b.covariance_free.topLeftCorner(nf, nf);
        if (b.intrinsics_estimated[kFx]) sigma = b.covariance_free.topLeftCorner(nf + 1, nf + 1);
        report.predicted_error = PredictDistanceErrors(calibrated, verification_poses, obs.robot, b.rho, b.fx_px,
                                                       b.free_indices, sigma, obs.pixel_noise_px, obs.check_distances);
      } else {
        report.predicted_error.message = "covariance unavailable: " + b.covariance_message;
      }
      report.seconds_predicted_error = SecondsSince(step);
    }
  }
  report.seconds_total = SecondsSince(clock_start);
  return report;
}

}  // namespace selfcal::calibration
