#include "session/setup_file.h"

#include <cmath>
#include <set>

#include <nlohmann/json.hpp>

namespace selfcal::session {

namespace {

using nlohmann::json;

json KnownDistancesJson(const std::vector<KnownDistance>& distances) {
  json a = json::array();
  for (const KnownDistance& d : distances) a.push_back({{"dot_a", d.dot_a}, {"dot_b", d.dot_b}, {"length_m", d.length_m}});
  return a;
}

// The optional naming keys (setup_file.h) into *naming; an error message, or empty.
std::string ParseNaming(const json& j, SetupNaming* naming) {
  if (j.contains("reference_image")) naming->reference_image = j.at("reference_image").get<std::string>();
  if (!j.contains("reference_dots")) return "";
  std::set<int> ids;
  for (const json& d : j.at("reference_dots")) {
    const ReferenceDot r{d.at("id").get<int>(), d.at("u_px").get<double>(), d.at("v_px").get<double>(),
                         d.at("area_px2").get<double>()};
    if (r.id < 0 || !ids.insert(r.id).second) return "reference_dots: id " + std::to_string(r.id) + " is negative or repeated";
    if (!std::isfinite(r.u_px) || !std::isfinite(r.v_px) || !(r.area_px2 >= 0)) {
      return "reference_dots: id " + std::to_string(r.id) + " has a non-finite position or a negative area";
    }
    naming->reference_dots.push_back(r);
  }
  return "";
}

}  // namespace

std::string SetupFileText(const ObservationSet& setup, const SetupNaming& naming) {
  const CameraIntrinsics& c = setup.camera;
  json j = {{"format", kSetupFormatName},
            {"version", kSetupFormatVersion},
            {"camera", {{"width_px", c.width_px}, {"height_px", c.height_px}, {"fx_px", c.fx_px}, {"mu", c.mu},
                        {"cx_px", c.cx_px}, {"cy_px", c.cy_px}, {"k1", c.k1}}},
            {"pixel_noise_px", setup.pixel_noise_px},
            {"yardsticks", KnownDistancesJson(setup.yardsticks)},
            {"check_distances", KnownDistancesJson(setup.check_distances)}};
  if (!naming.reference_image.empty()) j["reference_image"] = naming.reference_image;
  if (!naming.reference_dots.empty()) {
    json dots = json::array();
    for (const ReferenceDot& d : naming.reference_dots) {
      dots.push_back({{"id", d.id}, {"u_px", d.u_px}, {"v_px", d.v_px}, {"area_px2", d.area_px2}});
    }
    j["reference_dots"] = dots;
  }
  return j.dump(2) + "\n";
}

Status ParseSetupFile(const std::string& text, const std::string& name, ObservationSet* set, SetupNaming* naming) {
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
    if (naming != nullptr) {
      if (const std::string why = ParseNaming(j, naming); !why.empty()) return bad(why);
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
