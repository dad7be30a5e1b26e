#include "io/observations_file.h"

#include <climits>
#include <cmath>
#include <map>
#include <sstream>

#include "base/short_number.h"
#include "io/atomic_file.h"
#include "io/camera_file.h"
#include "io/plausible_limits.h"
#include "io/robot_config.h"
#include "io/transform_yaml.h"
#include "io/yaml_schema.h"
#include "io/yaml_writer.h"

namespace selfcal::io {

namespace {

const Range kPixel = Range::Closed(-1e5, 1e5);

std::string DirectoryOf(const std::string& path) {
  const size_t slash = path.find_last_of('/');
  return slash == std::string::npos ? "." : path.substr(0, slash == 0 ? 1 : slash);
}

// A problem that ObservationSet::Validate() does not see: dots outside the image (C11). Empty when plausible.
// (Joints outside the limits are the controller's reading: kept, and warned of by calibrate.)
std::string PixelProblem(const CameraIntrinsics& camera, const Eigen::Vector2d& uv) {
  if (InImage(camera, uv, 0.0)) return "";
  return "lies outside the " + std::to_string(camera.width_px) + "x" + std::to_string(camera.height_px) +
         " image (u in [-0.5, " + ShortNumber(camera.width_px - 0.5) + "], v in [-0.5, " + ShortNumber(camera.height_px - 0.5) + "])";
}

}  // namespace

bool ReadCamera(MapReader* root, Problems* problems, CameraIntrinsics* camera) {
  const yaml::YamlNode* file = root->Optional("camera_file");
  std::string camera_name;
  const bool named = root->OptionalString("camera_name", &camera_name);
  if (file != nullptr) {
    if (root->Optional("camera") != nullptr) {
      problems->Add("`camera` at " + problems->At(root->KeyLine("camera")) + " and `camera_file` at " +
                    problems->At(file->line) + ": give the intrinsics one way, not both");
      return false;
    }
    std::string relative;
    if (!ReadString(*file, root->Path("camera_file"), problems, &relative)) return false;
    const std::string resolved =
        !relative.empty() && relative[0] == '/' ? relative : DirectoryOf(problems->file()) + "/" + relative;
    Result<CameraIntrinsics> loaded = LoadCameraFile(resolved, camera_name);
    if (!loaded.ok()) {
      problems->Add("`" + root->Path("camera_file") + "` at " + problems->At(file->line) + ": " + loaded.status().message());
      return false;
    }
    *camera = *loaded;
    return true;
  }
  if (named && root->Optional("camera_name") != nullptr) {
    problems->Add("`" + root->Path("camera_name") + "` at " + problems->At(root->KeyLine("camera_name")) +
                  " selects a camera of a `camera_file`; there is none");
  }
  const yaml::YamlNode* node = root->Required("camera");
  if (!node) return false;
  MapReader map(*node, "camera", problems);
  if (!map.ok()) return false;
  long long width = 0, height = 0;
  bool ok = map.Int("width_px", 1, 100000, &width);
  ok &= map.Int("height_px", 1, 100000, &height);
  ok &= map.Double("fx_px", Range::Positive(1e6), &camera->fx_px);
  ok &= map.OptionalDouble("mu", Range::Positive(100), &camera->mu);
  ok &= map.Double("cx_px", Range::Closed(0, 1e5), &camera->cx_px);
  ok &= map.Double("cy_px", Range::Closed(0, 1e5), &camera->cy_px);
  ok &= map.OptionalDouble("k1", Range::Closed(-10, 10), &camera->k1);
  ok &= map.OptionalDouble("k2", Range::Closed(-1000, 1000), &camera->k2);
  ok &= map.OptionalDouble("p1", Range::Closed(-1, 1), &camera->p1);
  ok &= map.OptionalDouble("p2", Range::Closed(-1, 1), &camera->p2);
  ok &= map.OptionalDouble("k3", Range::Closed(-1000, 1000), &camera->k3);
  camera->width_px = static_cast<int>(width);
  camera->height_px = static_cast<int>(height);
  if (!ok) return false;
  // Cross-field checks (principal point inside the image, ...).
  std::istringstream invalid(camera->Validate());
  for (std::string line; std::getline(invalid, line);) {
    problems->Add("`camera` at " + problems->At(node->line) + ": " + line);
    ok = false;
  }
  return ok;
}

std::string CameraYaml(const CameraIntrinsics& c) {
  std::ostringstream out;
  out << "{width_px: " << c.width_px << ", height_px: " << c.height_px << ", fx_px: " << YamlNumber(c.fx_px)
      << ", mu: " << YamlNumber(c.mu) << ", cx_px: " << YamlNumber(c.cx_px) << ", cy_px: " << YamlNumber(c.cy_px)
      << ", k1: " << YamlNumber(c.k1);
  // Written only when non-zero, so that a file of a k1-only camera reads and writes as before.
  if (c.k2 != 0) out << ", k2: " << YamlNumber(c.k2);
  if (c.p1 != 0) out << ", p1: " << YamlNumber(c.p1);
  if (c.p2 != 0) out << ", p2: " << YamlNumber(c.p2);
  if (c.k3 != 0) out << ", k3: " << YamlNumber(c.k3);
  out << "}";
  return out.str();
}

const char* IntrinsicYamlKey(int intrinsic) {
  static constexpr const char* kKeys[kNumIntrinsics] = {"fx_px", "mu", "cx_px", "cy_px", "k1", "k2", "p1", "p2", "k3"};
  return intrinsic >= 0 && intrinsic < kNumIntrinsics ? kKeys[intrinsic] : "?";
}

std::string IntrinsicsStddevYaml(const IntrinsicsVector& stddev) {
  std::string out;
  for (int k = 0; k < kNumIntrinsics; ++k) {
    if (!std::isfinite(stddev[k])) continue;
    out += (out.empty() ? "{" : ", ") + std::string(IntrinsicYamlKey(k)) + ": " + YamlNumber(stddev[k]);
  }
  return out.empty() ? out : out + "}";
}

bool ReadIntrinsicsStddev(MapReader* root, IntrinsicsVector* stddev) {
  stddev->fill(NAN);
  const yaml::YamlNode* node = root->Optional("intrinsics_stddev");
  if (node == nullptr) return true;
  MapReader map(*node, root->Path("intrinsics_stddev"), root->problems());
  if (!map.ok()) return false;
  bool ok = true;
  for (int k = 0; k < kNumIntrinsics; ++k) ok &= map.OptionalDouble(IntrinsicYamlKey(k), Range::Closed(0, 1e6), &(*stddev)[k]);
  map.Finish();
  return ok;
}

bool ReadOptionalCamera(MapReader* root, Problems* problems, std::optional<CameraIntrinsics>* camera) {
  if (root->Optional("camera") == nullptr) return true;
  CameraIntrinsics read;
  if (!ReadCamera(root, problems, &read)) return false;
  *camera = read;
  return true;
}

namespace {

bool ReadDistances(MapReader* root, const std::string& key, bool required, Problems* problems,
                   std::vector<KnownDistance>* out) {
  const yaml::YamlNode* node = required ? root->Required(key) : root->Optional(key);
  if (!node) return !required;
  if (!node->IsSequence()) {
    problems->Add("`" + key + "` at " + problems->At(node->line) + " must be a sequence of {dot_a, dot_b, length_mm} " +
                  "(found " + node->KindName() + ")");
    return false;
  }
  bool ok = true;
  for (size_t i = 0; i < node->items.size(); ++i) {
    MapReader map(node->items[i], key + "[" + std::to_string(i) + "]", problems);
    if (!map.ok()) {
      ok = false;
      continue;
    }
    long long a = -1, b = -1;
    KnownDistance d;
    ok &= map.Int("dot_a", 0, INT_MAX, &a);
    ok &= map.Int("dot_b", 0, INT_MAX, &b);
    ok &= map.Quantity("length", Unit::kLength, Range::Closed(kMinKnownDistanceM, kMaxKnownDistanceM), &d.length_m);
    d.dot_a = static_cast<int>(a);
    d.dot_b = static_cast<int>(b);
    out->push_back(d);
  }
  return ok;
}

bool ReadDots(const yaml::YamlNode& node, const std::string& name, const CameraIntrinsics* camera, Problems* problems,
              std::map<int, Eigen::Vector2d>* dots) {
  if (!node.IsSequence()) {
    problems->Add("`" + name + "` at " + problems->At(node.line) + " must be a sequence of [dot id, u_px, v_px] " +
                  "(found " + node.KindName() + ")");
    return false;
  }
  bool ok = true;
  for (size_t i = 0; i < node.items.size(); ++i) {
    const yaml::YamlNode& item = node.items[i];
    const std::string item_name = name + "[" + std::to_string(i) + "]";
    if (!item.IsSequence() || item.items.size() != 3) {
      problems->Add("`" + item_name + "` at " + problems->At(item.line) + " must be [dot id, u_px, v_px]");
      ok = false;
      continue;
    }
    long long id = -1;
    Eigen::Vector2d uv;
    if (!ReadInt(item.items[0], item_name + "[0]", 0, INT_MAX, problems, &id) ||
        !ReadDouble(item.items[1], item_name + "[1]", kPixel, problems, &uv.x()) ||
        !ReadDouble(item.items[2], item_name + "[2]", kPixel, problems, &uv.y())) {
      ok = false;
      continue;
    }
    if (camera) {
      if (const std::string p = PixelProblem(*camera, uv); !p.empty()) {
        problems->Add("dot " + std::to_string(id) + " at (" + ShortNumber(uv.x()) + ", " + ShortNumber(uv.y()) + ") px in `" +
                      item_name + "` at " + problems->At(item.line) + " " + p);
        ok = false;
      }
    }
    if (!dots->emplace(static_cast<int>(id), uv).second) {
      problems->Add("dot " + std::to_string(id) + " appears twice in `" + name + "` (again at " +
                    problems->At(item.line) + ")");
      ok = false;
    }
  }
  return ok;
}

// `joints_deg` or `joints_rad` of a pose. Values outside the robot's limits are kept: the controller's
// reading is what happened (calibrate warns, observations/joint_limits.h); only the plausible range is checked,
// and radians typed under `joints_deg` are refused (yaml_schema.h: LooksLikeRadiansUnderDegrees).
bool ReadJoints(MapReader* map, const RobotModel* robot, PoseObservation* pose) {
  std::vector<double> joints;
  const int num_joints = robot ? robot->num_joints() : -1;
  if (!map->JointAngles(num_joints, &joints)) return false;
  pose->joints_rad = Eigen::Map<const Eigen::VectorXd>(joints.data(), static_cast<Eigen::Index>(joints.size()));
  return true;
}

bool ReadPose(const yaml::YamlNode& node, const std::string& name, const RobotModel* robot, const CameraIntrinsics* camera,
              Problems* problems, PoseObservation* pose, std::vector<std::string>* notes) {
  MapReader map(node, name, problems);
  if (!map.ok()) return false;
  bool ok = map.String("id", &pose->id);
  if (ok && pose->id.empty()) {
    problems->Add("`" + map.Path("id") + "` at " + problems->At(map.KeyLine("id")) + " is empty");
    ok = false;
  }
  std::string role = "identification";
  if (map.OptionalString("role", &role)) {
    if (role == "verification") {
      pose->role = PoseRole::kVerification;
    } else if (role != "identification") {
      problems->Add("`" + map.Path("role") + "` = `" + role + "` at " + problems->At(map.KeyLine("role")) +
                    " must be identification or verification");
      ok = false;
    }
  }
  if (map.Optional("scene") != nullptr && map.OptionalString("scene", &pose->scene) && pose->scene.empty()) {
    problems->Add("`" + map.Path("scene") + "` at " + problems->At(map.KeyLine("scene")) +
                  " is empty (leave the key out for the set's one scene)");
    ok = false;
  }
  const bool has_flange = map.Optional("base_from_flange") != nullptr;
  if (has_flange) {
    // Set even when unreadable (its problem is recorded): the set is still one of flange poses.
    Rigid3 base_from_flange;
    double correction_rad = 0;
    ok &= ReadTransform(&map, "base_from_flange", /*required=*/true, &base_from_flange, &correction_rad);
    pose->base_from_flange = base_from_flange;
    if (correction_rad > 0 && notes != nullptr) {
      notes->push_back(RotationCorrectionNote(problems->At(map.KeyLine("base_from_flange")), pose->id, correction_rad));
    }
    for (const char* joint_key : {"joints_deg", "joints_rad"}) {
      if (map.Optional(joint_key)) {
        problems->Add("`" + map.Path(joint_key) + "` at " + problems->At(map.KeyLine(joint_key)) +
                      " and `base_from_flange` both give the pose; keep one");
        ok = false;
      }
    }
  } else {
    ok &= ReadJoints(&map, robot, pose);
  }
  if (const yaml::YamlNode* dots = map.Required("dots")) {
    ok &= ReadDots(*dots, map.Path("dots"), camera, problems, &pose->dots_px);
  } else {
    ok = false;
  }
  return ok;
}

// The top-level `configuration` into *mount (left as it is when absent): eye_in_hand or eye_to_hand, and
// the same as a calibrated robot's (`robot`, null when none was read) when that says eye_to_hand.
bool ReadConfiguration(MapReader* root, Problems* problems, const RobotModel* robot, CameraMount* mount) {
  if (root->Optional("configuration") == nullptr) return true;
  std::string name;
  if (!root->OptionalString("configuration", &name)) return false;
  const std::string at = problems->At(root->KeyLine("configuration"));
  if (!ParseCameraMount(name, mount)) {
    problems->Add("`configuration` = `" + name + "` at " + at + " must be eye_in_hand or eye_to_hand");
    return false;
  }
  if (robot != nullptr && robot->mount == CameraMount::kEyeToHand && *mount != robot->mount) {
    problems->Add("`configuration` = `" + name + "` at " + at + ", but the robot is a calibrated " +
                  CameraMountName(robot->mount) + " model");
    return false;
  }
  return true;
}

// The top-level camera key of the other configuration is refused: an eye_to_hand set's camera is the fixed
// `base_from_cam`, an eye_in_hand set's the camera on the flange, `flange_from_cam`.
bool CameraKeyFitsConfiguration(MapReader* root, Problems* problems, CameraMount mount) {
  const bool eye_to_hand = mount == CameraMount::kEyeToHand;
  const char* wrong = eye_to_hand ? "flange_from_cam" : "base_from_cam";
  if (root->Optional(wrong) == nullptr) return true;
  const bool stated = root->Optional("configuration") != nullptr;
  problems->Add("`" + std::string(wrong) + "` at " + problems->At(root->KeyLine(wrong)) + " does not fit `configuration: " +
                CameraMountName(mount) + "`" + (stated ? " (at " + problems->At(root->KeyLine("configuration")) + ")" : " (the default)") +
                (eye_to_hand ? ": an eye_to_hand set's camera is fixed in the base frame, given as `base_from_cam`; the "
                               "flange carries the points"
                             : ": `base_from_cam` is the fixed camera of an eye_to_hand set; add `configuration: "
                               "eye_to_hand` if the camera does not move with the flange"));
  return false;
}

}  // namespace

namespace {

// The file's line of every subject ObservationSet::Validate names: "pose <id>" (the line of the id; of the
// later one for a repeated id), "yardstick <a>-<b>" and "check distance <a>-<b>" (the entry's line).
std::map<std::string, int> SubjectLines(const yaml::YamlNode& root, const ObservationSet& set) {
  std::map<std::string, int> lines;
  if (const yaml::YamlNode* poses = root.IsMap() ? root.Find("poses") : nullptr; poses && poses->IsSequence()) {
    for (size_t i = 0; i < poses->items.size() && i < set.poses.size(); ++i) {
      const yaml::YamlNode* id = poses->items[i].IsMap() ? poses->items[i].Find("id") : nullptr;
      lines["pose " + set.poses[i].id] = id != nullptr ? id->line : poses->items[i].line;
    }
  }
  auto distances = [&](const char* key, const char* what, const std::vector<KnownDistance>& list) {
    const yaml::YamlNode* node = root.IsMap() ? root.Find(key) : nullptr;
    if (node == nullptr || !node->IsSequence()) return;
    for (size_t k = 0; k < node->items.size() && k < list.size(); ++k) {
      lines.emplace(std::string(what) + " " + std::to_string(list[k].dot_a) + "-" + std::to_string(list[k].dot_b),
                    node->items[k].line);
    }
  };
  distances("yardsticks", "yardstick", set.yardsticks);
  distances("check_distances", "check distance", set.check_distances);
  return lines;
}

// The line of the subject a problem of ObservationSet::Validate starts with ("pose p03: ...",
// "pose p03, dot 7: ...", "yardstick 0-1: ..."), or 0.
int LineOfSubject(const std::map<std::string, int>& lines, const std::string& problem) {
  const size_t end = problem.find_first_of(":,");
  if (end == std::string::npos) return 0;
  const auto it = lines.find(problem.substr(0, end));
  return it != lines.end() ? it->second : 0;
}

}  // namespace

Result<ObservationSet> ParseObservations(const yaml::YamlDocument& doc, std::vector<std::string>* notes) {
  Problems problems(doc.path);
  MapReader root(doc.root, "", &problems);
  if (!CheckFormatAndVersion(&root, kObservationsFormat, kObservationsVersion)) {
    root.Abandon();
    return problems.ToStatus("observations");
  }
  ObservationSet set;
  bool robot_ok = false;
  const yaml::YamlNode* robot = root.Optional("robot");
  const yaml::YamlNode* robot_file = root.Optional("robot_file");
  if (robot && robot_file) {
    problems.Add("both `robot` and `robot_file` given at " + problems.At(root.KeyLine("robot_file")) + "; keep one");
  } else if (robot) {
    const size_t before = problems.size();
    set.robot = ParseRobotModel(*robot, "robot", &problems).model;
    robot_ok = problems.size() == before;
  } else if (robot_file) {
    std::string relative;
    if (ReadString(*robot_file, "robot_file", &problems, &relative)) {
      const std::string resolved = !relative.empty() && relative[0] == '/' ? relative : DirectoryOf(doc.path) + "/" + relative;
      Result<RobotModel> loaded = LoadRobotModel(resolved);
      if (loaded.ok()) {
        set.robot = *loaded;
        robot_ok = true;
      } else {
        problems.Add("`robot_file` at " + problems.At(robot_file->line) + ": " + loaded.status().message());
      }
    }
  }
  const bool robot_given = robot || robot_file;
  // The robot's own configuration (eye_in_hand for every robot config; a calibrated eye-to-hand model's
  // otherwise) unless the file says which.
  const RobotModel robot_read = set.robot;
  CameraMount mount = robot_ok ? robot_read.mount : CameraMount::kEyeInHand;
  const bool mount_ok = ReadConfiguration(&root, &problems, robot_ok ? &robot_read : nullptr, &mount);
  const bool eye_to_hand = mount == CameraMount::kEyeToHand;
  Rigid3 flange_from_cam;
  if (mount_ok && !CameraKeyFitsConfiguration(&root, &problems, mount)) {
    // refused, named by CameraKeyFitsConfiguration
  } else if (robot_given && !eye_to_hand && root.Optional("flange_from_cam")) {
    problems.Add("`flange_from_cam` at " + problems.At(root.KeyLine("flange_from_cam")) +
                 " is for sets of flange poses; with a robot it belongs in the robot's block");
  } else if (!robot_given) {
    set.flange_from_cam_known = !eye_to_hand && root.Optional("flange_from_cam") != nullptr;
    if (const yaml::YamlNode* noise = root.Optional("flange_pose_noise")) {
      MapReader map(*noise, "flange_pose_noise", &problems);
      map.Quantity("translation", Unit::kLength, Range::Positive(0.1), &set.flange_translation_sigma_m);
      map.Quantity("rotation", Unit::kAngle, Range::Positive(DegToRad(10)), &set.flange_rotation_sigma_rad);
    }
    if (!eye_to_hand) ReadTransform(&root, "flange_from_cam", /*required=*/false, &flange_from_cam);
    set.robot = FlangePoseModel(flange_from_cam);
  }
  set.robot.mount = mount;
  if (eye_to_hand) {
    // The nominal fixed camera: given here, else a calibrated eye-to-hand robot's, else started from the images.
    const bool given = root.Optional("base_from_cam") != nullptr;
    ReadTransform(&root, "base_from_cam", /*required=*/false, &set.robot.base_from_cam);
    set.flange_from_cam_known = given || (robot_ok && robot_read.mount == CameraMount::kEyeToHand);
  }
  const bool camera_ok = ReadCamera(&root, &problems, &set.camera);
  root.Double("pixel_noise_px", Range::Closed(kMinPixelNoisePx, kMaxPixelNoisePx), &set.pixel_noise_px);
  // A set of flange poses takes its scale from the flange translations: yardsticks are then optional.
  ReadDistances(&root, "yardsticks", /*required=*/robot_given, &problems, &set.yardsticks);
  ReadDistances(&root, "check_distances", /*required=*/false, &problems, &set.check_distances);
  if (const yaml::YamlNode* poses = root.Required("poses")) {
    if (!poses->IsSequence()) {
      problems.Add("`poses` at " + problems.At(poses->line) + " must be a sequence of poses (found " +
                   poses->KindName() + ")");
    } else {
      set.poses.resize(poses->items.size());
      for (size_t i = 0; i < poses->items.size(); ++i) {
        ReadPose(poses->items[i], "poses[" + std::to_string(i) + "]", robot_ok ? &set.robot : nullptr,
                 camera_ok ? &set.camera : nullptr, &problems, &set.poses[i], notes);
      }
    }
  }
  if (!robot_given && !set.UsesFlangePoses()) {
    root.AddMissing("`robot` (or `robot_file`), or `base_from_flange` in every pose");
  }
  root.Finish();
  if (problems.empty()) {
    // The set's own checks name a pose or a distance; the file's line of that pose or distance is added.
    const std::map<std::string, int> lines = SubjectLines(doc.root, set);
    std::istringstream invalid(set.Validate());
    for (std::string line; std::getline(invalid, line);) {
      const int at = LineOfSubject(lines, line);
      problems.Add((at > 0 ? problems.At(at) : doc.path) + ": " + line);
    }
  }
  if (!problems.empty()) return problems.ToStatus("observations");
  return set;
}

Result<ObservationSet> LoadObservations(const std::string& path) {
  Result<yaml::YamlDocument> doc = yaml::LoadYamlFile(path);
  if (!doc.ok()) return doc.status();
  return ParseObservations(*doc);
}

Status SaveObservations(const ObservationSet& set, const std::string& path) {
  std::string problems = set.Validate();
  for (const auto* list : {&set.yardsticks, &set.check_distances}) {
    for (const KnownDistance& k : *list) {
      if (!(k.length_m >= kMinKnownDistanceM && k.length_m <= kMaxKnownDistanceM)) {
        problems += (list == &set.yardsticks ? "yardstick " : "check distance ") + std::to_string(k.dot_a) + "-" +
                    std::to_string(k.dot_b) + ": length " + YamlNumber(k.length_m) + " m is not in [" +
                    YamlNumber(kMinKnownDistanceM) + ", " + YamlNumber(kMaxKnownDistanceM) + "] m\n";
      }
    }
  }
  if (problems.empty()) {
    for (const PoseObservation& pose : set.poses) {
      for (const auto& [dot, uv] : pose.dots_px) {
        const std::string p = PixelProblem(set.camera, uv);
        if (!p.empty()) problems += "pose " + pose.id + ", dot " + std::to_string(dot) + ": " + p + "\n";
      }
    }
  }
  if (!problems.empty()) {
    return Status::Error(ErrorCode::kInvalidInput, "refusing to write invalid observations to " + path + ":\n" + problems);
  }
  const CameraIntrinsics& c = set.camera;
  std::ostringstream out;
  out << "# selfcal observations (docs/observations-format.md), written in SI units (m, rad) so that the\n"
      << "# file loads back bit-identical. Pixels: origin at the centre of the top-left pixel, u right, v down.\n"
      << "format: " << kObservationsFormat << "\n";
  // Version 1.1 added flange poses, 1.2 the eye-to-hand configuration; a set of joint angles seen by a camera
  // on the flange stays readable by every 1.x reader.
  const bool eye_to_hand = set.robot.mount == CameraMount::kEyeToHand;
  out << "version: " << (eye_to_hand ? "1.2" : set.UsesFlangePoses() ? "1.1" : std::to_string(kObservationsVersion)) << "\n";
  if (eye_to_hand) {
    out << "configuration: " << CameraMountName(set.robot.mount) << "\n";
    if (set.flange_from_cam_known) out << "base_from_cam: " << TransformYaml(set.robot.base_from_cam, TransformStyle::kExact) << "\n";
  }
  if (set.UsesFlangePoses()) {
    if (set.flange_translation_sigma_m > 0) {
      out << "flange_pose_noise: {translation_m: " << YamlNumber(set.flange_translation_sigma_m)
          << ", rotation_rad: " << YamlNumber(set.flange_rotation_sigma_rad) << "}\n";
    }
    if (set.flange_from_cam_known && !eye_to_hand) {
      out << "flange_from_cam: " << TransformYaml(set.robot.flange_from_cam, TransformStyle::kExact) << "\n";
    }
  } else {
    out << "robot:\n" << RobotModelYaml(set.robot, TransformStyle::kExact, 2);
  }
  out << "camera: " << CameraYaml(c) << "\n"
      << "pixel_noise_px: " << YamlNumber(set.pixel_noise_px) << "\n";
  const auto distances = [&](const char* key, const std::vector<KnownDistance>& list) {
    out << key << ":" << (list.empty() ? " []\n" : "\n");
    for (const KnownDistance& d : list) {
      out << "  - {dot_a: " << d.dot_a << ", dot_b: " << d.dot_b << ", length_m: " << YamlNumber(d.length_m) << "}\n";
    }
  };
  distances("yardsticks", set.yardsticks);
  distances("check_distances", set.check_distances);
  out << "poses:" << (set.poses.empty() ? " []\n" : "\n");
  for (const PoseObservation& pose : set.poses) {
    out << "  - id: " << YamlQuoted(pose.id) << "\n"
        << "    role: " << PoseRoleName(pose.role) << "\n";
    if (!pose.scene.empty()) out << "    scene: " << YamlQuoted(pose.scene) << "\n";
    if (pose.base_from_flange) {
      out << "    base_from_flange: " << TransformYaml(*pose.base_from_flange, TransformStyle::kExact) << "\n";
    } else {
      out << "    joints_rad: " << YamlNumberList(pose.joints_rad) << "\n    # joints_deg (rounded): [";
      for (int j = 0; j < pose.joints_rad.size(); ++j) out << (j ? ", " : "") << ShortNumber(RadToDeg(pose.joints_rad[j]));
      out << "]\n";
    }
    out << "    dots:" << (pose.dots_px.empty() ? " []\n" : "\n");
    for (const auto& [dot, uv] : pose.dots_px) {
      out << "      - [" << dot << ", " << YamlNumber(uv.x()) << ", " << YamlNumber(uv.y()) << "]\n";
    }
  }
  return WriteFileAtomically(path, out.str());
}

}  // namespace selfcal::io
