#include "io/urdf_robot_config.h"

#include <filesystem>
#include <optional>

#include "base/atomic_file.h"
#include "io/robot_origin.h"
#include "urdf/urdf_robot.h"
#include "yaml/yaml_reader.h"

namespace selfcal::io {
namespace {

constexpr std::size_t kMaxRobotConfigBytes = 1u << 20;

}  // namespace

bool NamesUrdf(const yaml::YamlNode& node) {
  if (!node.IsMap()) return false;
  for (const std::string& key : node.keys) {
    if (key == "urdf_file") return true;
  }
  return false;
}

void ParseUrdfRobotConfig(MapReader* map, Problems* problems, CalibratedModel* out) {
  const size_t before = problems->size();
  std::string file, name;
  urdf::UrdfChainSpec spec;
  bool ok = map->String("urdf_file", &file);
  ok &= map->String("base_link", &spec.base_link);
  ok &= map->String("tip_link", &spec.tip_link);
  ok &= map->OptionalString("camera_link", &spec.camera_link);
  ok &= map->OptionalString("name", &name);
  ok &= map->OptionalString("source", &out->source);
  std::optional<Rigid3> flange_from_cam;
  const int cam_line = map->KeyLine("flange_from_cam");
  if (map->Optional("flange_from_cam")) {
    Rigid3 t;
    ok &= ReadTransform(map, "flange_from_cam", /*required=*/true, &t);
    flange_from_cam = t;
    if (!spec.camera_link.empty()) {
      problems->Add("`flange_from_cam` at " + problems->At(cam_line) + ": give either camera_link `" +
                    spec.camera_link + "` or flange_from_cam, not both");
      ok = false;
    }
  }
  for (const char* key : {"dh_convention", "joints", "base_from_link0", "link_n_from_flange"}) {
    map->Disallow(key, "a robot config with urdf_file takes the kinematics from the URDF");
  }
  map->Finish();
  if (!ok || problems->size() != before) return;
  Result<urdf::UrdfRobot> robot = urdf::LoadUrdfRobot(ResolveBesideConfig(file, problems->file()), spec, flange_from_cam);
  if (!robot.ok()) {  // at the config's line of the key the refusal is about (a missing one: the map's line)
    const std::string& message = robot.status().message();
    int line = map->KeyLine("urdf_file");
    for (const std::string key : {"base_link", "tip_link", "camera_link"}) {
      if (message.find(key + " `") != std::string::npos || message.find("give " + key) != std::string::npos) {
        line = map->KeyLine(key);
      }
    }
    problems->Add("urdf_file `" + file + "` of " + problems->At(line) + ": " + message);
    return;
  }
  out->model = robot->model;
  if (!name.empty()) out->model.name = name;
}

Result<std::string> RobotConfigTextForSession(const std::string& path) {
  Result<std::string> text = ReadFileCapped(path, kMaxRobotConfigBytes);
  if (!text.ok())
    return Status::Error(ErrorCode::kInvalidInput, "cannot read " + path + ": " + text.status().message());
  Result<yaml::YamlDocument> doc = yaml::ParseYamlText(*text, path);
  if (!doc.ok() || !NamesUrdf(doc->root)) return text;
  Result<RobotModel> model = LoadRobotModel(path);
  if (!model.ok()) return model.status();
  Result<RobotOrigin> origin = RobotOriginOfConfigText(*text, path);
  if (!origin.ok()) return origin.status();
  return "# Converted by selfcal from " + path + " (urdf_file; docs/urdf.md), exact SI values.\n" +
         RobotModelYaml(*model, TransformStyle::kExact, 0) + EnteredAsYaml(*origin);
}

}  // namespace selfcal::io
