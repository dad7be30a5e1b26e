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
  const Rigid3& x = result.flange_from_cam;
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
  out << "# selfcal hand-eye calibration on recorded flange poses: the camera frame in the flange frame\n"
      << "# (p_in_flange = flange_from_cam * p_in_cam), camera z forward, x right, y down.\n"
      << "format: " << kHandEyeFormat << "\n"
      << "version: 1\n";
  if (!result.source.empty()) out << "source: " << YamlQuoted(result.source) << "\n";
  out << "flange_from_cam: " << TransformYaml(x, TransformStyle::kMillimetreDegree) << "\n"
      << "flange_from_cam_exact: " << TransformYaml(x, TransformStyle::kExact) << "\n"
      << "flange_from_cam_quat_xyzw: " << YamlNumberList(std::vector<double>{q.x(), q.y(), q.z(), q.w()}) << "\n";
  const Eigen::Matrix<double, 6, 1>& s = result.stddev;
  if (s.allFinite()) {
    out << "flange_from_cam_stddev: {xyz_mm: "
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
  Rigid3 rounded;
  root.OptionalString("source", &result.source);
  ReadTransform(&root, "flange_from_cam", /*required=*/true, &rounded);
  ReadTransform(&root, "flange_from_cam_exact", /*required=*/true, &result.flange_from_cam);
  root.Optional("flange_from_cam_quat_xyzw");
  if (const yaml::YamlNode* node = root.Optional("flange_from_cam_stddev")) {
    MapReader map(*node, "flange_from_cam_stddev", &problems);
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
  if (problems.empty() && ((rounded.translation - result.flange_from_cam.translation).norm() > 1e-6 ||
                           (rounded.rotation - result.flange_from_cam.rotation).norm() > 1e-6)) {
    problems.Add("`flange_from_cam` and `flange_from_cam_exact` disagree: one of them was edited");
  }
  if (!problems.empty()) return problems.ToStatus("hand-eye result");
  return result;
}

}  // namespace selfcal::io
