// report.json's `scene_moves` and `scene_split`: where the scenes of a set lie against each other, and whether
// one set's images saw its scene in two places (docs/report-format.md). Internal to the report module.
#pragma once

#include <nlohmann/json.hpp>

#include "calibration/calibrate.h"

namespace selfcal::report {

nlohmann::json SceneMovesJson(const calibration::CalibrationReport& report);

// null when the check did not run (not a joint set of one scene, or the bundle gave no points).
nlohmann::json SceneSplitJson(const calibration::CalibrationReport& report);

}  // namespace selfcal::report
