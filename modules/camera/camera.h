// Pinhole camera of eq. (2)/(8) of the paper, with an optional radial term k1.
//
// Pixels: origin at the centre of the top-left pixel, u to the right, v down. Camera frame: z forward,
// x right, y down. Intrinsics: f_x (px), mu = f_y / f_x, principal point (c_x, c_y) in px, zero skew.
// Distortion acts on normalised coordinates: x_d = x (1 + k1 r^2), r^2 = x^2 + y^2.
#pragma once

#include <optional>
#include <string>

#include <Eigen/Core>

#include "geometry/rigid3.h"

namespace selfcal {

struct CameraIntrinsics {
  int width_px = 640;
  int height_px = 480;
  double fx_px = 1000.0;
  double mu = 1.0;  // f_y / f_x
  double cx_px = 319.5;
  double cy_px = 239.5;
  double k1 = 0.0;  // radial distortion on normalised coordinates

  double fy_px() const { return mu * fx_px; }
  // Empty when valid; otherwise every problem, one per line (C3).
  std::string Validate() const;
};

// Projects a point in the camera frame to pixels. Returns false (and leaves uv untouched) for points
// at or behind the camera (z <= 0). Templated for autodiff; `fx` is passed separately so that it can
// be an unknown.
template <typename T>
bool ProjectPoint(const CameraIntrinsics& cam, const T& fx, const T& k1, const Vec3T<T>& p_in_cam,
                  T* u, T* v) {
  if (!(p_in_cam.z() > T(0))) return false;
  const T x = p_in_cam.x() / p_in_cam.z();
  const T y = p_in_cam.y() / p_in_cam.z();
  const T radial = T(1) + k1 * (x * x + y * y);
  *u = fx * x * radial + T(cam.cx_px);
  *v = fx * T(cam.mu) * y * radial + T(cam.cy_px);
  return true;
}

inline std::optional<Eigen::Vector2d> Project(const CameraIntrinsics& cam, const Eigen::Vector3d& p_in_cam) {
  double u = 0, v = 0;
  if (!ProjectPoint<double>(cam, cam.fx_px, cam.k1, p_in_cam, &u, &v)) return std::nullopt;
  return Eigen::Vector2d(u, v);
}

// Normalised, undistorted image coordinates (x, y) with z = 1 of a pixel, given f_x (which may differ
// from cam.fx_px while it is being estimated). Distortion is inverted by fixed-point iteration.
Eigen::Vector2d PixelToNormalized(const CameraIntrinsics& cam, double fx_px, const Eigen::Vector2d& uv);

// Centred pixel coordinates of eq. (8): (u - c_x, (v - c_y) / mu); the single focal f_x then applies to
// both axes. Distortion is not removed.
Eigen::Vector2d CenteredPixel(const CameraIntrinsics& cam, const Eigen::Vector2d& uv);

bool InImage(const CameraIntrinsics& cam, const Eigen::Vector2d& uv, double margin_px);

}  // namespace selfcal
