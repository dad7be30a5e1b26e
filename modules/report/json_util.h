// Small pieces shared by the report writers: JSON numbers that may be non-finite, and kinematic
// parameters in SI with the unit in the key.
#pragma once

#include <string>

#include <nlohmann/json.hpp>

#include "kinematics/robot_model.h"

namespace selfcal::report {

// JSON has no NaN or infinity: a non-finite value is written as null ("not available").
inline nlohmann::json Finite(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); }

// "_m" for a length parameter, "_rad" for an angle: the unit of the SI value in the key.
inline const char* SiSuffix(const KinematicParameters& params, int i) {
  return params.kind(i) == ParameterKind::kLength ? "_m" : "_rad";
}

}  // namespace selfcal::report
