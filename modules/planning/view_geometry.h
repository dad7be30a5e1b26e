// Geometric quantities of planned views, templated so that the planner's barrier terms are differentiated
// through the same formulas the plan check applies.
#pragma once

#include <algorithm>
#include <cmath>

#include "camera/camera.h"
#include "geometry/rigid3.h"

namespace selfcal::planning {

// Distance (px) of a pixel to the nearest image border (negative outside).
template <typename T>
T ImageMargin(const CameraIntrinsics& cam, const T& u, const T& v) {
  using std::min;
  return min(min(u, T(cam.width_px - 1) - u), min(v, T(cam.height_px - 1) - v));
}

// Observability of f_x from a pair of views (the two-view estimator's "axis coplanarity sine",
// twoview/fundamental.cc, in 3-D): the sine of the angle between optical axis b and the plane through
// axis a and centre b, and symmetrically; the smaller. Zero when the axes intersect (or when one centre
// lies on the other's axis), where f_x cannot be recovered from the fundamental matrix.
// tau = z_b . (d x z_a) with d = c_b - c_a; sine_1 = |tau| / |d x z_a|, sine_2 = |tau| / |d x z_b|.
template <typename T>
T AxisSine(const Rigid3T<T>& base_from_cam_a, const Rigid3T<T>& base_from_cam_b) {
  using std::abs;
  using std::sqrt;
  const Vec3T<T> za = base_from_cam_a.rotation.col(2), zb = base_from_cam_b.rotation.col(2);
  const Vec3T<T> d = base_from_cam_b.translation - base_from_cam_a.translation;
  const T tau = zb.dot(d.cross(za));
  const T na = d.cross(za).norm(), nb = d.cross(zb).norm();
  const T largest = na > nb ? na : nb;
  if (!(largest > T(1e-12) * (d.norm() + T(1e-300)))) return T(0);
  return abs(tau) / largest;
}

// Eye-to-hand: the angle (rad) between the plate's normal, the z axis of the flange frame (the frame of the
// points), and the direction from `plate_centre` to the camera centre of `flange_from_cam`: 0 when the plate
// faces the camera squarely, pi / 2 when the camera sees it edge-on.
inline double PlateViewingAngle(const Rigid3& flange_from_cam, const Eigen::Vector3d& plate_centre) {
  const Eigen::Vector3d to_camera = (flange_from_cam.translation - plate_centre).normalized();
  return std::acos(std::clamp(to_camera.z(), -1.0, 1.0));
}

}  // namespace selfcal::planning
