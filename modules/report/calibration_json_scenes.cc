#include "report/calibration_json_scenes.h"

namespace selfcal::report {

using nlohmann::json;

json SceneMovesJson(const calibration::CalibrationReport& report) {
  json moves = json::array();
  for (const calibration::SceneMove& m : report.scene_moves) {
    moves.push_back({{"scene", m.scene},
                     {"relative_to", m.relative_to},
                     {"shared_points", m.shared_points},
                     {"displacement_rms_m", m.displacement_rms_m},
                     {"displacement_max_m", m.displacement_max_m},
                     {"rotation_rad", m.rotation_rad},
                     {"rigid_fit_rms_m", m.rigid_fit_rms_m},
                     {"moved", m.moved}});
  }
  return moves;
}

json SceneSplitJson(const calibration::CalibrationReport& report) {
  if (!report.scene_split) return nullptr;
  const calibration::SceneSplit& s = *report.scene_split;
  const auto px_or_null = [](double v) { return v > 0 ? json(v) : json(); };
  return {{"images", s.images},
          {"found", s.found},
          {"separation_px", s.separation_px},
          {"scatter_px", {s.scatter_first_px, s.scatter_second_px}},
          {"rms_one_place_px", s.rms_one_place_px},
          {"rms_two_places_px", s.rms_two_places_px},
          {"first_poses", s.first_poses},
          {"second_poses", s.second_poses},
          {"translation_m", s.translation_m},
          {"rotation_rad", s.rotation_rad},
          {"applied", s.applied},
          {"decision", s.decision},
          {"heldout_one_scene_px", px_or_null(s.one_scene_heldout_px)},
          {"heldout_scene_each_px", px_or_null(s.split_heldout_px)}};
}

}  // namespace selfcal::report
