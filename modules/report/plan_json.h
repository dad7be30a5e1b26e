// A plan's figures as JSON (`selfcal plan --json`, docs/cli-output.md): the criteria before and after,
// the plan check and the observability of the identification poses. SI with the unit in the key; a
// figure that was not computed is null.
#pragma once

#include <nlohmann/json.hpp>

#include "planning/observability.h"
#include "planning/planner.h"

namespace selfcal::report {

// ok, problems (sentences), the figures of the check (min_spread_m, min_axis_sine, max_joint_travel_rad,
// max_image_motion_px, min_image_margin_px, predicted_fx_stddev_px, identifiable of generic_identifiable).
nlohmann::json PlanCheckJson(const planning::PlanCheck& check);

// ok, message, the Jacobian's size, condition_number, min_singular_value, log10_product_singular_values,
// observability_index, noise_amplification_index; with a prediction: pixel_noise_px, predicted_stddev
// per free parameter ({name, value_m or value_rad}) and predicted_fx_stddev_px.
nlohmann::json ObservabilityJson(const planning::ObservabilityReport& report, const RobotModel& robot);

// criterion, ok, message, poses, identification_poses, repaired_poses, pool_size, iterations, evaluations,
// seconds, and {start, planned} of eq39 (total, ratio_term, condition_number, lambda), d_optimal (log det
// of the information) and a_optimal; check_start and check_final (PlanCheckJson).
nlohmann::json PlanResultJson(const planning::PlanResult& result);

}  // namespace selfcal::report
