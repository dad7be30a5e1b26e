#include "report/study_report.h"

#include <cmath>

#include "report/json_util.h"
#include "report/literature.h"

namespace selfcal::report {

namespace internal {

nlohmann::json StatJson(const simulation::Stat& s) {
  return {{"n", s.count()}, {"mean", Finite(s.Mean())}, {"sd", Finite(s.Sd())}, {"rms", Finite(s.Rms())},
          {"p90", Finite(s.Percentile(90))}, {"max", Finite(s.Max())}};
}

double Ratio(double a, double b) { return std::isfinite(a) && std::isfinite(b) && b > 0 ? a / b : NAN; }

}  // namespace internal

namespace {

using internal::Ratio;
using internal::StatJson;

// Per free parameter: RMS error against the truth, RMS Cramer-Rao std, and their ratio (units in the key).
nlohmann::json BundleParametersJson(const simulation::StudyCell& c) {
  nlohmann::json rows = nlohmann::json::array();
  for (const auto& [name, error] : c.bundle_parameter_error) {
    auto bound = c.bundle_parameter_bound.find(name);
    const double b = bound == c.bundle_parameter_bound.end() ? NAN : bound->second.Rms();
    rows.push_back({{"name", name}, {"n", error.count()}, {"rms_error", Finite(error.Rms())},
                    {"rms_bound", Finite(b)}, {"ratio", Finite(Ratio(error.Rms(), b))}});
  }
  return rows;
}

nlohmann::json BundleCellJson(const simulation::StudyCell& c) {
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
           {{"description", "std of the 3-D error of each check distance predicted to first order (calibration/"
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
          {"parameter_abs_error", {{"description", "|estimate - truth| of every free parameter, pooled over the "
                                                   "runs whose gauge is the truth's (runs_in_truths_gauge; noise 0 "
                                                   "included)"},
                                   {"length_mm", StatJson(c.bundle_length_error_mm)},
                                   {"angle_deg", StatJson(c.bundle_angle_error_deg)}}},
          {"weak_held_runs", c.bundle_weak_held},
          {"runs_with_weak_held", c.bundle_runs_weak_held},
          {"runs_in_truths_gauge", c.bundle_runs_in_truths_gauge},
          {"seconds_per_solve", StatJson(c.bundle_seconds)}};
}
}  // namespace

nlohmann::json StudyJson(const simulation::StudyReport& study, const simulation::StudyOptions& options) {
  nlohmann::json j;
  j["format"] = "selfcal-study";
  j["version"] = 1;
  j["software_version"] = SELFCAL_VERSION;
  j["runs_per_cell"] = options.runs;
  j["seed"] = options.seed;
  j["pixel_noise_note"] = "std per coordinate in px (the paper's N(0, s) read as a std)";
  j["hidden_errors"] = {{"length_std_mm", options.sim.length_error_std_m * kMmPerM},
                        {"angle_std_deg", RadToDeg(options.sim.angle_error_std_rad)},
                        {"cam_length_std_mm", options.sim.cam_length_error_std_m * kMmPerM},
                        {"cam_angle_std_deg", RadToDeg(options.sim.cam_angle_error_std_rad)},
                        {"fx_relative_std", options.sim.fx_relative_error_std}};
  j["identifiable_parameters"] = study.identifiable_parameters;
  j["fixed_parameters"] = study.fixed_parameters;
  j["flat_sheet"] = study.flat_sheet;
  j["configuration"] = CameraMountName(study.configuration);
  j["paper_pipeline_applies"] = study.paper_pipeline_note.empty();
  j["paper_pipeline_note"] = study.paper_pipeline_note.empty() ? nlohmann::json(nullptr) : nlohmann::json(study.paper_pipeline_note);
  j["bundle_free_parameters"] = study.bundle_free_parameters;
  j["bundle_fixed_parameters"] = study.bundle_fixed_parameters;
  nlohmann::json table2 = nlohmann::json::array();
  for (const PaperTable2Row& row : MengZhuang2001Table2()) {
    table2.push_back({{"trajectory", row.trajectory},
                      {"noise_px", row.noise_px},
                      {"position_mm", {row.position_mm.mean, row.position_mm.sd}},
                      {"orientation_1e4rad", {row.orientation_1e4rad.mean, row.orientation_1e4rad.sd}},
                      {"fx_px", {row.fx_px.mean, row.fx_px.sd}}});
  }
  j["paper_table2"] = table2;
  nlohmann::json cells = nlohmann::json::array();
  for (const simulation::StudyCell& c : study.cells) {
    nlohmann::json centroids = nullptr;
    if (c.rendered) {
      centroids = {{"expected", c.centroids.expected}, {"detected", c.centroids.detected},
                   {"matched", c.centroids.matched}, {"missed", c.centroids.missed},
                   {"spurious", c.centroids.spurious},
                   {"rms_vs_area_centroid_px", simulation::CentroidErrors::Rms(c.centroids.vs_area_centroid_px)},
                   {"rms_vs_projected_px", simulation::CentroidErrors::Rms(c.centroids.vs_projected_px)},
                   {"rms_ellipse_bias_px", simulation::CentroidErrors::Rms(c.centroids.ellipse_bias_px)}};
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

nlohmann::json BoundSweepJson(const std::vector<simulation::BoundPoint>& sweep) {
  nlohmann::json rows = nlohmann::json::array();
  for (const simulation::BoundPoint& p : sweep) {
    rows.push_back({{"fx_observable", p.ok_fx_unknown},
                    {"fx_px", p.setup.fx_px},
                    {"horizontal_fov_deg", p.horizontal_fov_deg},
                    {"depth_mm", p.setup.depth_m * kMmPerM},
                    {"depth_spread_ratio", p.setup.depth_spread_ratio},
                    {"baseline_mm", p.baseline_m * kMmPerM},
                    {"num_points", p.setup.num_points},
                    {"sigma_px", p.setup.sigma_px},
                    {"orientation_1e4rad_fx_unknown", p.orientation_rad_fx_unknown * 1e4},
                    {"position_mm_fx_unknown", p.position_m_fx_unknown * kMmPerM},
                    {"fx_px_rms", p.fx_px},
                    {"orientation_1e4rad_fx_known", p.orientation_rad_fx_known * 1e4},
                    {"position_mm_fx_known", p.position_m_fx_known * kMmPerM}});
  }
  return rows;
}

}  // namespace selfcal::report
