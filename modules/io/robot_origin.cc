#include "io/robot_origin.h"

#include <algorithm>
#include <cstdlib>
#include <filesystem>

#include "base/atomic_file.h"
#include "io/yaml_writer.h"
#include "urdf/urdf_robot.h"
#include "yaml/yaml_reader.h"

namespace selfcal::io {
namespace {

constexpr std::size_t kMaxConfigBytes = 1u << 20;

std::string ScalarOf(const yaml::YamlNode& map, const std::string& key) {
  const yaml::YamlNode* node = map.Find(key);
  return node != nullptr && node->IsScalar() ? node->scalar : "";
}

// A DH config's per-joint `name`, `link` and `max_velocity_deg_s`, each kept only when every row gives it (the
// robot config's own reader checks their values).
void ReadJointExtras(const yaml::YamlNode& root, RobotOrigin* origin) {
  const yaml::YamlNode* joints = root.Find("joints");
  if (joints == nullptr || !joints->IsSequence() || joints->items.empty()) return;
  std::vector<std::string> names, links;
  std::vector<double> velocities;
  for (const yaml::YamlNode& row : joints->items) {
    if (!row.IsMap()) return;
    names.push_back(ScalarOf(row, "name"));
    links.push_back(ScalarOf(row, "link"));
    char* end = nullptr;
    const std::string v = ScalarOf(row, "max_velocity_deg_s");
    const double deg_s = v.empty() ? 0 : std::strtod(v.c_str(), &end);
    velocities.push_back(deg_s > 0 && end != nullptr && *end == '\0' ? DegToRad(deg_s) : 0);
  }
  auto all = [](const auto& values, const auto& unset) {
    return std::none_of(values.begin(), values.end(), [&](const auto& v) { return v == unset; });
  };
  if (all(names, std::string())) origin->config_joint_names = names;
  if (all(links, std::string())) origin->config_link_names = links;
  if (all(velocities, 0.0)) origin->max_velocity_rad_s = velocities;
}

Result<RobotOrigin> OriginOfNode(const yaml::YamlNode& root, const std::string& path) {
  RobotOrigin origin;
  if (!root.IsMap()) return Status::Error(ErrorCode::kInvalidInput, path + ": not a robot config");
  const std::string urdf_file = ScalarOf(root, "urdf_file");
  if (!urdf_file.empty()) {
    const urdf::UrdfChainSpec spec{ScalarOf(root, "base_link"), ScalarOf(root, "tip_link"), ScalarOf(root, "camera_link")};
    // The joint names need the URDF; flange_from_cam does not matter for them.
    const std::string resolved = ResolveBesideConfig(urdf_file, path);
    Result<urdf::UrdfRobot> robot = urdf::LoadUrdfRobot(resolved, spec, Rigid3());
    if (!robot.ok()) return robot.status();
    RobotOrigin origin;
    origin.joint_names = robot->joint_names;
    origin.base_link = spec.base_link;
    origin.tip_link = spec.tip_link;
    origin.camera_link = spec.camera_link;
    origin.urdf_file = resolved;
    return origin;
  }
  Problems problems(path);
  MapReader map(root, "", &problems);
  map.Abandon();  // only entered_as is read here; the robot's own reader checks the rest
  if (!ReadEnteredAs(&map, &origin)) return problems.ToStatus("robot config");
  if (origin.dh_convention.empty() && !origin.FromUrdf()) origin.dh_convention = ScalarOf(root, "dh_convention");
  if (!origin.FromUrdf()) ReadJointExtras(root, &origin);
  return origin;
}

}  // namespace

std::string ResolveBesideConfig(const std::string& file, const std::string& config_path) {
  if (file.empty() || file.front() == '/') return file;
  return (std::filesystem::path(config_path).parent_path() / file).lexically_normal().string();
}

bool ReadEnteredAs(MapReader* root, RobotOrigin* origin) {
  const yaml::YamlNode* node = root->Optional("entered_as");
  if (!node) return true;
  MapReader map(*node, root->Path("entered_as"), root->problems());
  if (!map.ok()) return false;
  bool ok = map.OptionalString("dh_convention", &origin->dh_convention);
  ok &= map.OptionalString("base_link", &origin->base_link);
  ok &= map.OptionalString("tip_link", &origin->tip_link);
  ok &= map.OptionalString("camera_link", &origin->camera_link);
  ok &= map.OptionalString("urdf_file", &origin->urdf_file);
  if (const yaml::YamlNode* names = map.Optional("joint_names")) {
    if (!names->IsSequence()) {
      root->problems()->Add("`" + map.Path("joint_names") + "` at " + root->problems()->At(names->line) +
                            " must be a sequence of joint names");
      ok = false;
    } else {
      for (size_t i = 0; i < names->items.size(); ++i) {
        std::string name;
        ok &= ReadString(names->items[i], map.Path("joint_names") + "[" + std::to_string(i) + "]", root->problems(),
                         &name);
        origin->joint_names.push_back(name);
      }
    }
  }
  map.Finish();
  return ok;
}

std::string EnteredAsYaml(const RobotOrigin& origin) {
  if (!origin.FromUrdf()) return "";
  std::string out = "entered_as: {base_link: " + YamlQuoted(origin.base_link) + ", tip_link: " +
                    YamlQuoted(origin.tip_link) + ", camera_link: " + YamlQuoted(origin.camera_link) + ", joint_names: [";
  for (size_t i = 0; i < origin.joint_names.size(); ++i) out += (i ? ", " : "") + YamlQuoted(origin.joint_names[i]);
  out += "]";
  if (!origin.urdf_file.empty()) {
    out += ", urdf_file: " + YamlQuoted(std::filesystem::absolute(origin.urdf_file).lexically_normal().string());
  }
  return out + "}  # the URDF's names and file (for the exports)\n";
}

Result<RobotOrigin> RobotOriginOfConfigText(const std::string& text, const std::string& path) {
  Result<yaml::YamlDocument> doc = yaml::ParseYamlText(text, path);
  if (!doc.ok()) return doc.status();
  return OriginOfNode(doc->root, path);
}

Result<RobotOrigin> RobotOriginOfConfig(const std::string& path) {
  Result<std::string> text = ReadFileCapped(path, kMaxConfigBytes);
  if (!text.ok()) return text.status();
  return RobotOriginOfConfigText(*text, path);
}

Result<RobotOrigin> RobotOriginOfObservations(const yaml::YamlDocument& doc) {
  const std::string& path = doc.path;
  if (!doc.root.IsMap()) return Status::Error(ErrorCode::kInvalidInput, path + ": not an observations file");
  const std::string robot_file = ScalarOf(doc.root, "robot_file");
  if (!robot_file.empty()) return RobotOriginOfConfig(ResolveBesideConfig(robot_file, path));
  const yaml::YamlNode* robot = doc.root.Find("robot");
  if (robot == nullptr) return Status::Error(ErrorCode::kInvalidInput, path + ": no robot");
  return OriginOfNode(*robot, path);
}

Result<RobotOrigin> RobotOriginOfObservations(const std::string& path) {
  Result<yaml::YamlDocument> doc = yaml::LoadYamlFile(path);
  if (!doc.ok()) return doc.status();
  return RobotOriginOfObservations(*doc);
}

}  // namespace selfcal::io
