#include <algorithm>
#include <cmath>

#include "report/calibration_json_plots.h"
#include "report/calibration_json_scenes.h"
#include "report/calibration_report.h"
#include "report/json_util.h"

namespace selfcal::report {

namespace {

using nlohmann::json;

bool Contains(const std::vector<int>& v, int i) { return std::find(v.begin(), v.end(), i) != v.end(); }

json Vector3Json(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }

// A relative camera motion cam_from_reference_cam: its rotation vector and its translation (a unit
// direction for a pair, reference plane distances for a planar view) under `translation_key`.
json MotionJson(const Eigen::Matrix3d& rotation, const Eigen::Vector3d& translation, const char* translation_key) {
  return {{"rotvec_rad", Vector3Json(LogSO3(rotation))}, {translation_key, Vector3Json(translation)}};
}

// A pair's two-view solution, and the rival and the planes that a caller with more evidence can choose
// between when the pair stays ambiguous (twoview/two_view.h).
void AddTwoViewSolutions(const twoview::TwoViewReport& tv, json* row) {
  const bool posed = tv.outcome == twoview::Outcome::kSuccess || tv.outcome == twoview::Outcome::kNoConvergence ||
                     tv.outcome == twoview::Outcome::kAmbiguousPose || tv.outcome == twoview::Outcome::kPureRotation ||
                     tv.outcome == twoview::Outcome::kLowDepthVariation;
  (*row)["cam_from_reference"] = posed ? MotionJson(tv.rotation, tv.translation_direction, "translation_direction")
                                       : json();
  (*row)["plane_normal_in_reference_cam"] = tv.has_plane ? Vector3Json(tv.plane_normal) : json();
  json rival;
  if (tv.has_rival) {
    rival = MotionJson(tv.rival_rotation, tv.rival_translation_direction, "translation_direction");
    rival["plane_normal_in_reference_cam"] = tv.has_rival_plane ? Vector3Json(tv.rival_plane_normal) : json();
  }
  (*row)["rival"] = rival;
}

// A figure over no checks is absent (null), never 0.
json VerificationSummaryJson(const calibration::VerificationSummary& v) {
  json checks = json::array();
  for (const calibration::DistanceCheck& c : v.checks) {
    checks.push_back({{"dot_a", c.known.dot_a}, {"dot_b", c.known.dot_b}, {"known_m", c.known.length_m},
                      {"ok", c.ok}, {"measured_m", c.ok ? json(c.measured_m) : json()},
                      {"error_m", c.ok ? json(c.error_m) : json()}});
  }
  const bool any = v.num_ok > 0;
  return {{"num_checks", v.checks.size()},
          {"num_ok", v.num_ok},
          {"mean_error_m", any ? Finite(v.mean_error_m) : json()},
          {"rms_error_m", any ? Finite(v.rms_error_m) : json()},
          {"max_error_m", any ? Finite(v.max_error_m) : json()},
          {"checks", checks}};
}

json VerificationJson(const ObservationSet& obs, const calibration::VerificationSummary& nominal,
                      const calibration::VerificationSummary& calibrated) {
  return {{"poses", obs.PosesWithRole(PoseRole::kVerification).size()},
          {"nominal_model", VerificationSummaryJson(nominal)},
          {"calibrated_model", VerificationSummaryJson(calibrated)}};
}

json HeldOutFigureJson(const calibration::HeldOutFigure& f);

// The k-fold held-out figure (calibration/cross_validation.h).
json CrossValidationJson(const calibration::CrossValidationReport& cv) {
  json folds = json::array();
  for (const calibration::CrossValidationFold& f : cv.per_fold) {
    folds.push_back({{"held_out", f.held_out},
                     {"outcome", bundle::OutcomeName(f.outcome)},
                     {"message", f.message},
                     {"figure", f.figure.num_residuals > 0 ? HeldOutFigureJson(f.figure) : json()}});
  }
  return {{"ran", cv.ran},           {"message", cv.message},       {"folds", cv.folds},
          {"seed", cv.seed},         {"num_residuals", cv.pooled.num_residuals}, {"rms_px", Finite(cv.pooled.rms_px)},
          {"mm_per_px", Finite(cv.mm_per_px)}, {"rms_mm", Finite(cv.rms_mm)}, {"folds_passed", cv.folds_passed},
          {"folds_tested", cv.folds_tested},
          {"pooled", cv.pooled.dof > 0 ? HeldOutFigureJson(cv.pooled) : json()},
          {"per_fold", folds}};
}

// The parameters held because these poses determine them worse than their tolerance, and the joints that
// barely move (mm and deg, as the rest of the report's parameters).
json WeakJson(const bundle::BundleReport& b) {
  json held = json::array();
  for (const bundle::WeakParameter& w : b.weak) {
    const double scale = w.length ? 1e3 : RadToDeg(1.0);
    const char* unit = w.length ? "mm" : "deg";
    held.push_back({{"name", w.name},
                    {"unit", unit},
                    {"conditional_std", w.conditional_std * scale},
                    {"tolerance", w.tolerance * scale},
                    {"combination", w.combination},
                    {"under_error_model", w.under_error_model}});
  }
  json joints = json::array();
  for (const BarelyMovingJoint& j : b.barely_moving) {
    joints.push_back({{"joint", j.joint}, {"range_deg", RadToDeg(j.range_rad)}});
  }
  return {{"held", held}, {"barely_moving_joints", joints}};
}

json ModelChoiceJson(const std::optional<calibration::ModelChoice>& c) {
  if (!c) return json();
  return {{"made", c->made}, {"message", c->message}, {"folds", c->folds}, {"seed", c->seed},
          {"exact_pose_rms_px", Finite(c->exact_pose_rms_px)}, {"pose_noise_rms_px", Finite(c->pose_noise_rms_px)},
          {"pose_noise_chosen", c->pose_noise_chosen}};
}

json ErrorModelJson(const bundle::ErrorModel& m) {
  return {{"estimated", m.estimated},
          {"message", m.message},
          {"pixel_noise_px", Finite(m.pixel_px)},
          {"pose_translation_m", Finite(m.pose_translation_m)},
          {"pose_rotation_rad", Finite(m.pose_rotation_rad)},
          {"joint_rad", Finite(m.joint_rad)},
          {"redundancy", {{"pixel", Finite(m.pixel_redundancy)},
                          {"translation", Finite(m.translation_redundancy)},
                          {"rotation", Finite(m.rotation_redundancy)},
                          {"joint", Finite(m.joint_redundancy)}}},
          {"relative_variance_sd", {{"pixel", std::sqrt(m.relative_covariance(0, 0))},
                                    {"translation", std::sqrt(m.relative_covariance(1, 1))},
                                    {"rotation", std::sqrt(m.relative_covariance(2, 2))},
                                    {"joint", std::sqrt(m.relative_covariance(3, 3))}}},
          {"iterations", m.iterations}};
}

json HeldValuesJson(const bundle::HeldValueTest& t) {
  return {{"tested", t.tested}, {"names", t.names}, {"dof", t.dof}, {"chi_square", Finite(t.chi_square)},
          {"largest", t.largest}, {"decisive", t.decisive}};
}

json PredictedErrorJson(const calibration::PredictedDistanceErrors& p) {
  json distances = json::array();
  for (const calibration::PredictedDistanceError& e : p.distances) {
    distances.push_back({{"dot_a", e.known.dot_a}, {"dot_b", e.known.dot_b}, {"ok", e.ok},
                         {"std_m", Finite(e.std_m)}, {"parameters_std_m", Finite(e.parameters_std_m)},
                         {"pixels_std_m", Finite(e.pixels_std_m)}});
  }
  const bool any = p.ok && p.num_ok > 0;
  return {{"description", "predicted std of the 3-D error of each check distance: the bundle's covariance of the free "
                          "parameters and f_x (parameters part) and the stated pixel noise of the verification images "
                          "(pixels part), propagated through the triangulation to first order"},
          {"ok", p.ok},
          {"message", p.message},
          {"num_ok", p.num_ok},
          {"rms_std_m", any ? Finite(p.rms_std_m) : json()},
          {"rms_parameters_std_m", any ? Finite(p.rms_parameters_std_m) : json()},
          {"rms_pixels_std_m", any ? Finite(p.rms_pixels_std_m) : json()},
          {"distances", distances}};
}

// A held-out reprojection figure; its numbers null when it has no residual.
json HeldOutFigureJson(const calibration::HeldOutFigure& f) {
  const bool any = f.num_residuals > 0;
  json j = {{"num_residuals", f.num_residuals},
            {"dof", f.dof},
            {"rms_px", any ? Finite(f.rms_px) : json()},
            {"max_px", any ? Finite(f.max_px) : json()},
            {"chi_square", any ? Finite(f.chi_square) : json()},
            {"noise_dof", f.noise_dof},
            {"pose_share", f.pose_share},
            {"pose_noise_dof", f.pose_noise_dof},
            {"chi_square_limit", any ? Finite(f.chi_square_limit) : json()},
            {"p_value", any ? Finite(f.p_value) : json()},
            {"test_passed", any ? json(f.test_passed) : json()}};
  if (!f.pose_id.empty()) j["pose"] = f.pose_id;
  return j;
}

json HeldOutModelJson(const calibration::HeldOutReprojection& h) {
  json poses = json::array();
  for (const calibration::HeldOutFigure& f : h.poses) poses.push_back(HeldOutFigureJson(f));
  return {{"ok", h.ok},
          {"message", h.message},
          {"prediction_uncertainty", h.prediction_uncertainty},
          {"num_not_predicted", h.num_not_predicted},
          {"gross_errors", ResidualsJson(h.gross_errors)},
          {"overall", h.ok ? HeldOutFigureJson(h.overall) : json()},
          {"poses", poses}};
}

// A held-out reprojection (the bundle's, or the pose-noise solve's: `at_stated` its overall figure at the stated
// noise) beside the nominal model's; null when it was not computed (no converged rho, no verification pose).
json HeldOutJson(const ObservationSet& obs, const calibration::HeldOutReprojection& c,
                 const calibration::HeldOutFigure& at_stated, const calibration::HeldOutReprojection& n) {
  if (!c.ok && c.overall.num_residuals == 0 && c.poses.empty() && c.message.empty()) return nullptr;
  json calibrated = HeldOutModelJson(c);
  calibrated["overall_at_stated_noise"] = c.ok ? HeldOutFigureJson(at_stated) : json();
  calibrated["m_per_px"] = Finite(c.mm_per_px * 1e-3);  // SI keys (the cross-validation's mm keys predate the rule)
  calibrated["rms_m"] = Finite(c.rms_mm * 1e-3);
  const bool compare = c.ok && n.ok;
  return {{"description", "the dots placed from the identification images (the bundle's, or triangulated with the nominal "
                          "model) projected into every verification image with the same model and compared with the "
                          "detections; chi-square of the residuals normalised by the detection noise and the "
                          "prediction's own first-order uncertainty, 2 degrees of freedom per dot, tested at 95 %: "
                          "chi-square (Wilson-Hilferty) when the noise is taken as known, dof x F(dof, noise_dof) "
                          "(Paulson) when it is the bundle's estimate from noise_dof residual degrees of freedom"},
          {"noise_px", Finite(c.noise_px)},
          {"noise_source", c.noise_source},
          {"stated_noise_px", obs.pixel_noise_px},
          {"test_passed", c.ok ? json(at_stated.test_passed) : json()},
          {"beats_nominal", compare ? json(c.overall.rms_px < n.overall.rms_px) : json()},
          {"calibrated_model", calibrated},
          {"nominal_model", HeldOutModelJson(n)}};
}

json PoseMeasurementsJson(const calibration::PaperPipelineReport& r) {
  json measurements = json::array();
  for (const calibration::PoseMeasurement& m : r.measurements) {
    measurements.push_back({{"pose", m.pose_id},
                            {"outcome", twoview::OutcomeName(m.two_view.outcome)},
                            {"message", m.two_view.message},
                            {"used", m.used},
                            {"fx_px", m.two_view.fx_px},
                            {"fx_observable", m.two_view.fx_observable},
                            {"fx_from_other_pairs", m.fx_from_other_pairs},
                            {"planar", m.two_view.planar},
                            {"inliers", m.two_view.num_inliers},
                            {"rms_epipolar_px", m.two_view.rms_epipolar_px},
                            {"eq21_scale_m", m.scale},
                            {"far_point_fraction", m.two_view.far_point_fraction},
                            {"warnings", m.two_view.warnings},
                            {"refinement", m.two_view.refinement_termination}});
    AddTwoViewSolutions(m.two_view, &measurements.back());
  }
  return measurements;
}

// One row per kinematic parameter, SI with the unit in the key: name, free, nominal_*, `value_key`_* (the
// estimate), correction_* (estimate - nominal, when `with_correction`), stddev_* (null when unknown).
json ParametersJson(const ObservationSet& obs, const Eigen::VectorXd& rho, const Eigen::VectorXd& stddev,
                    const std::vector<int>& free_indices, const std::string& value_key, bool with_correction) {
  json parameters = json::array();
  if (rho.size() != obs.robot.num_parameters()) return parameters;
  const KinematicParameters params(obs.robot.num_joints());
  const Eigen::VectorXd nominal = KinematicParameters::Nominal(obs.robot);
  for (int i = 0; i < params.size(); ++i) {
    const std::string unit = SiSuffix(params, i);
    json row = {{"name", params.name(i)},
                {"free", Contains(free_indices, i)},
                {"nominal" + unit, nominal[i]},
                {value_key + unit, rho[i]},
                {"stddev" + unit, Finite(stddev.size() > i ? stddev[i] : NAN)}};
    if (with_correction) row["correction" + unit] = rho[i] - nominal[i];
    parameters.push_back(std::move(row));
  }
  return parameters;
}

json PaperSectionJson(const ObservationSet& obs, const calibration::PaperPipelineReport& r) {
  const identification::IdentifiabilityReport& id = r.identifiability;
  const identification::IdentificationReport& ident = r.identification;
  json lengths = json::array();
  for (double l : r.yardstick.measured_lengths_m) lengths.push_back(l);
  return {
      {"description", "paper pipeline (Meng & Zhuang 2001): factor method, eq. (21) scale, LM identification, yardstick"},
      // A paper pipeline that was not run (flange poses) has no verdict of its own.
      {"verdict", r.outcome == calibration::Outcome::kNotRun ? "not_run"
                                                               : calibration::VerdictName(calibration::VerdictFor(r.outcome))},
      {"outcome", calibration::OutcomeName(r.outcome)},
      {"message", r.message},
      {"fx_px", r.fx_px},
      {"fx_pairs", r.fx_pairs},
      {"reference_pose", r.reference_pose >= 0 ? obs.poses[r.reference_pose].id : ""},
      {"pose_measurements", PoseMeasurementsJson(r)},
      {"identifiability", {{"num_parameters", id.num_parameters}, {"identifiable", id.rank},
                           {"free", id.free_names}, {"fixed", id.fixed_names},
                           {"null_combinations", id.null_combinations},
                           {"condition_number", Finite(id.condition_number)}}},
      {"identification", {{"outcome", identification::OutcomeName(ident.outcome)},
                          {"message", ident.message},
                          {"termination", ident.termination},
                          {"iterations", ident.iterations},
                          {"initial_cost", ident.initial_cost},
                          {"final_cost", ident.final_cost},
                          {"rms_position_m", ident.rms_position_m},
                          {"rms_rotation_rad", ident.rms_rotation_rad},
                          {"covariance_available", ident.covariance_available},
                          {"covariance_message", ident.covariance_message}}},
      {"parameters",
       ParametersJson(obs, ident.rho, ident.stddev, ident.free_indices, "identified_before_yardstick", false)},
      {"yardstick", {{"ok", r.yardstick.ok},
                     {"message", r.yardstick.message},
                     {"scale", r.yardstick.scale},
                     {"scale_sigma", r.yardstick.scale_sigma},
                     {"measured_lengths_before_scale_m", lengths}}},
      {"verification", VerificationJson(obs, r.verification_nominal, r.verification_calibrated)},
      {"predicted_3d_error", nullptr}};
}

// Every intrinsic by name (camera/camera.h): its value (px for f_x, c_x, c_y), whether it was estimated,
// and its standard deviation (null when held or unavailable).
json IntrinsicsJson(const IntrinsicsVector& values, const IntrinsicsMask& estimated, const IntrinsicsVector& stddev) {
  json out = json::object();
  for (int k = 0; k < kNumIntrinsics; ++k) {
    const std::string unit = k == kFx || k == kCx || k == kCy ? "_px" : "";
    out[IntrinsicName(k)] = {{"value" + unit, values[k]},
                             {"estimated", estimated[k]},
                             {"stddev" + unit, estimated[k] ? Finite(stddev[k]) : json()}};
  }
  return out;
}

json BundleSectionJson(const ObservationSet& obs, const calibration::BundleStageReport& stage) {
  const bundle::BundleReport& b = stage.bundle;
  json removed = json::array();
  for (const bundle::RemovedObservation& o : b.removed) {
    removed.push_back({{"pose", o.pose_id}, {"dot", o.dot_id}, {"residual_px", o.residual_px}});
  }
  return {{"description", "kinematic bundle adjustment: reprojection of every dot in every identification image"
                          " over the free kinematic parameters, hand-eye, f_x and the dots; "
                          "yardstick as a length constraint"},
          {"verdict", calibration::VerdictName(calibration::VerdictFor(b.outcome))},
          {"outcome", bundle::OutcomeName(b.outcome)},
          {"message", b.message},
          {"fx_px", b.fx_px},
          {"fx_stddev_px", Finite(b.fx_stddev)},
          {"k1", b.intrinsics[kK1]},
          {"k1_stddev", Finite(b.intrinsics_stddev[kK1])},
          {"intrinsics", IntrinsicsJson(b.intrinsics, b.intrinsics_estimated, b.intrinsics_stddev)},
          {"start", calibration::BundleStartName(stage.start)},
          {"start_note", stage.start_note},
          {"fx_start_px", stage.fx_start_px},
          {"solver", {{"termination", b.termination}, {"iterations", b.iterations},
                      {"initial_cost", b.initial_cost}, {"final_cost", b.final_cost}}},
          {"num_observations", b.num_observations},
          {"rms_reprojection_px", b.rms_reprojection_px},
          {"removed_observations", removed},
          {"dropped_dots", b.dropped_dots},
          {"free", b.free_names},
          {"fixed", b.fixed_names},
          {"null_combinations", b.null_combinations},
          {"weak", WeakJson(b)},
          {"generic_rank", b.generic_rank},
          {"condition_number", Finite(b.condition_number)},
          {"covariance_available", b.covariance_available},
          {"covariance_message", b.covariance_message},
          {"error_model", ErrorModelJson(b.error_model)},
          {"held_values", HeldValuesJson(b.held_values)},
          {"parameters", ParametersJson(obs, b.rho, b.stddev, b.free_indices, "value", true)},
          {"verification", VerificationJson(obs, stage.verification_nominal, stage.verification)},
          {"predicted_3d_error", PredictedErrorJson(stage.predicted_error)},
          {"heldout_reprojection", HeldOutJson(obs, stage.heldout, stage.heldout_at_stated_noise, stage.heldout_nominal)},
          {"plot_data", BundlePlotDataJson(obs, stage)}};
}

// The session block: the input's path and manifest hash, the journal's counts, the findings.
json SessionJson(const ReportInput& input, const SessionContext& session) {
  const session::JournalSummary& s = session.summary;
  return {{"path", input.path},
          {"session_id", s.session_id},
          {"session_json_sha256", input.sha256},
          {"poses_planned", s.poses_planned},
          {"samples_accepted", s.samples_accepted},
          {"resumes", s.resumes},
          {"finished", s.finished},
          {"skips_by_reason", s.skips_by_reason},
          {"faults_by_kind", s.faults_by_kind},
          {"halts_by_reason", s.halts_by_reason},
          {"warnings", session.findings}};
}

// A flange-pose set's hand-eye start and, when accepted, the calibrated transform with its sigmas.
constexpr const char* kImageMotionsDescription =
    "the images' own camera poses: a bundle adjustment of the images alone, every camera free (no flange pose, no "
    "hand-eye transform), its rotation angles between pairs of images against the flange motions' (pairs), and each "
    "image's camera pose (camera_poses_from_images: base_from_cam, moved onto the model's base frame by the one rigid "
    "transform that best aligns all of them with the model's camera poses) with its disagreement with the model's "
    "camera pose (flange pose times the calibrated hand-eye transform, methods.bundle.plot_data.camera_poses_from_model)";

json HandEyeJson(const calibration::CalibrationReport& report) {
  const calibration::HandEyeStartReport& start = *report.hand_eye_start;
  json j;
  j["start"] = {{"ok", start.ok},
                {"message", start.message},
                {"pairs_tried", start.pairs.size()},
                {"rotation_pairs", start.rotation_pairs},
                {"translation_pairs", start.translation_pairs},
                {"rotation_residual_rms_rad", start.rotation_rms_rad},
                {"fx_px", start.fx_px},
                {"fx_from_images", start.fx_from_images}};
  j["start"]["plane"] = json();
  if (start.plane) {
    const twoview::PlanarViewsReport& p = *start.plane;
    json views = json::array();
    for (size_t k = 0; k < p.views.size(); ++k) {
      const twoview::PlanarView& v = p.views[k];
      const bool reference = static_cast<int>(k) == p.reference;  // its own normal is the plane's, above
      json view = {{"ok", v.ok}, {"resolved", v.resolved}, {"message", v.message}, {"has_rival", v.has_rival}};
      view["normal_error_rad"] = v.ok ? json(v.normal_error_rad) : json();
      view["rival_normal_error_rad"] = v.has_rival ? json(v.rival_normal_error_rad) : json();
      view["normal_in_reference_cam"] = v.ok && !reference ? Vector3Json(v.normal_in_ref) : json();
      view["cam_from_reference"] =
          v.ok ? MotionJson(v.cam_from_ref.rotation, v.cam_from_ref.translation, "translation_plane_distances") : json();
      // The rival of a view the plane did not resolve: the other physical decomposition of its homography.
      view["rival"] = json();
      if (v.ok && v.has_rival && !v.resolved) {
        view["rival"] = MotionJson(v.rival_cam_from_ref.rotation, v.rival_cam_from_ref.translation,
                                   "translation_plane_distances");
        view["rival"]["normal_in_reference_cam"] = Vector3Json(v.rival_normal_in_ref);
      }
      views.push_back(view);
    }
    const Eigen::Vector3d& n = p.normal_in_ref;
    j["start"]["plane"] = {{"ok", p.ok},
                           {"message", p.message},
                           {"reference_pose", start.plane_reference},
                           {"normal_in_reference_cam", {n.x(), n.y(), n.z()}},
                           {"normal_rms_rad", p.normal_rms_rad},
                           {"fx_px", p.fx_px},
                           {"fx_estimated", p.fx_estimated},
                           {"views_ok", p.views_ok},
                           {"views_resolved", p.views_resolved},
                           {"views", views}};
  }
  if (start.ok) {
    const Eigen::Vector3d w = LogSO3(start.flange_from_cam.rotation);
    const Eigen::Vector3d& t = start.flange_from_cam.translation;
    j["start"]["flange_from_cam"] = {{"xyz_m", {t.x(), t.y(), t.z()}}, {"rotvec_rad", {w.x(), w.y(), w.z()}}};
  } else {
    j["start"]["flange_from_cam"] = json();
  }
  j["scale_yardsticks"] = report.flange_scale_yardsticks;
  j["image_motions"] = json();
  if (report.motion_check) {
    const calibration::MotionCheck& m = *report.motion_check;
    json pairs = json::array();
    for (const calibration::MotionPair& p : m.pairs) {
      pairs.push_back({{"pose_a", p.pose_a}, {"pose_b", p.pose_b}, {"flange_angle_rad", p.flange_angle_rad},
                       {"camera_angle_rad", p.camera_angle_rad}, {"error_rad", p.error_rad}});
    }
    json cameras = json::array();
    for (const calibration::ImageCameraPose& c : m.cameras) {
      const Eigen::Vector3d& t = c.base_from_cam_images.translation;
      const Eigen::Vector3d w = LogSO3(c.base_from_cam_images.rotation);
      cameras.push_back({{"pose", c.pose_id},
                         {"xyz_m", {t.x(), t.y(), t.z()}},
                         {"rotvec_rad", {w.x(), w.y(), w.z()}},
                         {"model_translation_error_m", c.translation_error_m},
                         {"model_rotation_error_rad", c.rotation_error_rad}});
    }
    j["image_motions"] = {{"description", kImageMotionsDescription},
                          {"ok", m.ok},
                          {"message", m.message},
                          {"images_rms_reprojection_px", m.images.rms_reprojection_px},
                          {"images_fx_px", m.images.intrinsics[kFx]},
                          {"median_error_rad", m.median_error_rad},
                          {"p90_error_rad", m.p90_error_rad},
                          {"max_error_rad", m.max_error_rad},
                          {"pairs_over_2deg", m.pairs_over_2deg},
                          {"pairs", pairs},
                          {"camera_poses_from_images", cameras}};
  }
  j["pose_noise"] = json();
  if (report.pose_noise) {
    const bundle::PoseNoiseReport& n = *report.pose_noise;
    j["pose_noise"] = {{"ok", n.ok},
                       {"message", n.message},
                       {"noise_source", report.pose_noise_estimated ? "estimated" : "stated"},
                       {"translation_sigma_m", report.pose_noise_translation_m},
                       {"rotation_sigma_rad", report.pose_noise_rotation_rad},
                       {"intrinsics", report.bundle ? IntrinsicsJson(n.intrinsics, report.bundle->bundle.intrinsics_estimated,
                                                                     n.intrinsics_stddev)
                                                    : json()},
                       {"rms_reprojection_px", n.rms_reprojection_px},
                       {"is_the_result", report.PoseNoiseIsTheResult()},
                       {"fx_px", n.intrinsics[kFx]},
                       {"variance_factor", Finite(n.variance_factor)},
                       {"pose_ids", n.pose_ids},
                       {"correction_translation_m", n.correction_translation_m},
                       {"correction_rotation_rad", n.correction_rotation_rad},
                       {"model_choice", ModelChoiceJson(report.model_choice)}};
  }
  return j;
}

// The calibrated camera transform of a flange-pose set, null without a model: flange_from_cam (eye-in-hand) or
// the fixed camera's base_from_cam (eye-to-hand), with the standard deviations of its correction.
json CalibratedCameraJson(const calibration::CalibrationReport& report, bool eye_to_hand) {
  if (!report.model) return json();
  const Rigid3& x = eye_to_hand ? report.model->robot.base_from_cam : report.model->robot.flange_from_cam;
  const Eigen::Vector3d w = LogSO3(x.rotation);
  json calibrated = {{"xyz_m", {x.translation.x(), x.translation.y(), x.translation.z()}},
                     {"rotvec_rad", {w.x(), w.y(), w.z()}}};
  json rows = json::array();
  for (int r = 0; r < 3; ++r) rows.push_back({x.rotation(r, 0), x.rotation(r, 1), x.rotation(r, 2)});
  calibrated["rotation"] = rows;
  calibrated["stddev"] = json();
  const Eigen::Matrix<double, 6, 1>& sd = eye_to_hand ? report.model->base_from_cam_stddev : report.model->flange_from_cam_stddev;
  if (sd.allFinite()) {
    calibrated["stddev"] = {{"xyz_m", {sd[0], sd[1], sd[2]}},
                            {"rotvec_rad", {sd[3], sd[4], sd[5]}},
                            {"frame", std::string("camera (of a correction ") +
                                          (eye_to_hand ? "base_from_cam" : "flange_from_cam") + " * Exp(delta))"}};
  }
  return calibrated;
}

}  // namespace

json CalibrationReportJson(const ObservationSet& obs, const calibration::CalibrationReport& report,
                           const ReportContext& context) {
  json methods = {{"paper", PaperSectionJson(obs, report.paper)}};
  if (report.bundle) methods["bundle"] = BundleSectionJson(obs, *report.bundle);
  if (report.paper_heldout) {
    methods["paper"]["heldout_models"] = {{"calibrated_model", HeldOutModelJson(report.paper_heldout->calibrated)},
                                          {"nominal_model", HeldOutModelJson(report.paper_heldout->nominal)}};
  }
  const json& chosen = methods[calibration::MethodName(report.method)];
  json j;
  j["format"] = kCalibrationReportFormat;
  j["version"] = kCalibrationReportVersion;
  j["software_version"] = SELFCAL_VERSION;
  j["input"] = {{"kind", context.input.kind}, {"path", context.input.path}, {"sha256", context.input.sha256},
                {"camera_file", json()}};
  if (!context.input.camera_file.empty()) {
    j["input"]["camera_file"] = {{"path", context.input.camera_file},
                                 {"sha256", context.input.camera_file_sha256},
                                 {"camera_name", context.input.camera_name}};
  }
  j["configuration"] = CameraMountName(obs.robot.mount);
  j["method"] = calibration::MethodName(report.method);
  j["verdict"] = calibration::VerdictName(report.verdict);
  j["accepted"] = report.accepted();
  j["message"] = report.message;
  j["reasons"] = report.acceptance.Reasons();
  json checks = json::array();
  for (const calibration::AcceptanceCheck& c : report.acceptance.checks) {
    checks.push_back({{"check", c.name}, {"status", calibration::CheckStatusName(c.status)}, {"decisive", c.decisive},
                      {"sentence", c.sentence}});
  }
  j["acceptance"] = checks;
  j["exit_code"] = context.exit_code;
  j["pixel_noise_px"] = obs.pixel_noise_px;
  j["pixel_noise_note"] = "standard deviation per coordinate (the paper's N(0, s) read as a std)";
  // The chosen method's figures, so that a script reading the top level reads the product's answer.
  // A refusal before the chosen method ran (e.g. bad options for a flange-pose set) has no section.
  auto field = [&chosen](const char* key) { return chosen.is_object() && chosen.contains(key) ? chosen[key] : json(); };
  j["fx_px"] = field("fx_px");
  j["verification"] = field("verification");
  j["predicted_3d_error"] = field("predicted_3d_error");
  j["heldout_reprojection"] = field("heldout_reprojection");
  if (report.PoseNoiseIsTheResult() && report.bundle) {
    // The pose-noise solve is the model written: the top level, the held-out test and the plots are its.
    j["fx_px"] = report.pose_noise->intrinsics[kFx];
    if (report.pose_noise_heldout) {
      j["heldout_reprojection"] = HeldOutJson(obs, *report.pose_noise_heldout, report.pose_noise_heldout->overall,
                                              report.bundle->heldout_nominal);
    }
    methods["bundle"]["plot_data"] = PoseNoisePlotDataJson(obs, report);
  }
  j["cross_validation"] = report.cross_validation ? CrossValidationJson(*report.cross_validation) : json();
  j["scene_moves"] = SceneMovesJson(report);
  j["scene_split"] = SceneSplitJson(report);
  j["methods"] = methods;
  j["session"] = context.session ? SessionJson(context.input, *context.session) : json();
  if (report.hand_eye_start) {
    const bool eye_to_hand = obs.robot.mount == CameraMount::kEyeToHand;
    j["hand_eye"] = HandEyeJson(report);
    j["hand_eye"][eye_to_hand ? "base_from_cam" : "flange_from_cam"] = CalibratedCameraJson(report, eye_to_hand);
  }
  // Timing in one place, so that two reports of the same input compare equal without it.
  const calibration::PaperPipelineReport& p = report.paper;
  const calibration::BundleStageReport* b = report.bundle ? &*report.bundle : nullptr;
  auto bundle_seconds = [b](double calibration::BundleStageReport::*field) { return b ? json(b->*field) : json(); };
  j["timing"] = {{"paper_two_view_s", p.seconds_two_view},
                 {"paper_identification_s", p.seconds_identification},
                 {"paper_total_s", p.seconds_total},
                 {"bundle_s", b ? json(b->bundle.seconds) : json()},
                 {"bundle_verification_s", bundle_seconds(&calibration::BundleStageReport::seconds_verification)},
                 {"bundle_heldout_s", bundle_seconds(&calibration::BundleStageReport::seconds_heldout)},
                 {"bundle_fit_geometry_s", bundle_seconds(&calibration::BundleStageReport::seconds_fit_geometry)},
                 {"bundle_predicted_error_s", bundle_seconds(&calibration::BundleStageReport::seconds_predicted_error)},
                 {"bundle_stage_total_s", bundle_seconds(&calibration::BundleStageReport::seconds_total)},
                 {"acceptance_s", report.seconds_acceptance},
                 {"total_s", report.seconds_total}};
  return j;
}

}  // namespace selfcal::report
