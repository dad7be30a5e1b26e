#include "session/setup_file.h"

#include <nlohmann/json.hpp>

namespace selfcal::session {

namespace {

using nlohmann::json;

json KnownDistancesJson(const std::vector<KnownDistance>& distances) {
  json a = json::array();
  for (const KnownDistance& d : distances) a.push_back({{"dot_a", d.dot_a}, {"dot_b", d.dot_b}, {"length_m", d.length_m}});
  return a;
}

}  // namespace

std::string SetupFileText(const ObservationSet& setup) {
  const CameraIntrinsics& c = setup.camera;
  const json j = {{"format", kSetupFormatName},
                  {"version", kSetupFormatVersion},
                  {"camera", {{"width_px", c.width_px}, {"height_px", c.height_px}, {"fx_px", c.fx_px}, {"mu", c.mu},
                              {"cx_px", c.cx_px}, {"cy_px", c.cy_px}, {"k1", c.k1}}},
                  {"pixel_noise_px", setup.pixel_noise_px},
                  {"yardsticks", KnownDistancesJson(setup.yardsticks)},
                  {"check_distances", KnownDistancesJson(setup.check_distances)}};
  return j.dump(2) + "\n";
}

Status ParseSetupFile(const std::string& text, const std::string& name, ObservationSet* set) {
  auto bad = [&](const std::string& why) { return Status::Error(ErrorCode::kInvalidInput, name + ": " + why); };
  json j = json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (j.is_discarded() || !j.is_object()) return bad("not a JSON object");
  if (j.value("format", "") != kSetupFormatName || j.value("version", 0) != kSetupFormatVersion) {
    return bad(std::string("format must be ") + kSetupFormatName + " version " + std::to_string(kSetupFormatVersion));
  }
  try {
    const json& c = j.at("camera");
    set->camera.width_px = c.at("width_px").get<int>();
    set->camera.height_px = c.at("height_px").get<int>();
    set->camera.fx_px = c.at("fx_px").get<double>();
    set->camera.mu = c.at("mu").get<double>();
    set->camera.cx_px = c.at("cx_px").get<double>();
    set->camera.cy_px = c.at("cy_px").get<double>();
    set->camera.k1 = c.at("k1").get<double>();
    set->pixel_noise_px = j.at("pixel_noise_px").get<double>();
    for (const char* key : {"yardsticks", "check_distances"}) {
      std::vector<KnownDistance>& out = std::string(key) == "yardsticks" ? set->yardsticks : set->check_distances;
      for (const json& d : j.at(key)) {
        out.push_back({d.at("dot_a").get<int>(), d.at("dot_b").get<int>(), d.at("length_m").get<double>()});
      }
    }
  } catch (const json::exception& e) {
    return bad(std::string("missing or mistyped key: ") + e.what());
  }
  if (!(set->camera.fx_px > 0) || set->camera.width_px <= 0 || set->camera.height_px <= 0 || !(set->pixel_noise_px > 0)) {
    return bad("camera size, fx_px and pixel_noise_px must be positive");
  }
  return Status::Ok();
}

}  // namespace selfcal::session
