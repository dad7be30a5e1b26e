#include "io/transform_yaml.h"

#include <cmath>
#include <cstdio>

#include <Eigen/Dense>
#include <Eigen/Geometry>

#include "io/plausible_limits.h"
#include "io/yaml_writer.h"

namespace selfcal::io {

namespace {

bool ReadRotationMatrix(const yaml::YamlNode& node, const std::string& name, double tolerance, Problems* problems,
                        Eigen::Matrix3d* out, double* correction_rad) {
  if (!node.IsSequence() || node.items.size() != 3) {
    problems->Add("`" + name + "` at " + problems->At(node.line) + " must be 3 rows of 3 numbers: [[r00, r01, r02], " +
                  "[r10, r11, r12], [r20, r21, r22]]");
    return false;
  }
  Eigen::Matrix3d r;
  bool ok = true;
  for (int i = 0; i < 3; ++i) {
    std::vector<double> row;
    if (ReadDoubleList(node.items[i], name + "[" + std::to_string(i) + "]", 3, Range::Closed(-1.0 - tolerance, 1.0 + tolerance), problems, &row)) {
      r.row(i) << row[0], row[1], row[2];
    } else {
      ok = false;
    }
  }
  if (!ok) return false;
  const RotationFromMatrix rotation = MakeRotation(r, tolerance);
  if (!rotation.ok) {
    problems->Add("`" + name + "` at " + problems->At(node.line) + " " + rotation.problem);
    return false;
  }
  *out = rotation.rotation;
  if (correction_rad != nullptr) *correction_rad = rotation.correction_rad;
  return true;
}

// (x, y, z, w) of a unit quaternion, as ROS and Eigen write it; its norm must be 1 to 1e-6 (a file that
// swapped w to the front is caught only by the reader's eye, so the order is in the key's name).
bool ReadQuaternion(const std::vector<double>& q, const std::string& name, const std::string& at, Problems* problems,
                    Eigen::Matrix3d* out) {
  const double norm = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
  if (std::abs(norm - 1.0) > 1e-6) {
    char detail[64];
    std::snprintf(detail, sizeof(detail), "%.9g", norm);
    problems->Add("`" + name + "` at " + at + " has norm " + detail + "; a rotation quaternion [x, y, z, w] has norm 1");
    return false;
  }
  *out = Eigen::Quaterniond(q[3], q[0], q[1], q[2]).normalized().toRotationMatrix();
  return true;
}

}  // namespace

RotationFromMatrix MakeRotation(const Eigen::Matrix3d& r, double tolerance) {
  RotationFromMatrix out;
  out.orthogonality = (r.transpose() * r - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
  const double det = r.determinant();
  const double as_written = tolerance <= kExactRotationTolerance ? tolerance : kRecordedRotationAsWritten;
  const bool exact = out.orthogonality <= as_written && std::abs(det - 1.0) <= as_written;
  // Within the tolerance |det R| is within 2e-4 of 1: its sign tells a rotation from a reflection.
  if (!exact && !(out.orthogonality <= tolerance && det > 0)) {
    char detail[160];
    std::snprintf(detail, sizeof(detail), "max |R^T R - I| = %.3g, det R = %.12g; a rotation is orthonormal to %.0e",
                  out.orthogonality, det, tolerance);
    out.problem = std::string("is not a rotation matrix (") + detail +
                  (det < 0 ? ", with determinant +1: this one is a reflection)" : ")");
    return out;
  }
  out.ok = true;
  if (exact) {
    out.rotation = r;
    return out;
  }
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(r, Eigen::ComputeFullU | Eigen::ComputeFullV);
  out.rotation = svd.matrixU() * svd.matrixV().transpose();
  const Eigen::JacobiSVD<Eigen::Matrix3d> change(out.rotation - r);
  out.correction_rad = change.singularValues()[0];
  return out;
}

std::string RotationCorrectionNote(const std::string& source, const std::string& pose_id, double correction_rad) {
  char detail[160];
  std::snprintf(detail, sizeof(detail), "corrected by %.2g deg, within the tolerance of max |R^T R - I| <= %.0e",
                RadToDeg(correction_rad), kRecordedRotationTolerance);
  return source + ": pose " + pose_id + ": its rotation matrix was not orthonormal; taken as the nearest rotation (" +
         detail + ")";
}

Eigen::Matrix3d RotationFromRpy(double roll_rad, double pitch_rad, double yaw_rad) {
  return RotZ(yaw_rad) * RotY(pitch_rad) * RotX(roll_rad);
}

Eigen::Vector3d RpyFromRotation(const Eigen::Matrix3d& r) {
  // R = Rz(y) Ry(p) Rx(r): first column (cy cp, sy cp, -sp), last row (-sp, cp sr, cp cr).
  const double cos_pitch = std::hypot(r(0, 0), r(1, 0));
  const double pitch = std::atan2(-r(2, 0), cos_pitch);
  if (cos_pitch < 1e-12) {
    // Gimbal lock: only roll - yaw (pitch = +pi/2) or roll + yaw (-pi/2) is defined; set yaw = 0.
    // Then rows 0 and 1 read (0, sp sr, sp cr) and (0, cr, -sr).
    return Eigen::Vector3d(std::atan2(-r(1, 2), r(1, 1)), pitch, 0.0);
  }
  return Eigen::Vector3d(std::atan2(r(2, 1), r(2, 2)), pitch, std::atan2(r(1, 0), r(0, 0)));
}

bool ReadTransform(MapReader* parent, const std::string& key, bool required, Rigid3* out,
                   double* rotation_correction_rad) {
  const yaml::YamlNode* node = required ? parent->Required(key) : parent->Optional(key);
  if (!node) return !required;
  MapReader map(*node, parent->Path(key), parent->problems());
  if (!map.ok()) return false;
  Problems* problems = parent->problems();
  std::vector<double> xyz, rpy;
  bool ok = map.QuantityList("xyz", Unit::kLength, 3, Range::Closed(-kMaxTranslationM, kMaxTranslationM), &xyz);
  std::string rpy_key;
  const bool rpy_ok = map.QuantityList("rpy", Unit::kAngle, 3, Range::Closed(DegToRad(-360), DegToRad(360)), &rpy,
                                       /*required=*/false, &rpy_key);
  std::vector<double> rotvec;
  std::string rotvec_key;
  const bool rotvec_ok = map.QuantityList("rotvec", Unit::kAngle, 3, Range::Closed(DegToRad(-720), DegToRad(720)),
                                          &rotvec, /*required=*/false, &rotvec_key);
  std::vector<double> quat;
  const yaml::YamlNode* quat_node = map.Optional("quat_xyzw");
  const bool quat_given = quat_node != nullptr;
  const bool quat_ok = quat_given && ReadDoubleList(*quat_node, map.Path("quat_xyzw"), 4,
                                                    Range::Closed(-100.0, 100.0), problems, &quat);
  const yaml::YamlNode* matrix_node = map.Optional("rotation");
  std::vector<std::string> given;
  if (matrix_node) given.push_back("rotation");
  if (!rpy_key.empty()) given.push_back(rpy_key);
  if (!rotvec_key.empty()) given.push_back(rotvec_key);
  if (quat_given) given.push_back("quat_xyzw");
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  if (given.size() > 1) {
    problems->Add("`" + map.Path(given[0]) + "` and `" + map.Path(given[1]) + "` at " +
                  problems->At(map.KeyLine(given[1])) + " both give the rotation; keep one");
    ok = false;
  } else if (matrix_node) {
    const double tolerance = rotation_correction_rad != nullptr ? kRecordedRotationTolerance : kExactRotationTolerance;
    ok &= ReadRotationMatrix(*matrix_node, map.Path("rotation"), tolerance, problems, &rotation, rotation_correction_rad);
  } else if (!rpy_key.empty()) {
    ok &= rpy_ok;
    if (rpy_ok) rotation = RotationFromRpy(rpy[0], rpy[1], rpy[2]);
  } else if (!rotvec_key.empty()) {
    ok &= rotvec_ok;
    if (rotvec_ok) rotation = ExpSO3<double>(Eigen::Vector3d(rotvec[0], rotvec[1], rotvec[2]));
  } else if (quat_given) {
    ok &= quat_ok && ReadQuaternion(quat, map.Path("quat_xyzw"), problems->At(map.KeyLine("quat_xyzw")), problems,
                                    &rotation);
  } else {
    map.AddMissing("`rpy_deg` (or `rpy_rad`, `rotation`, `rotvec_rad`, `quat_xyzw`)");
    ok = false;
  }
  map.Finish();
  if (!ok) return false;
  *out = Rigid3(rotation, Eigen::Vector3d(xyz[0], xyz[1], xyz[2]));
  return true;
}

std::string TransformYaml(const Rigid3& transform, TransformStyle style) {
  const Eigen::Vector3d& t = transform.translation;
  if (style == TransformStyle::kExact) {
    std::string text = "{xyz_m: " + YamlNumberList(std::vector<double>{t.x(), t.y(), t.z()}) + ", rotation: [";
    for (int i = 0; i < 3; ++i) {
      const Eigen::Matrix3d& r = transform.rotation;
      text += (i ? ", " : "") + YamlNumberList(std::vector<double>{r(i, 0), r(i, 1), r(i, 2)});
    }
    return text + "]}";
  }
  // For people: "+ 0.0" turns -0 into 0.
  const Eigen::Vector3d rpy = RpyFromRotation(transform.rotation);
  const Eigen::Vector3d mm = t * 1000.0;
  return "{xyz_mm: " + YamlNumberList(std::vector<double>{mm.x() + 0.0, mm.y() + 0.0, mm.z() + 0.0}) +
         ", rpy_deg: " + YamlNumberList(std::vector<double>{RadToDeg(rpy[0]) + 0.0, RadToDeg(rpy[1]) + 0.0, RadToDeg(rpy[2]) + 0.0}) + "}";
}

}  // namespace selfcal::io
