#include "io/trajectory_file.h"

#include <cmath>
#include <sstream>

#include "base/short_number.h"
#include "io/atomic_file.h"
#include "io/observations_file.h"
#include "io/transform_yaml.h"
#include "yaml/yaml_reader.h"
#include "io/yaml_schema.h"
#include "io/yaml_writer.h"

namespace selfcal::io {

namespace {

// A list of points `key` ([x, y, z] in mm) of the map.
bool ReadPointsMm(MapReader* map, const std::string& key, bool required, Problems* problems,
                  std::vector<Eigen::Vector3d>* out) {
  const yaml::YamlNode* list = required ? map->Required(key) : map->Optional(key);
  if (list == nullptr) return !required;
  if (!list->IsSequence()) {
    problems->Add("`" + map->Path(key) + "` at " + problems->At(list->line) + " must be a sequence of [x, y, z] rows");
    return false;
  }
  bool ok = true;
  for (size_t i = 0; i < list->items.size(); ++i) {
    std::vector<double> p;
    if (ReadDoubleList(list->items[i], map->Path(key) + "[" + std::to_string(i) + "]", 3, Range::Closed(-100, 100),
                       problems, &p, KeyUnit::kMillimetre)) {
      out->emplace_back(p[0], p[1], p[2]);
    } else {
      ok = false;
    }
  }
  return ok;
}

// The optional `planned_for` block (docs/trajectory-format.md).
void ReadPlannedFor(MapReader* root, Problems* problems, std::optional<planning::PlannedFor>* out) {
  const yaml::YamlNode* node = root->Optional("planned_for");
  if (node == nullptr) return;
  MapReader map(*node, "planned_for", problems);
  if (!map.ok()) return;
  planning::PlannedFor p;
  planning::PlanConstraints& c = p.constraints;
  bool ok = ReadCamera(&map, problems, &p.camera);
  ok &= map.Quantity("joint_margin", Unit::kAngle, Range::Closed(0, kPi), &c.joint_margin_rad);
  ok &= map.Double("image_margin_px", Range::Closed(0, 1e5), &c.image_margin_px);
  ok &= map.Quantity("min_depth", Unit::kLength, Range::Positive(1e3), &c.min_depth_m);
  ok &= map.Quantity("max_depth", Unit::kLength, Range::Positive(1e3), &c.max_depth_m);
  ok &= map.Quantity("min_spread", Unit::kLength, Range::Closed(0, 1e3), &c.min_spread_m);
  ok &= map.Double("min_axis_sine", Range::Closed(0, 0.999), &c.min_axis_sine);
  ok &= map.Quantity("max_joint_travel", Unit::kAngle, Range::Positive(2 * kPi), &c.max_joint_travel_rad);
  ok &= map.Double("max_image_motion_px", Range::Positive(1e5), &c.max_image_motion_px);
  ok &= map.Double("max_fx_stddev_rel", Range::Positive(1), &c.max_fx_stddev_rel);
  ok &= map.Double("pixel_noise_px", Range::Closed(kMinPixelNoisePx, kMaxPixelNoisePx), &c.pixel_noise_px);
  long long min_poses = 0;
  ok &= map.Int("min_identification_poses", 3, 100000, &min_poses);
  c.min_identification_poses = static_cast<int>(min_poses);
  ok &= map.Double("max_condition_number", Range::Positive(1e300), &c.max_condition_number);
  ok &= ReadPointsMm(&map, "scene_dots_mm", true, problems, &p.scene.dots_in_base);
  ok &= ReadPointsMm(&map, "scene_extent_mm", false, problems, &p.scene.extent_in_base);
  std::string configuration = CameraMountName(CameraMount::kEyeInHand);
  if (map.OptionalString("configuration", &configuration) && !ParseCameraMount(configuration, &p.configuration)) {
    problems->Add("`planned_for.configuration` at " + problems->At(node->line) + ": \"" + configuration +
                  "\" is neither eye_in_hand nor eye_to_hand");
    ok = false;
  }
  ok &= ReadTransform(&map, "base_from_cam", p.configuration == CameraMount::kEyeToHand, &p.base_from_cam);
  map.Finish();
  if (p.scene.extent_in_base.empty()) p.scene.extent_in_base = p.scene.dots_in_base;
  if (ok) {
    std::istringstream invalid(c.Validate() + "\n" + p.scene.Validate());
    for (std::string line; std::getline(invalid, line);) {
      if (!line.empty()) problems->Add("`planned_for` at " + problems->At(node->line) + ": " + line);
    }
    *out = std::move(p);
  }
}

std::string PointsMm(const std::vector<Eigen::Vector3d>& points) {
  std::ostringstream out;
  for (const Eigen::Vector3d& x : points) out << "    - " << YamlNumberList(Eigen::VectorXd(x * 1e3)) << "\n";
  return out.str();
}

// The `planned_for` block as SaveTrajectoryFile writes it.
std::string PlannedForYaml(const planning::PlannedFor& p) {
  const CameraIntrinsics& k = p.camera;
  const planning::PlanConstraints& c = p.constraints;
  std::ostringstream out;
  out << "planned_for:\n"
      << "  camera: " << CameraYaml(k) << "\n"
      << "  joint_margin_rad: " << YamlNumber(c.joint_margin_rad) << "\n"
      << "  image_margin_px: " << YamlNumber(c.image_margin_px) << "\n"
      << "  min_depth_m: " << YamlNumber(c.min_depth_m) << "\n"
      << "  max_depth_m: " << YamlNumber(c.max_depth_m) << "\n"
      << "  min_spread_m: " << YamlNumber(c.min_spread_m) << "\n"
      << "  min_axis_sine: " << YamlNumber(c.min_axis_sine) << "\n"
      << "  max_joint_travel_rad: " << YamlNumber(c.max_joint_travel_rad) << "\n"
      << "  max_image_motion_px: " << YamlNumber(c.max_image_motion_px) << "\n"
      << "  max_fx_stddev_rel: " << YamlNumber(c.max_fx_stddev_rel) << "\n"
      << "  pixel_noise_px: " << YamlNumber(c.pixel_noise_px) << "\n"
      << "  min_identification_poses: " << c.min_identification_poses << "\n"
      << "  max_condition_number: " << YamlNumber(c.max_condition_number) << "\n";
  if (p.scene.extent_in_base != p.scene.dots_in_base) out << "  scene_extent_mm:\n" << PointsMm(p.scene.extent_in_base);
  out << "  scene_dots_mm:\n" << PointsMm(p.scene.dots_in_base);
  if (p.configuration == CameraMount::kEyeToHand) {  // eye-in-hand plans keep their earlier bytes
    out << "  configuration: " << CameraMountName(p.configuration) << "\n"
        << "  base_from_cam: " << TransformYaml(p.base_from_cam, TransformStyle::kExact) << "\n";
  }
  return out.str();
}

// `robot` (optional): also the joint limits and the robot name as problems of the file. `for_robot`
// (optional): a file for another robot is refused at once, naming both (LoadTrajectoryFileForRobot).
struct ForRobot {
  const RobotModel* robot;
  const std::string* config_path;
};

Status OtherRobot(const std::string& path, const std::string& line, const std::string& named, const ForRobot& r) {
  return Status::Error(ErrorCode::kInvalidInput,
                       "trajectory " + path + " is for robot `" + named + "` (`robot` at " + line + "), but the robot config " +
                           *r.config_path + " is robot `" + r.robot->name + "`: give the trajectory made for `" +
                           r.robot->name + "` (shipped: " + InitialTrajectoryPath(r.robot->name) +
                           ") or plan one with `selfcal plan --robot " + *r.config_path + "`");
}

// Radians typed under `poses_deg` (yaml_schema.h): a file has one unit, so all rows are looked at together.
void CheckDegreeRows(const std::vector<Eigen::VectorXd>& poses, const yaml::YamlNode& list, const std::string& key_at,
                     Problems* problems) {
  std::vector<double> all;
  for (const Eigen::VectorXd& pose : poses) all.insert(all.end(), pose.data(), pose.data() + pose.size());
  if (poses.empty() || !LooksLikeRadiansUnderDegrees(all)) return;
  const std::vector<double> first(poses.front().data(), poses.front().data() + poses.front().size());
  problems->Add(RadiansUnderDegreesProblem("poses_deg[0]", problems->At(list.items.front().line), first, "poses_rad") +
                "; so do all " + std::to_string(poses.size()) + " rows of `poses_deg` at " + key_at);
}

Result<TrajectoryFile> Load(const std::string& path, int num_joints, const RobotModel* robot,
                            const ForRobot* for_robot = nullptr) {
  Result<yaml::YamlDocument> doc = yaml::LoadYamlFile(path);
  if (!doc.ok()) return doc.status();
  Problems problems(path);
  MapReader root(doc->root, "", &problems);
  if (!CheckFormatAndVersion(&root, kTrajectoryFormat, kTrajectoryVersion)) {
    root.Abandon();
    return problems.ToStatus("trajectory");
  }
  TrajectoryFile file;
  std::string& robot_name = file.robot;
  root.OptionalName("robot", &robot_name);
  if (for_robot && !robot_name.empty() && robot_name != for_robot->robot->name) {
    const std::string line = problems.At(root.KeyLine("robot"));
    root.Abandon();
    return OtherRobot(path, line, robot_name, *for_robot);
  }
  root.OptionalString("description", &file.description);
  root.OptionalString("planner", &file.planner);
  if (root.Optional("num_identification_poses")) {
    long long count = 0;
    if (root.Int("num_identification_poses", 3, 100000, &count)) file.num_identification_poses = static_cast<int>(count);
  }
  ReadPlannedFor(&root, &problems, &file.planned_for);
  if (robot && !robot_name.empty() && robot_name != robot->name) {
    problems.Add("`robot` = `" + robot_name + "` at " + problems.At(root.KeyLine("robot")) +
                 ", but the robot model is `" + robot->name + "`");
  }
  std::vector<Eigen::VectorXd> poses;
  root.Disallow("poses", "the unit goes in the key: `poses_deg` or `poses_rad`");
  const yaml::YamlNode* deg = root.Optional("poses_deg");
  const yaml::YamlNode* rad = root.Optional("poses_rad");
  if (deg && rad) {
    problems.Add("both `poses_deg` and `poses_rad` given at " + problems.At(root.KeyLine("poses_rad")) + "; keep one");
  } else if (!deg && !rad) {
    if (!root.Optional("poses")) root.AddMissing("`poses_deg` (or `poses_rad`)");
  } else {
    const yaml::YamlNode& list = deg ? *deg : *rad;
    const std::string key = deg ? "poses_deg" : "poses_rad";
    if (!list.IsSequence()) {
      problems.Add("`" + key + "` at " + problems.At(list.line) + " must be a sequence of joint-angle rows (found " +
                   list.KindName() + ")");
    } else if (list.items.empty()) {  // a run, a simulation and a plan check all start at the first pose
      problems.Add("`" + key + "` at " + problems.At(list.line) + " is empty: a plan needs at least one pose");
    } else if (list.items.size() > static_cast<size_t>(kMaxTrajectoryPoses)) {
      problems.Add("`" + key + "` at " + problems.At(list.line) + " holds " + std::to_string(list.items.size()) +
                   " poses, more than the limit of " + std::to_string(kMaxTrajectoryPoses) + " poses per plan");
    }
    for (size_t i = 0; list.IsSequence() && i < list.items.size() && i < static_cast<size_t>(kMaxTrajectoryPoses);
         ++i) {
      const yaml::YamlNode& row = list.items[i];
      const std::string name = key + "[" + std::to_string(i) + "]";
      if (row.IsSequence() && static_cast<int>(row.items.size()) != num_joints) {
        problems.Add("pose " + std::to_string(i) + " (`" + name + "` at " + problems.At(row.line) + ") has " +
                     std::to_string(row.items.size()) + " joint values, the robot has " + std::to_string(num_joints));
        continue;
      }
      std::vector<double> q;
      if (!ReadDoubleList(row, name, num_joints, Range::Closed(DegToRad(-720), DegToRad(720)), &problems, &q,
                          deg ? KeyUnit::kDegree : KeyUnit::kSi)) {
        continue;
      }
      Eigen::VectorXd pose = Eigen::Map<const Eigen::VectorXd>(q.data(), num_joints);
      for (int j = 0; robot && j < num_joints; ++j) {
        const JointLimits& l = robot->limits[j];
        if (pose[j] < l.min_rad || pose[j] > l.max_rad) {
          problems.Add("pose " + std::to_string(i) + " (`" + name + "` at " + problems.At(row.items[j].line) +
                       "): joint " + std::to_string(j + 1) + " = " + ShortNumber(RadToDeg(pose[j])) + " deg is outside its limits [" +
                       ShortNumber(RadToDeg(l.min_rad)) + ", " + ShortNumber(RadToDeg(l.max_rad)) + "] deg");
        }
      }
      poses.push_back(pose);
    }
    if (deg) CheckDegreeRows(poses, list, problems.At(root.KeyLine("poses_deg")), &problems);
  }
  root.Finish();
  if (file.num_identification_poses > static_cast<int>(poses.size()) && problems.empty()) {
    problems.Add("`num_identification_poses` = " + std::to_string(file.num_identification_poses) + " at " +
                 problems.At(root.KeyLine("num_identification_poses")) + " exceeds the " + std::to_string(poses.size()) +
                 " poses");
  }
  if (!problems.empty()) return problems.ToStatus("trajectory");
  file.poses = std::move(poses);
  return file;
}

}  // namespace

planning::PlanSubject PlanSubjectOf(const TrajectoryFile& file) {
  planning::PlanSubject plan;
  plan.robot = file.robot;
  plan.poses = file.poses;
  plan.num_identification_poses = file.num_identification_poses;
  plan.planned_for = file.planned_for;
  return plan;
}

Result<TrajectoryFile> LoadTrajectoryFile(const std::string& path, int num_joints) {
  if (num_joints <= 0) return Status::Error(ErrorCode::kInvalidInput, "LoadTrajectory(" + path + "): num_joints must be > 0");
  return Load(path, num_joints, nullptr);
}

Result<TrajectoryFile> LoadTrajectoryFile(const std::string& path, const RobotModel& robot) {
  if (robot.num_joints() <= 0 || robot.limits.size() != robot.links.size()) {
    return Status::Error(ErrorCode::kInvalidInput, "LoadTrajectory(" + path + "): the robot model has no joints or no limits");
  }
  return Load(path, robot.num_joints(), &robot);
}

Result<TrajectoryFile> LoadTrajectoryFileForRobot(const std::string& path, const RobotModel& robot,
                                                  const std::string& robot_path) {
  if (robot.num_joints() <= 0) return Status::Error(ErrorCode::kInvalidInput, "LoadTrajectory(" + path + "): the robot has no joints");
  const ForRobot for_robot{&robot, &robot_path};
  return Load(path, robot.num_joints(), nullptr, &for_robot);
}

std::string InitialTrajectoryPath(const std::string& robot_name) {
  return "config/trajectories/initial_" + robot_name + ".yaml";
}

Result<std::vector<Eigen::VectorXd>> LoadTrajectory(const std::string& path, int num_joints) {
  Result<TrajectoryFile> file = LoadTrajectoryFile(path, num_joints);
  if (!file.ok()) return file.status();
  return file->poses;
}

Result<std::vector<Eigen::VectorXd>> LoadTrajectory(const std::string& path, const RobotModel& robot) {
  Result<TrajectoryFile> file = LoadTrajectoryFile(path, robot);
  if (!file.ok()) return file.status();
  return file->poses;
}

Status SaveTrajectory(const std::vector<Eigen::VectorXd>& poses_rad, const std::string& path,
                      const std::string& robot_name, const std::string& description) {
  TrajectoryFile file;
  file.poses = poses_rad;
  file.robot = robot_name;
  file.description = description;
  return SaveTrajectoryFile(file, path);
}

Status SaveTrajectoryFile(const TrajectoryFile& file, const std::string& path) {
  const std::vector<Eigen::VectorXd>& poses_rad = file.poses;
  const std::string& robot_name = file.robot;
  const std::string& description = file.description;
  for (size_t i = 0; i < poses_rad.size(); ++i) {
    if (!poses_rad[i].allFinite() || poses_rad[i].size() != poses_rad.front().size() || poses_rad[i].size() == 0) {
      return Status::Error(ErrorCode::kInvalidInput, "refusing to write trajectory " + path + ": pose " + std::to_string(i) +
                                                 " is empty, not finite, or has a different joint count");
    }
  }
  std::ostringstream out;
  out << "# selfcal trajectory (docs/trajectory-format.md); joint angles in radians, degrees in comments.\n"
      << "format: " << kTrajectoryFormat << "\n"
      << "version: " << kTrajectoryVersion << "\n";
  if (!robot_name.empty()) out << "robot: " << YamlQuoted(robot_name) << "\n";
  if (!description.empty()) out << "description: " << YamlQuoted(description) << "\n";
  if (!file.planner.empty()) out << "planner: " << YamlQuoted(file.planner) << "\n";
  if (file.num_identification_poses > 0) out << "num_identification_poses: " << file.num_identification_poses << "\n";
  if (file.planned_for) out << PlannedForYaml(*file.planned_for);
  out << "poses_rad:" << (poses_rad.empty() ? " []\n" : "\n");
  for (size_t i = 0; i < poses_rad.size(); ++i) {
    out << "  - " << YamlNumberList(poses_rad[i]) << "  # " << i << ": [";
    for (int j = 0; j < poses_rad[i].size(); ++j) out << (j ? ", " : "") << ShortNumber(RadToDeg(poses_rad[i][j]));
    out << "] deg\n";
  }
  return WriteFileAtomically(path, out.str());
}

}  // namespace selfcal::io
