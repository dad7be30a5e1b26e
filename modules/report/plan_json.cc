#include "report/plan_json.h"

#include "report/json_util.h"

namespace selfcal::report {

nlohmann::json PlanCheckJson(const planning::PlanCheck& check) {
  nlohmann::json problems = nlohmann::json::array();
  for (const planning::PlanProblemItem& p : check.problems) problems.push_back(p.message);
  return {{"ok", check.ok},
          {"problems", problems},
          {"min_spread_m", Finite(check.min_spread_m)},
          {"min_axis_sine", Finite(check.min_axis_sine)},
          {"max_joint_travel_rad", Finite(check.max_joint_travel_rad)},
          {"max_image_motion_px", check.image_motion.empty() ? nlohmann::json() : Finite(check.max_image_motion_px)},
          {"min_image_margin_px", check.image_motion.empty() ? nlohmann::json() : Finite(check.min_image_margin_px)},
          {"predicted_fx_stddev_px", check.image_motion.empty() ? nlohmann::json() : Finite(check.predicted_fx_stddev_px)},
          {"identifiable", check.identifiable},
          {"generic_identifiable", check.generic_identifiable}};
}

nlohmann::json ObservabilityJson(const planning::ObservabilityReport& r, const RobotModel& robot) {
  nlohmann::json j = {{"ok", r.ok}, {"message", r.message}};
  if (!r.ok) return j;
  j["rows"] = r.rows;
  j["columns"] = r.columns;
  j["condition_number"] = Finite(r.condition_number);
  j["min_singular_value"] = Finite(r.min_singular_value);
  j["log10_product_singular_values"] = Finite(r.log10_product_singular_values);
  j["observability_index"] = Finite(r.observability_index);
  j["noise_amplification_index"] = Finite(r.noise_amplification_index);
  j["prediction_ok"] = r.prediction_ok;
  if (!r.prediction_ok) return j;
  const KinematicParameters params(robot.num_joints());
  nlohmann::json stddev = nlohmann::json::array();
  for (size_t k = 0; k < r.free_indices.size() && k < r.predicted_stddev.size(); ++k) {
    stddev.push_back({{"name", r.free_names[k]},
                      {std::string("value") + SiSuffix(params, r.free_indices[k]), Finite(r.predicted_stddev[k])}});
  }
  j["pixel_noise_px"] = r.pixel_noise_px;
  j["predicted_stddev"] = stddev;
  j["predicted_fx_stddev_px"] = Finite(r.predicted_fx_stddev_px);
  return j;
}

nlohmann::json PlanResultJson(const planning::PlanResult& r) {
  auto eq39 = [](const planning::Eq39Value& v) {
    return nlohmann::json{{"total", Finite(v.total)},
                          {"ratio_term", Finite(v.ratio_term)},
                          {"condition_number", Finite(v.condition_number)},
                          {"lambda", v.lambda}};
  };
  return {{"criterion", planning::CriterionName(r.criterion)},
          {"ok", r.ok},
          {"message", r.message},
          {"poses", r.poses.size()},
          {"identification_poses", r.num_identification_poses},
          {"repaired_poses", r.repaired_poses},
          {"pool_size", r.pool_size},
          {"iterations", r.iterations},
          {"evaluations", r.evaluations},
          {"converged", r.converged},
          {"stop_rule", r.stop_rule},
          {"seconds", r.seconds},
          {"eq39", {{"start", eq39(r.eq39_start)}, {"planned", eq39(r.eq39_final)}}},
          {"d_optimal_log_det", {{"start", Finite(r.fisher_start.log_det)}, {"planned", Finite(r.fisher_final.log_det)}}},
          {"a_optimal", {{"start", Finite(r.fisher_start.a_value)}, {"planned", Finite(r.fisher_final.a_value)}}},
          {"check_start", PlanCheckJson(r.check_start)},
          {"check_final", PlanCheckJson(r.check_final)}};
}

}  // namespace selfcal::report
