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
// determinant +1 and is used as written. selfcal writes that form where a file must load back
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

// Reads the map under `key` of `parent` into *out. When the key is absent: a missing-key problem if
// required, else *out is left unchanged and true is returned.
bool ReadTransform(MapReader* parent, const std::string& key, bool required, Rigid3* out);

enum class TransformStyle {
  kMillimetreDegree,  // {xyz_mm: [...], rpy_deg: [...]}: for people
  kExact,             // {xyz_m: [...], rotation: [[...], [...], [...]]}: loads back bit-identical
};
// A YAML flow map for the transform.
std::string TransformYaml(const Rigid3& transform, TransformStyle style);

}  // namespace selfcal::io
