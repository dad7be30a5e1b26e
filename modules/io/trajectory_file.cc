#include "io/trajectory_file.h"

#include <cmath>
#include <cstdio>
#include <sstream>

#include "io/atomic_file.h"
#include "yaml/yaml_reader.h"
#include "io/yaml_schema.h"
#include "io/yaml_writer.h"

namespace selfcal::io {

namespace {

std::string Short(double v) {
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%.6g", v);
  return buffer;
}

Result<TrajectoryFile> Load(const std::string& path, int num_joints, const RobotModel* robot) {
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
  root.OptionalString("robot", &robot_name);
  root.OptionalString("description", &file.description);
  root.OptionalString("planner", &file.planner);
  if (root.Optional("num_identification_poses")) {
    long long count = 0;
    if (root.Int("num_identification_poses", 3, 100000, &count)) file.num_identification_poses = static_cast<int>(count);
  }
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
    }
    for (size_t i = 0; list.IsSequence() && i < list.items.size(); ++i) {
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
                       "): joint " + std::to_string(j + 1) + " = " + Short(RadToDeg(pose[j])) + " deg is outside its limits [" +
                       Short(RadToDeg(l.min_rad)) + ", " + Short(RadToDeg(l.max_rad)) + "] deg");
        }
      }
      poses.push_back(pose);
    }
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
  out << "poses_rad:" << (poses_rad.empty() ? " []\n" : "\n");
  for (size_t i = 0; i < poses_rad.size(); ++i) {
    out << "  - " << YamlNumberList(poses_rad[i]) << "  # " << i << ": [";
    for (int j = 0; j < poses_rad[i].size(); ++j) out << (j ? ", " : "") << Short(RadToDeg(poses_rad[i][j]));
    out << "] deg\n";
  }
  return WriteFileAtomically(path, out.str());
}

}  // namespace selfcal::io
