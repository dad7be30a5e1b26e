#include "app/report_format.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iomanip>

namespace selfcal::app {

namespace {

constexpr double kMm = 1e3;

nlohmann::json Finite(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); }

nlohmann::json VerificationJson(const pipeline::VerificationSummary& v) {
  nlohmann::json checks = nlohmann::json::array();
  for (const pipeline::DistanceCheck& c : v.checks) {
    checks.push_back({{"dot_a", c.known.dot_a}, {"dot_b", c.known.dot_b}, {"known_mm", c.known.length_m * kMm},
                      {"ok", c.ok}, {"measured_mm", c.measured_m * kMm}, {"error_mm", c.error_m * kMm}});
  }
  return {{"num_ok", v.num_ok}, {"mean_error_mm", v.mean_error_m * kMm}, {"rms_error_mm", v.rms_error_m * kMm},
          {"max_error_mm", v.max_error_m * kMm}, {"checks", checks}};
}

// A parameter value in report units: mm for lengths, degrees for angles.
double InReportUnits(const KinematicParameters& params, int i, double v) {
  return params.kind(i) == ParameterKind::kLength ? v * kMm : RadToDeg(v);
}

nlohmann::json StatJson(const pipeline::Stat& s) {
  return {{"n", s.count()}, {"mean", Finite(s.Mean())}, {"sd", Finite(s.Sd())}, {"rms", Finite(s.Rms())},
          {"p90", Finite(s.Percentile(90))}, {"max", Finite(s.Max())}};
}

// A failure message cut for a table line (the JSON keeps it whole).
std::string Shortened(const std::string& message) {
  return message.size() <= 160 ? message : message.substr(0, 157) + "...";
}

double Ratio(double a, double b) { return std::isfinite(a) && std::isfinite(b) && b > 0 ? a / b : NAN; }

// Per free parameter: RMS error against the truth, RMS Cramer-Rao std, and their ratio (units in the key).
nlohmann::json BundleParametersJson(const pipeline::StudyCell& c) {
  nlohmann::json rows = nlohmann::json::array();
  for (const auto& [name, error] : c.bundle_parameter_error) {
    auto bound = c.bundle_parameter_bound.find(name);
    const double b = bound == c.bundle_parameter_bound.end() ? NAN : bound->second.Rms();
    rows.push_back({{"name", name}, {"n", error.count()}, {"rms_error", Finite(error.Rms())},
                    {"rms_bound", Finite(b)}, {"ratio", Finite(Ratio(error.Rms(), b))}});
  }
  return rows;
}

// min, mean and max of the per-parameter RMS error / RMS bound, with the extreme parameters' names.
struct RatioSummary {
  int n = 0;
  double min = NAN, mean = NAN, max = NAN;
  std::string min_name, max_name;
};
RatioSummary SummarizeParameterRatios(const pipeline::StudyCell& c) {
  RatioSummary r;
  double sum = 0;
  for (const auto& [name, error] : c.bundle_parameter_error) {
    auto bound = c.bundle_parameter_bound.find(name);
    if (bound == c.bundle_parameter_bound.end()) continue;
    const double ratio = Ratio(error.Rms(), bound->second.Rms());
    if (!std::isfinite(ratio)) continue;
    if (r.n == 0 || ratio < r.min) r.min = ratio, r.min_name = name;
    if (r.n == 0 || ratio > r.max) r.max = ratio, r.max_name = name;
    sum += ratio;
    ++r.n;
  }
  if (r.n > 0) r.mean = sum / r.n;
  return r;
}

nlohmann::json BundleCellJson(const pipeline::StudyCell& c) {
  return {{"runs", c.bundle_runs},
          {"runs_failed", c.bundle_runs_failed},
          {"failures", c.bundle_failures},
          {"relative_pose_identification", {{"position_mm", StatJson(c.bundle_position_mm)},
                                            {"orientation_1e4rad", StatJson(c.bundle_orientation_1e4rad)},
                                            {"fx_px", StatJson(c.bundle_fx_px)}}},
          {"cramer_rao", {{"position_mm_rms", StatJson(c.bundle_bound_position_mm)},
                          {"orientation_1e4rad_rms", StatJson(c.bundle_bound_orientation_1e4rad)},
                          {"fx_px_rms", StatJson(c.bundle_bound_fx_px)},
                          {"verification_position_mm_rms", StatJson(c.bundle_bound_pose_position_mm)},
                          {"verification_orientation_1e4rad_rms", StatJson(c.bundle_bound_pose_orientation_1e4rad)}}},
          {"rms_over_bound", {{"position", Finite(Ratio(c.bundle_position_mm.Rms(), c.bundle_bound_position_mm.Rms()))},
                              {"orientation", Finite(Ratio(c.bundle_orientation_1e4rad.Rms(), c.bundle_bound_orientation_1e4rad.Rms()))},
                              {"fx", Finite(Ratio(c.bundle_fx_px.Rms(), c.bundle_bound_fx_px.Rms()))}}},
          {"fig6_3d_error_mm", StatJson(c.bundle_error3d_mm)},
          {"predicted_3d_error_mm",
           {{"description", "std of the 3-D error of each check distance predicted to first order (pipeline/"
                            "predicted_error.h), pooled over runs; compare actual_rms with the rms entries"},
            {"actual_rms", Finite(c.bundle_error3d_mm.Rms())},
            {"predicted", StatJson(c.bundle_predicted3d_mm)},
            {"predicted_parameters_part", StatJson(c.bundle_predicted3d_parameters_mm)},
            {"predicted_pixels_part", StatJson(c.bundle_predicted3d_pixels_mm)},
            {"bound", StatJson(c.bundle_bound3d_mm)},
            {"bound_parameters_part", StatJson(c.bundle_bound3d_parameters_mm)},
            {"actual_over_predicted", Finite(Ratio(c.bundle_error3d_mm.Rms(), c.bundle_predicted3d_mm.Rms()))},
            {"actual_over_bound", Finite(Ratio(c.bundle_error3d_mm.Rms(), c.bundle_bound3d_mm.Rms()))}}},
          {"verification_pose_error", {{"position_mm", StatJson(c.bundle_pose_position_mm)},
                                       {"orientation_1e4rad", StatJson(c.bundle_pose_orientation_1e4rad)}}},
          {"coverage_2sigma", {{"intervals", c.bundle_intervals},
                               {"covered", c.bundle_covered},
                               {"fraction", Finite(c.BundleCoverage())}}},
          {"parameters_rms_error_over_bound", BundleParametersJson(c)},
          {"seconds_per_solve", StatJson(c.bundle_seconds)}};
}

}  // namespace

nlohmann::json CalibrationReportJson(const ObservationSet& obs, const pipeline::PaperPipelineReport& r) {
  nlohmann::json j;
  j["format"] = "selfcal-calibration-report";
  j["version"] = 1;
  j["software_version"] = SELFCAL_VERSION;
  j["method"] = "paper pipeline (Meng & Zhuang 2001): factor method, eq. (21) scale, LM identification, yardstick";
  j["outcome"] = pipeline::OutcomeName(r.outcome);
  j["message"] = r.message;
  j["reference_pose"] = r.reference_pose >= 0 ? obs.poses[r.reference_pose].id : "";
  j["fx_px"] = r.fx_px;
  j["fx_pairs"] = r.fx_pairs;
  j["pixel_noise_px"] = obs.pixel_noise_px;
  j["pixel_noise_note"] = "standard deviation per coordinate (the paper's N(0, s) read as a std)";

  nlohmann::json measurements = nlohmann::json::array();
  for (const pipeline::PoseMeasurement& m : r.measurements) {
    measurements.push_back({{"pose", m.pose_id},
                            {"outcome", twoview::OutcomeName(m.two_view.outcome)},
                            {"message", m.two_view.message},
                            {"used", m.used},
                            {"fx_px", m.two_view.fx_px},
                            {"fx_observable", m.two_view.fx_observable},
                            {"planar", m.two_view.planar},
                            {"inliers", m.two_view.num_inliers},
                            {"rms_epipolar_px", m.two_view.rms_epipolar_px},
                            {"eq21_scale_mm", m.scale * kMm},
                            {"fx_from_other_pairs", m.fx_from_other_pairs},
                            {"far_point_fraction", m.two_view.far_point_fraction},
                            {"warnings", m.two_view.warnings},
                            {"refinement", m.two_view.refinement_termination}});
  }
  j["pose_measurements"] = measurements;

  const identification::IdentifiabilityReport& id = r.identifiability;
  j["identifiability"] = {{"num_parameters", id.num_parameters}, {"identifiable", id.rank},
                          {"free", id.free_names},           {"fixed", id.fixed_names},
                          {"null_combinations", id.null_combinations},
                          {"condition_number", Finite(id.condition_number)}};

  const identification::IdentificationReport& ident = r.identification;
  nlohmann::json parameters = nlohmann::json::array();
  if (ident.rho.size() == obs.robot.num_parameters()) {
    const KinematicParameters params(obs.robot.num_joints());
    const Eigen::VectorXd nominal = KinematicParameters::Nominal(obs.robot);
    for (int i = 0; i < params.size(); ++i) {
      const bool free = std::count(ident.free_indices.begin(), ident.free_indices.end(), i) > 0;
      const char* unit = params.kind(i) == ParameterKind::kLength ? "mm" : "deg";
      parameters.push_back({{"name", params.name(i)},
                            {"unit", unit},
                            {"free", free},
                            {"nominal", InReportUnits(params, i, nominal[i])},
                            {"identified_before_yardstick", InReportUnits(params, i, ident.rho[i])},
                            {"stddev", Finite(ident.stddev.size() > i ? InReportUnits(params, i, ident.stddev[i]) : NAN)}});
    }
  }
  j["identification"] = {{"outcome", identification::OutcomeName(ident.outcome)},
                         {"message", ident.message},
                         {"termination", ident.termination},
                         {"iterations", ident.iterations},
                         {"initial_cost", ident.initial_cost},
                         {"final_cost", ident.final_cost},
                         {"rms_position_mm", ident.rms_position_m * kMm},
                         {"rms_rotation_deg", RadToDeg(ident.rms_rotation_rad)},
                         {"covariance_available", ident.covariance_available},
                         {"covariance_message", ident.covariance_message},
                         {"parameters", parameters}};
  nlohmann::json lengths = nlohmann::json::array();
  for (double l : r.yardstick.measured_lengths_m) lengths.push_back(l * kMm);
  j["yardstick"] = {{"ok", r.yardstick.ok},
                    {"message", r.yardstick.message},
                    {"scale", r.yardstick.scale},
                    {"scale_sigma", r.yardstick.scale_sigma},
                    {"measured_lengths_before_scale_mm", lengths}};
  j["verification"] = {{"poses", obs.PosesWithRole(PoseRole::kVerification).size()},
                       {"nominal_model", VerificationJson(r.verification_nominal)},
                       {"calibrated_model", VerificationJson(r.verification_calibrated)}};
  j["timing_s"] = {{"two_view", r.seconds_two_view}, {"identification", r.seconds_identification},
                   {"total", r.seconds_total}};
  return j;
}

void PrintCalibrationSummary(const pipeline::PaperPipelineReport& r, std::ostream& out) {
  out << "outcome: " << pipeline::OutcomeName(r.outcome);
  if (!r.message.empty()) out << " (" << r.message << ")";
  out << "\n";
  int used = 0;
  for (const auto& m : r.measurements) used += m.used ? 1 : 0;
  out << "pose measurements: " << used << " of " << r.measurements.size() << " pairs used; f_x = " << std::fixed
      << std::setprecision(3) << r.fx_px << " px from " << r.fx_pairs << " pairs\n";
  out << "identifiable parameters: " << r.identifiability.rank << " of " << r.identifiability.num_parameters
      << " (condition number " << std::setprecision(1) << r.identifiability.condition_number << ")\n";
  out << "identification: " << identification::OutcomeName(r.identification.outcome) << ", "
      << r.identification.iterations << " iterations, residual RMS " << std::setprecision(3)
      << r.identification.rms_position_m * kMm << " mm / " << RadToDeg(r.identification.rms_rotation_rad) << " deg\n";
  if (r.yardstick.ok) {
    out << "yardstick scale: " << std::setprecision(6) << r.yardstick.scale << " +- " << r.yardstick.scale_sigma << "\n";
  } else {
    out << "yardstick: " << r.yardstick.message << "\n";
  }
  if (r.verification_calibrated.num_ok > 0) {
    out << "3-D error on " << r.verification_calibrated.num_ok << " held-out distances: nominal model "
        << std::setprecision(3) << r.verification_nominal.rms_error_m * kMm << " mm RMS, calibrated "
        << r.verification_calibrated.rms_error_m * kMm << " mm RMS (max " << r.verification_calibrated.max_error_m * kMm
        << " mm)\n";
  }
  out << "time: " << std::setprecision(1) << r.seconds_total * 1e3 << " ms\n";
  out.unsetf(std::ios::floatfield);
}

namespace {

nlohmann::json PredictedErrorJson(const pipeline::PredictedDistanceErrors& p) {
  nlohmann::json distances = nlohmann::json::array();
  for (const pipeline::PredictedDistanceError& e : p.distances) {
    distances.push_back({{"dot_a", e.known.dot_a}, {"dot_b", e.known.dot_b}, {"ok", e.ok},
                         {"std_mm", e.std_m * kMm}, {"parameters_std_mm", e.parameters_std_m * kMm},
                         {"pixels_std_mm", e.pixels_std_m * kMm}});
  }
  return {{"description", "predicted std of the 3-D error of each check distance: the bundle's covariance of the free "
                          "parameters and f_x (parameters part) and the stated pixel noise of the verification images "
                          "(pixels part), propagated through the triangulation to first order"},
          {"ok", p.ok},
          {"message", p.message},
          {"num_ok", p.num_ok},
          {"rms_mm", p.rms_std_m * kMm},
          {"rms_parameters_mm", p.rms_parameters_std_m * kMm},
          {"rms_pixels_mm", p.rms_pixels_std_m * kMm},
          {"distances", distances}};
}

}  // namespace

nlohmann::json BundleReportJson(const ObservationSet& obs, const pipeline::BundleStageReport& stage) {
  const bundle::BundleReport& b = stage.bundle;
  nlohmann::json removed = nlohmann::json::array();
  for (const bundle::RemovedObservation& o : b.removed) {
    removed.push_back({{"pose", o.pose_id}, {"dot", o.dot_id}, {"residual_px", o.residual_px}});
  }
  nlohmann::json parameters = nlohmann::json::array();
  if (b.rho.size() == obs.robot.num_parameters()) {
    const KinematicParameters params(obs.robot.num_joints());
    const Eigen::VectorXd nominal = KinematicParameters::Nominal(obs.robot);
    for (int i = 0; i < params.size(); ++i) {
      const bool free = std::count(b.free_indices.begin(), b.free_indices.end(), i) > 0;
      const std::string unit = params.kind(i) == ParameterKind::kLength ? "_mm" : "_deg";
      const double sd = b.stddev.size() > i ? b.stddev[i] : NAN;
      parameters.push_back({{"name", params.name(i)},
                            {"free", free},
                            {"nominal" + unit, InReportUnits(params, i, nominal[i])},
                            {"value" + unit, InReportUnits(params, i, b.rho[i])},
                            {"correction" + unit, InReportUnits(params, i, b.rho[i] - nominal[i])},
                            {"stddev" + unit, Finite(InReportUnits(params, i, sd))}});
    }
  }
  return {{"description", "kinematic bundle adjustment (DESIGN.md section 5): reprojection of every dot in every "
                          "identification image over the free kinematic parameters, hand-eye, f_x and the dots; "
                          "yardstick as a length constraint"},
          {"outcome", bundle::OutcomeName(b.outcome)},
          {"message", b.message},
          {"start", pipeline::BundleStartName(stage.start)},
          {"start_note", stage.start_note},
          {"fx_start_px", stage.fx_start_px},
          {"termination", b.termination},
          {"iterations", b.iterations},
          {"initial_cost", b.initial_cost},
          {"final_cost", b.final_cost},
          {"num_observations", b.num_observations},
          {"rms_reprojection_px", b.rms_reprojection_px},
          {"removed_observations", removed},
          {"dropped_dots", b.dropped_dots},
          {"free", b.free_names},
          {"fixed", b.fixed_names},
          {"null_combinations", b.null_combinations},
          {"generic_rank", b.generic_rank},
          {"condition_number", Finite(b.condition_number)},
          {"covariance_available", b.covariance_available},
          {"covariance_message", b.covariance_message},
          {"parameters", parameters},
          {"fx_px", b.fx_px},
          {"fx_stddev_px", Finite(b.fx_stddev)},
          {"k1", b.k1},
          {"k1_stddev", Finite(b.k1_stddev)},
          {"verification", {{"poses", obs.PosesWithRole(PoseRole::kVerification).size()},
                            {"nominal_model", VerificationJson(stage.verification_nominal)},
                            {"calibrated_model", VerificationJson(stage.verification)}}},
          {"predicted_3d_error_mm", PredictedErrorJson(stage.predicted_error)}};
}

void PrintBundleSummary(const pipeline::BundleStageReport& stage, std::ostream& out) {
  const bundle::BundleReport& b = stage.bundle;
  out << "kinematic bundle adjustment: " << bundle::OutcomeName(b.outcome);
  if (!b.message.empty()) out << " (" << b.message << ")";
  out << "\n  start: " << stage.start_note << "\n";
  if (b.rho.size() == 0) return;
  out << "  " << b.free_names.size() << " free kinematic parameters + f_x, " << b.fixed_names.size()
      << " fixed; " << b.num_observations << " observations, " << b.removed.size() << " removed by the screen, "
      << b.dropped_dots.size() << " dots dropped\n";
  out << "  " << b.iterations << " iterations (" << b.termination << "), reprojection RMS " << std::setprecision(4)
      << b.rms_reprojection_px << " px; f_x = " << std::fixed << std::setprecision(3) << b.fx_px << " +- "
      << b.fx_stddev << " px\n";
  out.unsetf(std::ios::floatfield);
  if (stage.verification.num_ok > 0) {
    out << "  3-D error on " << stage.verification.num_ok << " held-out distances: nominal model " << std::fixed
        << std::setprecision(3) << stage.verification_nominal.rms_error_m * kMm << " mm RMS, bundle "
        << stage.verification.rms_error_m * kMm << " mm RMS (max " << stage.verification.max_error_m * kMm << " mm)\n";
  }
  if (stage.predicted_error.ok) {
    out << "  predicted 3-D error (first order): " << std::fixed << std::setprecision(3) << stage.predicted_error.rms_std_m * kMm
        << " mm RMS (calibrated parameters " << stage.predicted_error.rms_parameters_std_m * kMm
        << " mm, verification pixels " << stage.predicted_error.rms_pixels_std_m * kMm << " mm)\n";
    out.unsetf(std::ios::floatfield);
  }
  out << "  time: " << std::fixed << std::setprecision(1) << b.seconds * 1e3 << " ms\n";
  out.unsetf(std::ios::floatfield);
}

nlohmann::json StudyJson(const pipeline::StudyReport& study, const pipeline::StudyOptions& options) {
  nlohmann::json j;
  j["format"] = "selfcal-study";
  j["version"] = 1;
  j["software_version"] = SELFCAL_VERSION;
  j["runs_per_cell"] = options.runs;
  j["seed"] = options.seed;
  j["pixel_noise_note"] = "std per coordinate in px (the paper's N(0, s) read as a std)";
  j["hidden_errors"] = {{"length_std_mm", options.sim.length_error_std_m * kMm},
                        {"angle_std_deg", RadToDeg(options.sim.angle_error_std_rad)},
                        {"cam_length_std_mm", options.sim.cam_length_error_std_m * kMm},
                        {"cam_angle_std_deg", RadToDeg(options.sim.cam_angle_error_std_rad)},
                        {"fx_relative_std", options.sim.fx_relative_error_std}};
  j["identifiable_parameters"] = study.identifiable_parameters;
  j["fixed_parameters"] = study.fixed_parameters;
  j["flat_sheet"] = study.flat_sheet;
  j["bundle_free_parameters"] = study.bundle_free_parameters;
  j["bundle_fixed_parameters"] = study.bundle_fixed_parameters;
  j["paper_table2"] = {
      {{"trajectory", "initial"}, {"noise_px", 0.2}, {"position_mm", {3.0427, 1.1051}}, {"orientation_1e4rad", {1.4918, 2.5354}}, {"fx_px", {0.2249, 0.2374}}},
      {{"trajectory", "optimal"}, {"noise_px", 0.2}, {"position_mm", {0.2809, 0.2452}}, {"orientation_1e4rad", {1.0701, 1.4532}}, {"fx_px", {0.1539, 0.2128}}},
      {{"trajectory", "initial"}, {"noise_px", 0.5}, {"position_mm", {6.9837, 2.6475}}, {"orientation_1e4rad", {4.0876, 7.1762}}, {"fx_px", {0.6181, 0.7324}}},
      {{"trajectory", "optimal"}, {"noise_px", 0.5}, {"position_mm", {0.3035, 0.2826}}, {"orientation_1e4rad", {2.4016, 3.2432}}, {"fx_px", {0.3458, 0.4791}}}};
  nlohmann::json cells = nlohmann::json::array();
  for (const pipeline::StudyCell& c : study.cells) {
    nlohmann::json centroids = nullptr;
    if (c.rendered) {
      centroids = {{"expected", c.centroids.expected}, {"detected", c.centroids.detected},
                   {"matched", c.centroids.matched}, {"missed", c.centroids.missed},
                   {"spurious", c.centroids.spurious},
                   {"rms_vs_area_centroid_px", pipeline::CentroidErrors::Rms(c.centroids.vs_area_centroid_px)},
                   {"rms_vs_projected_px", pipeline::CentroidErrors::Rms(c.centroids.vs_projected_px)},
                   {"rms_ellipse_bias_px", pipeline::CentroidErrors::Rms(c.centroids.ellipse_bias_px)}};
    }
    cells.push_back({{"trajectory", c.trajectory},
                     {"noise_px", c.noise_px},
                     {"rendered", c.rendered},
                     {"centroids", centroids},
                     {"runs", c.runs},
                     {"runs_failed", c.runs_failed},
                     {"failures", c.failures},
                     {"paper_pipeline", {{"position_mm", StatJson(c.position_mm)},
                                         {"position_true_scale_mm", StatJson(c.position_true_scale_mm)},
                                         {"orientation_1e4rad", StatJson(c.orientation_1e4rad)},
                                         {"fx_px", StatJson(c.fx_px)},
                                         {"eq21_ratio_error", StatJson(c.scale_ratio_error)}}},
                     {"opencv_true_fx", {{"position_mm", StatJson(c.opencv_position_mm)},
                                         {"position_true_scale_mm", StatJson(c.opencv_position_true_scale_mm)},
                                         {"orientation_1e4rad", StatJson(c.opencv_orientation_1e4rad)}}},
                     {"cramer_rao_fx_unknown", {{"position_mm_rms", StatJson(c.bound_position_mm_fx_unknown)},
                                                {"orientation_1e4rad_rms", StatJson(c.bound_orientation_1e4rad_fx_unknown)},
                                                {"fx_px_rms", StatJson(c.bound_fx_px)}}},
                     {"cramer_rao_fx_known", {{"position_mm_rms", StatJson(c.bound_position_mm_fx_known)},
                                              {"orientation_1e4rad_rms", StatJson(c.bound_orientation_1e4rad_fx_known)}}},
                     {"fig6_3d_error_mm", {{"nominal_model", StatJson(c.error3d_nominal_mm)},
                                           {"calibrated", StatJson(c.error3d_calibrated_mm)}}},
                     {"verification_pose_error", {{"position_nominal_mm", StatJson(c.pose_position_nominal_mm)},
                                                  {"position_calibrated_mm", StatJson(c.pose_position_calibrated_mm)},
                                                  {"orientation_nominal_1e4rad", StatJson(c.pose_orientation_nominal_1e4rad)},
                                                  {"orientation_calibrated_1e4rad", StatJson(c.pose_orientation_calibrated_1e4rad)}}},
                     {"fx_final_error_px", StatJson(c.fx_final_error_px)},
                     {"yardstick_scale_error", StatJson(c.yardstick_scale_error)},
                     {"seconds_per_calibration", StatJson(c.seconds_per_calibration)},
                     {"kinematic_bundle", BundleCellJson(c)}});
  }
  j["cells"] = cells;
  j["seconds_total"] = study.seconds_total;
  return j;
}

void PrintStudyTables(const pipeline::StudyReport& study, std::ostream& out) {
  char line[512];
  if (study.flat_sheet) {
    out << "FLAT DOT SHEET: every dot on one plane. The paper's factor method is degenerate there: the paper\n"
           "pipeline rows below count only the runs it completed ('runs' column; failures listed at the end),\n"
           "nan where it completed none. The kinematic bundle adjustment starts from the nominal model then.\n\n";
  }
  out << "Table 2 reproduction: pose measurement errors, mean / SD over pose pairs and runs\n";
  out << "(position with the eq. (21) scale and k_1 from the true first motion; bound rows are RMS)\n";
  bool any_rendered = false;
  for (const pipeline::StudyCell& c : study.cells) any_rendered = any_rendered || c.rendered;
  if (any_rendered) {
    out << "Centroids on rendered images (detector vs truth, per coordinate, pooled over poses and runs; rows\n"
           "'<trajectory>/<level>' below use these pixels, their noise column is the noise the solvers are told)\n";
    std::snprintf(line, sizeof(line), "%-22s %9s %7s %8s %12s %12s %12s %12s\n", "trajectory/level", "dots", "missed",
                  "spurious", "RMS vs area", "RMS vs proj", "max vs proj", "ellipse bias");
    out << line;
    for (const pipeline::StudyCell& c : study.cells) {
      if (!c.rendered) continue;
      double worst = 0;
      for (double e : c.centroids.vs_projected_px) worst = std::max(worst, std::abs(e));
      std::snprintf(line, sizeof(line), "%-22s %9d %7d %8d %9.4f px %9.4f px %9.4f px %9.4f px\n", c.trajectory.c_str(),
                    c.centroids.expected, c.centroids.missed, c.centroids.spurious,
                    pipeline::CentroidErrors::Rms(c.centroids.vs_area_centroid_px),
                    pipeline::CentroidErrors::Rms(c.centroids.vs_projected_px), worst,
                    pipeline::CentroidErrors::Rms(c.centroids.ellipse_bias_px));
      out << line;
    }
    out << "\n";
  }
  std::snprintf(line, sizeof(line), "%-10s %-6s %-28s %9s %9s %10s %10s %8s %8s %6s\n", "trajectory", "noise",
                "method", "pos M mm", "pos SD", "ori M e-4", "ori SD", "fx M px", "fx SD", "runs");
  out << line;
  auto row = [&](const pipeline::StudyCell& c, const char* method, const pipeline::Stat& p, const pipeline::Stat& o,
                 const pipeline::Stat* f, bool rms) {
    std::snprintf(line, sizeof(line), "%-10s %-6.2f %-28s %9.4f %9.4f %10.4f %10.4f %8.4f %8.4f %6d\n",
                  c.trajectory.c_str(), c.noise_px, method, rms ? p.Rms() : p.Mean(), rms ? NAN : p.Sd(),
                  rms ? o.Rms() : o.Mean(), rms ? NAN : o.Sd(), f ? (rms ? f->Rms() : f->Mean()) : NAN,
                  f && !rms ? f->Sd() : NAN, c.runs - c.runs_failed);
    out << line;
  };
  for (const pipeline::StudyCell& c : study.cells) {
    row(c, "paper pipeline", c.position_mm, c.orientation_1e4rad, &c.fx_px, false);
    row(c, "paper pipeline, true scale", c.position_true_scale_mm, c.orientation_1e4rad, nullptr, false);
    if (c.opencv_position_mm.count() > 0) {
      row(c, "OpenCV E+recoverPose true fx", c.opencv_position_mm, c.opencv_orientation_1e4rad, nullptr, false);
    }
    if (c.bound_position_mm_fx_unknown.count() > 0) {
      row(c, "CRB fx unknown (RMS)", c.bound_position_mm_fx_unknown, c.bound_orientation_1e4rad_fx_unknown,
          &c.bound_fx_px, true);
      row(c, "CRB fx known (RMS)", c.bound_position_mm_fx_known, c.bound_orientation_1e4rad_fx_known, nullptr, true);
    }
  }
  out << "\nFig. 6 and 'does calibration help?': verification poses, nominal model vs calibrated\n";
  std::snprintf(line, sizeof(line), "%-10s %-6s %14s %14s %14s %14s %14s %14s\n", "trajectory", "noise",
                "3-D nom mm", "3-D cal mm", "3-D cal p90", "pose nom mm", "pose cal mm", "ori cal e-4");
  out << line;
  for (const pipeline::StudyCell& c : study.cells) {
    std::snprintf(line, sizeof(line), "%-10s %-6.2f %14.4f %14.4f %14.4f %14.4f %14.4f %14.4f\n", c.trajectory.c_str(),
                  c.noise_px, c.error3d_nominal_mm.Mean(), c.error3d_calibrated_mm.Mean(),
                  c.error3d_calibrated_mm.Percentile(90), c.pose_position_nominal_mm.Mean(),
                  c.pose_position_calibrated_mm.Mean(), c.pose_orientation_calibrated_1e4rad.Mean());
    out << line;
  }
  const bool any_bundle = std::any_of(study.cells.begin(), study.cells.end(),
                                      [](const pipeline::StudyCell& c) { return c.bundle_runs > 0; });
  if (any_bundle) {
    out << "\nBeyond the paper: kinematic bundle adjustment (BA), same runs. Relative poses reference -> identification\n"
           "pose i predicted by the BA model vs truth (the poses of the Table 2 rows), mean / SD; CRB rows: the BA's own\n"
           "Cramer-Rao bound at the truth, RMS; 'runs' = converged BA runs\n";
    std::snprintf(line, sizeof(line), "%-10s %-6s %-28s %9s %9s %10s %10s %8s %8s %6s\n", "trajectory", "noise",
                  "method", "pos M mm", "pos SD", "ori M e-4", "ori SD", "fx M px", "fx SD", "runs");
    out << line;
    for (const pipeline::StudyCell& c : study.cells) {
      if (c.bundle_runs == 0) continue;
      const int ok = c.bundle_runs - c.bundle_runs_failed;
      std::snprintf(line, sizeof(line), "%-10s %-6.2f %-28s %9.4f %9.4f %10.4f %10.4f %8.4f %8.4f %6d\n",
                    c.trajectory.c_str(), c.noise_px, "kinematic BA", c.bundle_position_mm.Mean(),
                    c.bundle_position_mm.Sd(), c.bundle_orientation_1e4rad.Mean(), c.bundle_orientation_1e4rad.Sd(),
                    c.bundle_fx_px.Mean(), c.bundle_fx_px.Sd(), ok);
      out << line;
      if (c.bundle_bound_position_mm.count() > 0) {
        std::snprintf(line, sizeof(line), "%-10s %-6.2f %-28s %9.4f %9s %10.4f %10s %8.4f %8s %6d\n",
                      c.trajectory.c_str(), c.noise_px, "BA CRB (RMS)", c.bundle_bound_position_mm.Rms(), "",
                      c.bundle_bound_orientation_1e4rad.Rms(), "", c.bundle_bound_fx_px.Rms(), "", ok);
        out << line;
      }
    }
    out << "\nBA against its bound: RMS error / RMS bound; coverage: free parameters and f_x whose truth lies within\n"
           "+-2 reported sigma (pooled over runs)\n";
    std::snprintf(line, sizeof(line), "%-10s %-6s %10s %10s %7s %10s %10s %7s %9s %9s %7s %9s %9s\n", "trajectory",
                  "noise", "pos RMS mm", "CRB mm", "ratio", "ori RMS e-4", "CRB e-4", "ratio", "fx RMS px", "CRB px",
                  "ratio", "cover 2s", "ms/solve");
    out << line;
    for (const pipeline::StudyCell& c : study.cells) {
      if (c.bundle_runs == 0) continue;
      const double p = c.bundle_position_mm.Rms(), pb = c.bundle_bound_position_mm.Rms();
      const double o = c.bundle_orientation_1e4rad.Rms(), ob = c.bundle_bound_orientation_1e4rad.Rms();
      const double f = c.bundle_fx_px.Rms(), fb = c.bundle_bound_fx_px.Rms();
      std::snprintf(line, sizeof(line), "%-10s %-6.2f %10.4f %10.4f %7.3f %10.4f %10.4f %7.3f %9.4f %9.4f %7.3f %8.1f%% %9.1f\n",
                    c.trajectory.c_str(), c.noise_px, p, pb, Ratio(p, pb), o, ob, Ratio(o, ob), f, fb, Ratio(f, fb),
                    100 * c.BundleCoverage(), 1e3 * c.bundle_seconds.Mean());
      out << line;
    }
    for (const pipeline::StudyCell& c : study.cells) {
      const RatioSummary r = SummarizeParameterRatios(c);
      if (r.n == 0) continue;
      std::snprintf(line, sizeof(line),
                    "%-10s %-6.2f per-parameter RMS error / Cramer-Rao std, %d free parameters: mean %.3f, min %.3f "
                    "(%s), max %.3f (%s)\n",
                    c.trajectory.c_str(), c.noise_px, r.n, r.mean, r.min, r.min_name.c_str(), r.max, r.max_name.c_str());
      out << line;
    }
    out << "\nFig. 6 with the BA model: verification poses (paper pipeline's calibrated model beside it)\n";
    std::snprintf(line, sizeof(line), "%-10s %-6s %14s %14s %14s %14s %14s %14s %14s\n", "trajectory", "noise",
                  "3-D paper mm", "3-D BA mm", "3-D BA p90", "pose paper mm", "pose BA mm", "pose CRB mm", "ori BA e-4");
    out << line;
    for (const pipeline::StudyCell& c : study.cells) {
      if (c.bundle_runs == 0) continue;
      std::snprintf(line, sizeof(line), "%-10s %-6.2f %14.4f %14.4f %14.4f %14.4f %14.4f %14.4f %14.4f\n",
                    c.trajectory.c_str(), c.noise_px, c.error3d_calibrated_mm.Mean(), c.bundle_error3d_mm.Mean(),
                    c.bundle_error3d_mm.Percentile(90), c.pose_position_calibrated_mm.Mean(),
                    c.bundle_pose_position_mm.Mean(), c.bundle_bound_pose_position_mm.Rms(),
                    c.bundle_pose_orientation_1e4rad.Mean());
      out << line;
    }
  }
  if (any_bundle) {
    out << "\nBA 3-D error of the check distances: actual RMS / predicted (each run's own covariance and pixel noise,\n"
           "quadratic mean of the per-distance std; parts: parameters, verification pixels) / bound (Cramer-Rao\n"
           "covariance at the truth, same propagation)\n";
    std::snprintf(line, sizeof(line), "%-10s %-6s %12s %12s %12s %12s %12s %9s %9s\n", "trajectory", "noise",
                  "3-D RMS mm", "predicted", "pred param", "pred pixel", "bound", "act/pred", "act/bound");
    out << line;
    for (const pipeline::StudyCell& c : study.cells) {
      if (c.bundle_runs == 0 || c.bundle_predicted3d_mm.count() == 0) continue;
      const double a = c.bundle_error3d_mm.Rms(), p = c.bundle_predicted3d_mm.Rms(), b = c.bundle_bound3d_mm.Rms();
      std::snprintf(line, sizeof(line), "%-10s %-6.2f %12.4f %12.4f %12.4f %12.4f %12.4f %9.3f %9.3f\n",
                    c.trajectory.c_str(), c.noise_px, a, p, c.bundle_predicted3d_parameters_mm.Rms(),
                    c.bundle_predicted3d_pixels_mm.Rms(), b, Ratio(a, p), Ratio(a, b));
      out << line;
    }
  }
  out << "\neq. (21) bias: |nominal ratio / true ratio - 1| per pose, mean (max)\n";
  for (const pipeline::StudyCell& c : study.cells) {
    if (c.noise_px != 0) continue;
    std::snprintf(line, sizeof(line), "%-10s %.3e (%.3e); position error at noise 0: %.4f mm mean, %.4f mm max\n",
                  c.trajectory.c_str(), c.scale_ratio_error.Mean(), c.scale_ratio_error.Max(), c.position_mm.Mean(),
                  c.position_mm.Max());
    out << line;
  }
  for (const pipeline::StudyCell& c : study.cells) {
    if (c.runs_failed > 0) {
      out << c.trajectory << " noise " << c.noise_px << ": " << c.runs_failed << " of " << c.runs << " runs failed";
      if (!c.failures.empty()) out << " (first: " << Shortened(c.failures.front()) << ")";
      out << "\n";
    }
  }
  for (const pipeline::StudyCell& c : study.cells) {
    if (c.bundle_runs_failed > 0) {
      out << c.trajectory << " noise " << c.noise_px << ": bundle adjustment did not converge in " << c.bundle_runs_failed
          << " of " << c.bundle_runs << " runs";
      if (!c.bundle_failures.empty()) out << " (first: " << Shortened(c.bundle_failures.front()) << ")";
      out << "\n";
    }
  }
  std::snprintf(line, sizeof(line), "identifiable parameters: paper pipeline %d, bundle adjustment %d (+ f_x); total time %.1f s\n",
                study.identifiable_parameters, study.bundle_free_parameters, study.seconds_total);
  out << line;
}

nlohmann::json BoundSweepJson(const std::vector<pipeline::BoundPoint>& sweep) {
  nlohmann::json rows = nlohmann::json::array();
  for (const pipeline::BoundPoint& p : sweep) {
    rows.push_back({{"fx_observable", p.ok_fx_unknown},
                    {"fx_px", p.setup.fx_px},
                    {"horizontal_fov_deg", p.horizontal_fov_deg},
                    {"depth_mm", p.setup.depth_m * kMm},
                    {"depth_spread_ratio", p.setup.depth_spread_ratio},
                    {"baseline_mm", p.baseline_m * kMm},
                    {"num_points", p.setup.num_points},
                    {"sigma_px", p.setup.sigma_px},
                    {"orientation_1e4rad_fx_unknown", p.orientation_rad_fx_unknown * 1e4},
                    {"position_mm_fx_unknown", p.position_m_fx_unknown * kMm},
                    {"fx_px_rms", p.fx_px},
                    {"orientation_1e4rad_fx_known", p.orientation_rad_fx_known * 1e4},
                    {"position_mm_fx_known", p.position_m_fx_known * kMm}});
  }
  return rows;
}

void PrintBoundSweep(const std::vector<pipeline::BoundPoint>& sweep, std::ostream& out) {
  if (sweep.empty()) return;
  char line[256];
  // The paper's Table 2, optimal trajectory, at its nearest noise level (I = 0.2 px, II = 0.5 px).
  const double sigma = sweep.front().setup.sigma_px;
  const bool level_two = std::abs(sigma - 0.5) < std::abs(sigma - 0.2);
  std::snprintf(line, sizeof(line),
                "\nTwo-view Cramer-Rao bound (RMS), %d points, sigma %.2f px, depth %.0f mm; paper's Table 2 "
                "optimal at noise %s: %s\n",
                sweep.front().setup.num_points, sigma, sweep.front().setup.depth_m * kMm, level_two ? "II" : "I",
                level_two ? "2.40e-4 rad, 0.30 mm, 0.35 px" : "1.07e-4 rad, 0.28 mm, 0.15 px");
  out << line;
  std::snprintf(line, sizeof(line), "%7s %7s %7s %9s %6s | %12s %10s %8s | %12s %10s\n", "fx px", "FOV deg", "spread",
                "base mm", "dots", "ori e-4 (f?)", "pos mm", "fx px", "ori e-4 (f)", "pos mm");
  out << line;
  for (const pipeline::BoundPoint& p : sweep) {
    std::snprintf(line, sizeof(line), "%7.0f %7.1f %7.2f %9.0f %6d | %12.3f %10.4f %8.3f | %12.3f %10.4f%s\n",
                  p.setup.fx_px, p.horizontal_fov_deg, p.setup.depth_spread_ratio, p.baseline_m * kMm, p.setup.num_points,
                  p.orientation_rad_fx_unknown * 1e4, p.position_m_fx_unknown * kMm, p.fx_px,
                  p.orientation_rad_fx_known * 1e4, p.position_m_fx_known * kMm,
                  p.ok_fx_unknown ? "" : "  (f_x unobservable)");
    out << line;
  }
}

}  // namespace selfcal::app
