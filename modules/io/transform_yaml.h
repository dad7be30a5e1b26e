// Rigid transforms in YAML files, and the roll-pitch-yaw convention of every selfcal file.
//
//   base_from_link0: {xyz_mm: [0, 0, 0], rpy_deg: [0, 0, 0]}
//
// xyz is the translation of the transform b_from_a, i.e. the origin of frame a expressed in frame b.
// rpy = (roll, pitch, yaw) are fixed-axis angles: roll about x, then pitch about y, then yaw about z, all
// about the axes of frame b, so
//
//   R = Rz(yaw) * Ry(pitch) * Rx(roll).
//
// Units are in the key: xyz_mm or xyz_m, rpy_deg or rpy_rad. Instead of rpy, `rotation` may give the
// 3x3 matrix row by row ([[r00, r01, r02], [r10, ...], [...]]); it must be orthonormal to 1e-9 with
// determinant +1 and is used as written (a recorded pose's: see kRecordedRotationTolerance). selfcal writes that form where a file must load back
// bit-identical (observations files), and rpy where people read it (calibrated models). Two more forms
// are read, as other tools write them: `rotvec_rad` / `rotvec_deg` (axis times angle: ViSP's theta-u
// vector, OpenCV's Rodrigues vector) and `quat_xyzw` (a unit quaternion [x, y, z, w] as ROS writes it,
// its norm 1 to 1e-6).
#pragma once

#include <string>

#include <Eigen/Core>

#include "geometry/rigid3.h"
#include "io/yaml_schema.h"

namespace selfcal::io {

Eigen::Matrix3d RotationFromRpy(double roll_rad, double pitch_rad, double yaw_rad);
// Inverse of RotationFromRpy: pitch in [-pi/2, pi/2], roll and yaw in (-pi, pi]; at pitch = +-pi/2
// (gimbal lock) roll carries the whole rotation about x and yaw is 0.
Eigen::Vector3d RpyFromRotation(const Eigen::Matrix3d& rotation);

// A rotation matrix at or below this max |R^T R - I| (and |det R - 1|) is used as written: what selfcal
// writes reads back bit-identical.
inline constexpr double kExactRotationTolerance = 1e-9;
// Recorded poses (flange or tool poses of pose files and observations files) come as controllers and people
// write them: rotations at 6 to 9 decimals, libfranka's float output orthonormal to about 2e-5. Up to this
// max |R^T R - I| such a rotation is replaced by the nearest rotation matrix (the orthogonal polar factor,
// through the SVD: R = U S V^T -> U V^T); beyond it the matrix is refused.
inline constexpr double kRecordedRotationTolerance = 1e-4;
// A recorded rotation orthonormal to this is used as written (the rotations selfcal writes, orthonormal to
// a few 1e-16, read back bit-identical); above it, a 9-decimal one included, it is made a rotation.
inline constexpr double kRecordedRotationAsWritten = 1e-12;

// The outcome of MakeRotation: the rotation, and how far it moved from the numbers as written (the largest
// change of a unit vector, ||U V^T - R||_2, rad; 0 when used as written).
struct RotationFromMatrix {
  bool ok = false;
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  double orthogonality = 0;   // max |R^T R - I| of the numbers as written
  double correction_rad = 0;
  std::string problem;        // why not, when !ok: "is not a rotation matrix (max |R^T R - I| = ..., ...)"
};
// `r` as a rotation. With `tolerance` at most kExactRotationTolerance: used as written within it, else
// refused. With a larger one (a recorded pose's): used as written within kRecordedRotationAsWritten, replaced
// by the nearest rotation within `tolerance`, else refused. A reflection (det R < 0) is always refused.
RotationFromMatrix MakeRotation(const Eigen::Matrix3d& r, double tolerance);

// "SOURCE: pose ID: its rotation matrix was not orthonormal; taken as the nearest rotation (corrected by
// 0.00055 deg, ...)": the note of a recorded rotation made a rotation, as detect and calibrate print it.
std::string RotationCorrectionNote(const std::string& source, const std::string& pose_id, double correction_rad);

// Reads the map under `key` of `parent` into *out. When the key is absent: a missing-key problem if
// required, else *out is left unchanged and true is returned. A `rotation` matrix must be orthonormal to
// kExactRotationTolerance, or, when `rotation_correction_rad` is given (a recorded pose), to
// kRecordedRotationTolerance, made a rotation, and the correction (rad, MakeRotation) stored there.
bool ReadTransform(MapReader* parent, const std::string& key, bool required, Rigid3* out,
                   double* rotation_correction_rad = nullptr);

enum class TransformStyle {
  kMillimetreDegree,  // {xyz_mm: [...], rpy_deg: [...]}: for people
  kExact,             // {xyz_m: [...], rotation: [[...], [...], [...]]}: loads back bit-identical
};
// A YAML flow map for the transform.
std::string TransformYaml(const Rigid3& transform, TransformStyle style);

}  // namespace selfcal::io
