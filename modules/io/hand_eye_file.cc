#include "io/hand_eye_file.h"

#include <cmath>
#include <sstream>

#include <Eigen/Geometry>

#include "io/atomic_file.h"
#include "io/observations_file.h"
#include "io/transform_yaml.h"
#include "io/yaml_schema.h"
#include "io/yaml_writer.h"
#include "yaml/yaml_reader.h"

namespace selfcal::io {

namespace {

std::string MaybeNumber(double v) { return std::isfinite(v) ? YamlNumber(v) : std::string(".nan"); }

}  // namespace

Status SaveHandEye(const HandEyeResult& result, const std::string& path) {
  const bool eye_to_hand = result.mount == CameraMount::kEyeToHand;
  const Rigid3& x = eye_to_hand ? result.base_from_cam : result.flange_from_cam;
  const std::string key = eye_to_hand ? "base_from_cam" : "flange_from_cam";
  if (!x.translation.allFinite() || !x.rotation.allFinite() || !std::isfinite(result.fx_px) || result.fx_px <= 0) {
    return Status::Error(ErrorCode::kInvalidInput, "refusing to write a non-finite hand-eye result to " + path);
  }
  if (result.camera) {
    if (const std::string invalid = result.camera->Validate(); !invalid.empty()) {
      return Status::Error(ErrorCode::kInvalidInput, "refusing to write invalid intrinsics to " + path + ":\n" + invalid);
    }
  }
  const Eigen::Quaterniond q(x.rotation);
  std::ostringstream out;
  if (eye_to_hand) {
    out << "# selfcal hand-eye calibration on recorded flange poses, eye-to-hand: the fixed camera frame in the\n"
        << "# robot base frame (p_in_base = base_from_cam * p_in_cam), camera z forward, x right, y down.\n";
  } else {
    out << "# selfcal hand-eye calibration on recorded flange poses: the camera frame in the flange frame\n"
        << "# (p_in_flange = flange_from_cam * p_in_cam), camera z forward, x right, y down.\n";
  }
  // Version 1.1 added eye-to-hand; an eye-in-hand result stays readable by every 1.x reader.
  out << "format: " << kHandEyeFormat << "\n"
      << "version: " << (eye_to_hand ? "1.1" : "1") << "\n";
  if (eye_to_hand) out << "configuration: " << CameraMountName(result.mount) << "\n";
  if (!result.source.empty()) out << "source: " << YamlQuoted(result.source) << "\n";
  out << key << ": " << TransformYaml(x, TransformStyle::kMillimetreDegree) << "\n"
      << key << "_exact: " << TransformYaml(x, TransformStyle::kExact) << "\n"
      << key << "_quat_xyzw: " << YamlNumberList(std::vector<double>{q.x(), q.y(), q.z(), q.w()}) << "\n";
  const Eigen::Matrix<double, 6, 1>& s = result.stddev;
  if (s.allFinite()) {
    out << key << "_stddev: {xyz_mm: "
        << YamlNumberList(std::vector<double>{s[0] * 1e3, s[1] * 1e3, s[2] * 1e3})
        << ", rotvec_deg: " << YamlNumberList(std::vector<double>{RadToDeg(s[3]), RadToDeg(s[4]), RadToDeg(s[5])})
        << "}  # of a correction in the camera frame\n";
  }
  out << "fx_px: " << YamlNumber(result.fx_px) << "\n";
  if (std::isfinite(result.fx_stddev_px)) out << "fx_stddev_px: " << MaybeNumber(result.fx_stddev_px) << "\n";
  if (result.camera) out << "camera: " << CameraYaml(*result.camera) << "  # the calibrated intrinsics\n";
  if (const std::string sd = IntrinsicsStddevYaml(result.intrinsics_stddev); !sd.empty()) {
    out << "intrinsics_stddev: " << sd << "  # of the estimated intrinsics\n";
  }
  if (!result.provenance.empty()) {
    out << "provenance:\n";
    for (const auto& [key, value] : result.provenance) out << "  " << YamlQuoted(key) << ": " << YamlQuoted(value) << "\n";
  }
  return WriteFileAtomically(path, out.str());
}

Result<HandEyeResult> LoadHandEye(const std::string& path) {
  Result<yaml::YamlDocument> doc = yaml::LoadYamlFile(path);
  if (!doc.ok()) return doc.status();
  Problems problems(doc->path);
  MapReader root(doc->root, "", &problems);
  if (!CheckFormatAndVersion(&root, kHandEyeFormat, 1)) {
    root.Abandon();
    return problems.ToStatus("hand-eye result");
  }
  HandEyeResult result;
  std::string configuration = CameraMountName(result.mount);
  if (root.OptionalString("configuration", &configuration) && !ParseCameraMount(configuration, &result.mount)) {
    problems.Add("`configuration` = `" + configuration + "` at " + problems.At(root.KeyLine("configuration")) +
                 " must be eye_in_hand or eye_to_hand");
  }
  const bool eye_to_hand = result.mount == CameraMount::kEyeToHand;
  const std::string key = eye_to_hand ? "base_from_cam" : "flange_from_cam";
  Rigid3& exact = eye_to_hand ? result.base_from_cam : result.flange_from_cam;
  Rigid3 rounded;
  root.OptionalString("source", &result.source);
  ReadTransform(&root, key, /*required=*/true, &rounded);
  ReadTransform(&root, key + "_exact", /*required=*/true, &exact);
  root.Optional(key + "_quat_xyzw");
  if (const yaml::YamlNode* node = root.Optional(key + "_stddev")) {
    MapReader map(*node, key + "_stddev", &problems);
    std::vector<double> xyz, rotvec;
    if (map.QuantityList("xyz", Unit::kLength, 3, Range::Closed(0, 10), &xyz) &&
        map.QuantityList("rotvec", Unit::kAngle, 3, Range::Closed(0, 10), &rotvec)) {
      result.stddev << xyz[0], xyz[1], xyz[2], rotvec[0], rotvec[1], rotvec[2];
    }
  }
  root.Optional("provenance");
  root.Double("fx_px", Range::Positive(1e6), &result.fx_px);
  root.OptionalDouble("fx_stddev_px", Range::Closed(0, 1e6), &result.fx_stddev_px);
  ReadOptionalCamera(&root, &problems, &result.camera);
  ReadIntrinsicsStddev(&root, &result.intrinsics_stddev);
  root.Finish();
  if (problems.empty() && ((rounded.translation - exact.translation).norm() > 1e-6 ||
                           (rounded.rotation - exact.rotation).norm() > 1e-6)) {
    problems.Add("`" + key + "` and `" + key + "_exact` disagree: one of them was edited");
  }
  if (!problems.empty()) return problems.ToStatus("hand-eye result");
  return result;
}

}  // namespace selfcal::io
