#include "session/setup_file.h"

#include <cmath>
#include <optional>
#include <set>
#include <utility>

#include <nlohmann/json.hpp>

#include "base/short_number.h"
#include "io/plausible_limits.h"
#include "session/json_fields.h"

namespace selfcal::session {

namespace {

using nlohmann::json;

json KnownDistancesJson(const std::vector<KnownDistance>& distances) {
  json a = json::array();
  for (const KnownDistance& d : distances) a.push_back({{"dot_a", d.dot_a}, {"dot_b", d.dot_b}, {"length_m", d.length_m}});
  return a;
}

// The optional naming keys (setup_file.h) into *naming; problems into *fields.
void ParseNaming(const json& j, JsonFields* fields, SetupNaming* naming) {
  if (j.contains("reference_image")) fields->GetString(j, {}, "reference_image", &naming->reference_image);
  if (!j.contains("reference_dots")) return;
  const json* dots = fields->GetArray(j, {}, "reference_dots");
  if (dots == nullptr) return;
  const JsonPath list = JsonPath{}.Member("reference_dots");
  std::set<int> ids;
  for (std::size_t i = 0; i < dots->size(); ++i) {
    const json& d = (*dots)[i];
    const JsonPath at = list.Element(i);
    if (!d.is_object()) {
      fields->Add(at, "`" + at.name + "` must be an object {id, u_px, v_px, area_px2}");
      continue;
    }
    fields->CheckKnown(d, at, {"id", "u_px", "v_px", "area_px2"});
    ReferenceDot r;
    if (!(fields->GetInt(d, at, "id", &r.id) & fields->GetDouble(d, at, "u_px", &r.u_px) &
          fields->GetDouble(d, at, "v_px", &r.v_px) & fields->GetDouble(d, at, "area_px2", &r.area_px2))) {
      continue;
    }
    if (r.id < 0 || !ids.insert(r.id).second) {
      fields->Add(at, "`" + at.name + "`: id " + std::to_string(r.id) + " is negative or repeated");
    } else if (!(r.area_px2 >= 0)) {
      fields->Add(at, "`" + at.name + "`: id " + std::to_string(r.id) + " has a negative area");
    }
    naming->reference_dots.push_back(r);
  }
}

// The camera block into *camera, each key checked (sizes and fx_px positive).
void ParseCamera(const json& j, JsonFields* fields, CameraIntrinsics* camera) {
  const json* c = fields->Get(j, {}, "camera");
  if (c == nullptr) return;
  const JsonPath at = JsonPath{}.Member("camera");
  if (!c->is_object()) {
    fields->Add(at, "`camera` must be an object (found " + JsonTypeName(*c) + ")");
    return;
  }
  fields->CheckKnown(*c, at, {"width_px", "height_px", "fx_px", "mu", "cx_px", "cy_px", "k1"});
  for (const auto& [key, out] : {std::pair{"width_px", &camera->width_px}, std::pair{"height_px", &camera->height_px}}) {
    if (fields->GetInt(*c, at, key, out) && *out <= 0) fields->Add(at.Member(key), "`camera." + std::string(key) + "` must be positive");
  }
  if (fields->GetDouble(*c, at, "fx_px", &camera->fx_px) && !(camera->fx_px > 0)) {
    fields->Add(at.Member("fx_px"), "`camera.fx_px` must be positive");
  }
  fields->GetDouble(*c, at, "mu", &camera->mu);
  fields->GetDouble(*c, at, "cx_px", &camera->cx_px);
  fields->GetDouble(*c, at, "cy_px", &camera->cy_px);
  fields->GetDouble(*c, at, "k1", &camera->k1);
}

// yardsticks or check_distances: [{dot_a, dot_b, length_m}], each length in [1 mm, 100 m] as in observations
// files (io/observations_file.h).
void ParseDistances(const json& j, const std::string& key, JsonFields* fields, std::vector<KnownDistance>* out) {
  const json* list = fields->GetArray(j, {}, key);
  if (list == nullptr) return;
  for (std::size_t i = 0; i < list->size(); ++i) {
    const JsonPath at = JsonPath{}.Member(key).Element(i);
    const json& d = (*list)[i];
    if (!d.is_object()) {
      fields->Add(at, "`" + at.name + "` must be an object {dot_a, dot_b, length_m}");
      continue;
    }
    fields->CheckKnown(d, at, {"dot_a", "dot_b", "length_m"});
    KnownDistance distance;
    if (!(fields->GetInt(d, at, "dot_a", &distance.dot_a) & fields->GetInt(d, at, "dot_b", &distance.dot_b) &
          fields->GetDouble(d, at, "length_m", &distance.length_m))) {
      continue;
    }
    if (!(distance.length_m >= io::kMinKnownDistanceM && distance.length_m <= io::kMaxKnownDistanceM)) {
      const JsonPath length = at.Member("length_m");
      fields->Add(length, "`" + length.name + "` = " + ShortNumber(distance.length_m) + " m is out of range: must be in [" +
                              ShortNumber(io::kMinKnownDistanceM) + ", " + ShortNumber(io::kMaxKnownDistanceM) +
                              "] m (two dots' centres, at least 1 mm apart)");
      continue;
    }
    out->push_back(distance);
  }
}

// The numbers of `value` (an array of `count` numbers) into *out; false after naming the problem.
bool Numbers(const json& value, const JsonPath& at, std::size_t count, JsonFields* fields, double* out) {
  if (!value.is_array() || value.size() != count) {
    fields->Add(at, "`" + at.name + "` must be an array of " + std::to_string(count) + " numbers");
    return false;
  }
  for (std::size_t k = 0; k < count; ++k) {
    if (!value[k].is_number() || !std::isfinite(value[k].get<double>())) {
      fields->Add(at, "`" + at.name + "` must be an array of " + std::to_string(count) + " finite numbers");
      return false;
    }
    out[k] = value[k].get<double>();
  }
  return true;
}

// "configuration" (default eye_in_hand) and, in eye-to-hand, "base_from_cam" {translation_m: [x, y, z],
// rotation: [[row 0], [row 1], [row 2]]} (the nominal fixed camera) into robot->mount, robot->base_from_cam.
void ParseConfiguration(const json& j, JsonFields* fields, RobotModel* robot) {
  std::string configuration = CameraMountName(CameraMount::kEyeInHand);
  if (j.contains("configuration") && fields->GetString(j, {}, "configuration", &configuration) &&
      !ParseCameraMount(configuration, &robot->mount)) {
    fields->Add(JsonPath{}.Member("configuration"),
                "`configuration` \"" + configuration + "\" is neither eye_in_hand nor eye_to_hand");
  }
  const JsonPath at = JsonPath{}.Member("base_from_cam");
  if (robot->mount == CameraMount::kEyeInHand) {
    if (j.contains("base_from_cam")) {
      fields->Add(at, "`base_from_cam` (a fixed camera) needs `configuration` eye_to_hand; eye_in_hand has none");
    }
    return;
  }
  const json* c = fields->Get(j, {}, "base_from_cam");
  if (c == nullptr) return;
  if (!c->is_object()) {
    fields->Add(at, "`base_from_cam` must be an object {translation_m, rotation}");
    return;
  }
  fields->CheckKnown(*c, at, {"translation_m", "rotation"});
  double t[3], r[9];
  const json* translation = fields->Get(*c, at, "translation_m");
  const json* rotation = fields->Get(*c, at, "rotation");
  if (translation == nullptr || rotation == nullptr) return;
  bool ok = Numbers(*translation, at.Member("translation_m"), 3, fields, t);
  for (int k = 0; ok && k < 3; ++k) {
    if (std::abs(t[k]) > io::kMaxTranslationM) {
      fields->Add(at.Member("translation_m").Element(k), "`base_from_cam.translation_m` " + ShortNumber(t[k]) +
                                                             " m is beyond the " + ShortNumber(io::kMaxTranslationM) +
                                                             " m a camera of an arm's cell can be from its base");
      ok = false;
    }
  }
  if (!rotation->is_array() || rotation->size() != 3) {
    fields->Add(at.Member("rotation"), "`base_from_cam.rotation` must be 3 rows of 3 numbers");
    return;
  }
  for (std::size_t row = 0; row < 3; ++row) {
    ok = Numbers((*rotation)[row], at.Member("rotation").Element(row), 3, fields, r + 3 * row) && ok;
  }
  if (!ok) return;
  Eigen::Matrix3d m;
  m << r[0], r[1], r[2], r[3], r[4], r[5], r[6], r[7], r[8];
  if ((m.transpose() * m - Eigen::Matrix3d::Identity()).norm() > 1e-6 || m.determinant() < 0) {
    fields->Add(at.Member("rotation"), "`base_from_cam.rotation` is not a rotation (orthonormal, determinant +1)");
    return;
  }
  robot->base_from_cam = Rigid3(m, Eigen::Vector3d(t[0], t[1], t[2]));
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
  if (setup.robot.mount == CameraMount::kEyeToHand) {  // eye-in-hand setups keep their earlier bytes
    const Rigid3& c = setup.robot.base_from_cam;
    j["configuration"] = CameraMountName(setup.robot.mount);
    json rows = json::array();
    for (int r = 0; r < 3; ++r) rows.push_back({c.rotation(r, 0), c.rotation(r, 1), c.rotation(r, 2)});
    j["base_from_cam"] = {{"translation_m", {c.translation.x(), c.translation.y(), c.translation.z()}}, {"rotation", rows}};
  }
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
  JsonFields fields(text, name);
  const std::optional<json> parsed = fields.ParseObject();
  if (!parsed) return fields.ToStatus();
  const json& j = *parsed;
  std::string format;
  int version = 0;
  if (!fields.GetString(j, {}, "format", &format) || !fields.GetInt(j, {}, "version", &version)) {
    return fields.ToStatus();
  }
  if (format != kSetupFormatName || version != kSetupFormatVersion) {
    fields.Add(JsonPath{}.Member(format != kSetupFormatName ? "format" : "version"),
               std::string("format must be ") + kSetupFormatName + " version " + std::to_string(kSetupFormatVersion));
    return fields.ToStatus();
  }
  fields.CheckKnown(j, {}, {"format", "version", "camera", "pixel_noise_px", "yardsticks", "check_distances",
                           "reference_dots", "reference_image", "configuration", "base_from_cam"});
  ParseConfiguration(j, &fields, &set->robot);
  ParseCamera(j, &fields, &set->camera);
  if (fields.GetDouble(j, {}, "pixel_noise_px", &set->pixel_noise_px) && !(set->pixel_noise_px > 0)) {
    fields.Add(JsonPath{}.Member("pixel_noise_px"), "`pixel_noise_px` must be positive");
  }
  ParseDistances(j, "yardsticks", &fields, &set->yardsticks);
  ParseDistances(j, "check_distances", &fields, &set->check_distances);
  if (naming != nullptr) ParseNaming(j, &fields, naming);
  return fields.ok() ? Status::Ok() : fields.ToStatus();
}

}  // namespace selfcal::session
