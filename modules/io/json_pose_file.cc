#include "io/json_pose_file.h"

#include <cmath>
#include <cstdio>
#include <vector>

#include <Eigen/Geometry>
#include <nlohmann/json.hpp>

#include "base/atomic_file.h"
#include "base/closest_name.h"
#include "base/json_lines.h"
#include "geometry/rigid3.h"
#include "io/plausible_limits.h"
#include "io/pose_files.h"
#include "io/report_json.h"
#include "io/transform_yaml.h"
#include "yaml/yaml_reader.h"

namespace selfcal::io {

namespace {

constexpr double kMaxJointRad = 4 * kPi;

std::string Short(double v) {
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%.6g", v);
  return buffer;
}

// One JSON pose file's text, its document and the lines of its keys, for messages naming `file:line`.
class JsonPoseReader {
 public:
  JsonPoseReader(std::string path, nlohmann::json document, const std::string& text)
      : path_(std::move(path)), document_(std::move(document)), lines_(text) {}

  Status Error(const std::string& key, const std::string& message) const {
    return Status::Error(ErrorCode::kInvalidInput,
                         path_ + ":" + std::to_string(lines_.Line(JsonLines::Member("", key))) + ": " + message);
  }

  // The value of `key` (named by `option` in messages): refused when absent, with the nearest key.
  Result<const nlohmann::json*> Value(const std::string& key, const std::string& option) const {
    if (!document_.is_object()) {
      return Status::Error(ErrorCode::kInvalidInput, path_ + ":1: a JSON pose file must be an object of keys");
    }
    const auto it = document_.find(key);
    if (it != document_.end()) return &*it;
    std::vector<std::string> keys;
    for (const auto& item : document_.items()) keys.push_back(item.key());
    const std::string near = ClosestName(key, keys);
    std::string list;
    for (const std::string& k : keys) list += (list.empty() ? "" : ", ") + k;
    return Status::Error(ErrorCode::kInvalidInput,
                         path_ + ":1: no key `" + key + "` (" + option + ")" +
                             (near.empty() ? "" : "; did you mean `" + near + "`?") + " The file's keys: " + list);
  }

  // `size` finite numbers under `key` (flat, or with `rows` > 0 also `rows` lists of size / rows).
  Result<std::vector<double>> Numbers(const std::string& key, const std::string& option, size_t size, size_t rows,
                                      const std::string& what) const {
    Result<const nlohmann::json*> value = Value(key, option);
    if (!value.ok()) return value.status();
    const nlohmann::json& v = **value;
    std::vector<double> out;
    bool ok = v.is_array();
    const bool nested = ok && rows > 0 && !v.empty() && v.front().is_array();
    for (size_t i = 0; ok && i < v.size(); ++i) {
      if (nested) {
        ok = v[i].is_array() && v.size() == rows && v[i].size() == size / rows;
        for (size_t j = 0; ok && j < v[i].size(); ++j) {
          ok = v[i][j].is_number();
          if (ok) out.push_back(v[i][j].get<double>());
        }
      } else {
        ok = v[i].is_number();
        if (ok) out.push_back(v[i].get<double>());
      }
    }
    if (!ok || out.size() != size) {
      const std::string got = v.is_array() ? std::to_string(v.size()) + (nested ? " rows" : " numbers")
                                           : std::string("a ") + v.type_name();
      return Error(key, "`" + key + "` has " + got + "; " + what);
    }
    for (double x : out) {
      if (!std::isfinite(x)) return Error(key, "`" + key + "` holds a number that is not finite");
    }
    return out;
  }

 private:
  std::string path_;
  nlohmann::json document_;
  JsonLines lines_;
};

Status ReadJoints(const JsonPoseReader& reader, const JsonPoseKeys& keys, const RobotModel* robot, ImagePose* out) {
  if (robot == nullptr) {
    return reader.Error(keys.joints, "joint angles (--pose-joints-key " + keys.joints +
                                         ") need the robot's config (selfcal detect --robot)");
  }
  const size_t n = static_cast<size_t>(robot->num_joints());
  Result<std::vector<double>> q = reader.Numbers(keys.joints, "--pose-joints-key", n, 0,
                                                 "the robot has " + std::to_string(n) + " joints");
  if (!q.ok()) return q.status();
  out->joints_rad.resize(static_cast<Eigen::Index>(n));
  for (size_t i = 0; i < n; ++i) {
    const double rad = keys.joints_deg ? DegToRad((*q)[i]) : (*q)[i];
    if (!(std::abs(rad) <= kMaxJointRad)) {
      return reader.Error(keys.joints, "`" + keys.joints + "[" + std::to_string(i) + "]` = " + Short((*q)[i]) +
                                           (keys.joints_deg ? " deg" : " rad") + " is beyond 720 deg");
    }
    out->joints_rad[static_cast<Eigen::Index>(i)] = rad;
  }
  return Status::Ok();
}

Status CheckTranslation(const JsonPoseReader& reader, const std::string& key, const Eigen::Vector3d& t) {
  if (!(t.cwiseAbs().maxCoeff() <= kMaxTranslationM)) {
    return reader.Error(key, "`" + key + "`'s translation (" + Short(t.x()) + ", " + Short(t.y()) + ", " +
                                 Short(t.z()) + ") m is beyond " + Short(kMaxTranslationM) +
                                 " m: no arm reaches that far (metres expected)");
  }
  return Status::Ok();
}

Status ReadMatrix(const JsonPoseReader& reader, const JsonPoseKeys& keys, ImagePose* out) {
  const std::string& key = keys.matrix;
  Result<std::vector<double>> m = reader.Numbers(key, "--pose-matrix-key", 16, 4,
                                                 "a 4x4 pose is 16 numbers (or 4 rows of 4)");
  if (!m.ok()) return m.status();
  Eigen::Matrix4d t;
  for (int i = 0; i < 16; ++i) {
    if (keys.column_major) {
      t(i % 4, i / 4) = (*m)[static_cast<size_t>(i)];
    } else {
      t(i / 4, i % 4) = (*m)[static_cast<size_t>(i)];
    }
  }
  const Eigen::RowVector4d last = t.row(3);
  if (!(last - Eigen::RowVector4d(0, 0, 0, 1)).isZero(1e-6)) {
    return reader.Error(key, "`" + key + "` read " + (keys.column_major ? "column" : "row") + "-major has the last row (" +
                                 Short(last[0]) + ", " + Short(last[1]) + ", " + Short(last[2]) + ", " + Short(last[3]) +
                                 "), not (0, 0, 0, 1): is it stored " + (keys.column_major ? "row" : "column") +
                                 "-major (--pose-matrix-order " + (keys.column_major ? "row" : "column") + ")?");
  }
  const RotationFromMatrix rotation = MakeRotation(t.topLeftCorner<3, 3>(), kRecordedRotationTolerance);
  if (!rotation.ok) return reader.Error(key, "the rotation of `" + key + "` " + rotation.problem);
  const Eigen::Vector3d translation = t.topRightCorner<3, 1>();
  if (Status s = CheckTranslation(reader, key, translation); !s.ok()) return s;
  out->base_from_flange = Rigid3(rotation.rotation, translation);
  out->rotation_correction_rad = rotation.correction_rad;
  return Status::Ok();
}

Status ReadPositionQuaternion(const JsonPoseReader& reader, const JsonPoseKeys& keys, ImagePose* out) {
  Result<std::vector<double>> p = reader.Numbers(keys.position, "--pose-position-key", 3, 0, "a position is 3 numbers, m");
  if (!p.ok()) return p.status();
  Result<std::vector<double>> q = reader.Numbers(keys.quaternion, "--pose-quaternion-key", 4, 0,
                                                 std::string("a quaternion is 4 numbers, ") +
                                                     (keys.quaternion_wxyz ? "w, x, y, z" : "x, y, z, w"));
  if (!q.ok()) return q.status();
  const std::vector<double>& v = *q;
  const double norm = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2] + v[3] * v[3]);
  if (!(std::abs(norm - 1.0) <= kQuaternionNormTolerance)) {
    return reader.Error(keys.quaternion, "the quaternion `" + keys.quaternion + "` has norm " + Short(norm) +
                                             ", not 1 (within " + Short(kQuaternionNormTolerance) + ")");
  }
  const Eigen::Quaterniond quaternion = keys.quaternion_wxyz ? Eigen::Quaterniond(v[0], v[1], v[2], v[3])
                                                             : Eigen::Quaterniond(v[3], v[0], v[1], v[2]);
  const Eigen::Vector3d translation((*p)[0], (*p)[1], (*p)[2]);
  if (Status s = CheckTranslation(reader, keys.position, translation); !s.ok()) return s;
  out->base_from_flange = Rigid3(quaternion.normalized().toRotationMatrix(), translation);
  return Status::Ok();
}

}  // namespace

Status JsonPoseKeys::Validate() const {
  const int given = (joints.empty() ? 0 : 1) + (matrix.empty() ? 0 : 1) + (position.empty() && quaternion.empty() ? 0 : 1);
  if (given != 1) {
    return Status::Error(ErrorCode::kInvalidInput,
                         "JSON pose files: give exactly one of --pose-joints-key, --pose-matrix-key and "
                         "--pose-position-key with --pose-quaternion-key (the key of the pose in each file)");
  }
  if (position.empty() != quaternion.empty()) {
    return Status::Error(ErrorCode::kInvalidInput, "--pose-position-key and --pose-quaternion-key go together");
  }
  return Status::Ok();
}

Status LoadJsonPoseFile(const std::string& path, const JsonPoseKeys& keys, const RobotModel* robot, ImagePose* out) {
  if (Status s = keys.Validate(); !s.ok()) {
    return Status::Error(ErrorCode::kInvalidInput, path + ": " + s.message());
  }
  Result<nlohmann::json> document = ReadJsonFile(path);
  if (!document.ok()) return document.status();
  Result<std::string> text = ReadFileCapped(path, yaml::kMaxYamlBytes);
  if (!text.ok()) return text.status();
  const JsonPoseReader reader(path, std::move(*document), *text);
  out->key = ImageKey(path);
  out->source = path;
  if (!keys.joints.empty()) return ReadJoints(reader, keys, robot, out);
  if (!keys.matrix.empty()) return ReadMatrix(reader, keys, out);
  return ReadPositionQuaternion(reader, keys, out);
}

}  // namespace selfcal::io
