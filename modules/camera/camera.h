// Module camera (ARCHITECTURE.md): the pinhole model of eq. (8) with OpenCV's lens (this header),
// inverted by Newton; the templated projection with every intrinsic an unknown (ProjectWithIntrinsics, the
// Intrinsic order fx, mu, cx, cy, k1, k2, p1, p2, k3) and the IntrinsicsMask of which ones an estimator moves.
// Uses geometry.
//
// Pinhole camera of eq. (2)/(8) of the paper with OpenCV's radial-tangential lens model (the five
// coefficients of cv::calibrateCamera, in OpenCV's order k1, k2, p1, p2, k3).
//
// Pixels: origin at the centre of the top-left pixel, u to the right, v down (OpenCV's and ViSP's
// convention too: their c_x, c_y are ours unchanged). Camera frame: z forward, x right, y down.
// Intrinsics: f_x (px), mu = f_y / f_x, principal point (c_x, c_y) in px, zero skew.
// Distortion acts on normalised coordinates (x, y) = (X / Z, Y / Z), exactly as cv::projectPoints:
//
//   r^2 = x^2 + y^2,  radial = 1 + k1 r^2 + k2 r^4 + k3 r^6
//   x_d = x radial + 2 p1 x y + p2 (r^2 + 2 x^2)
//   y_d = y radial + p1 (r^2 + 2 y^2) + 2 p2 x y
//   u = f_x x_d + c_x,  v = mu f_x y_d + c_y
#pragma once

#include <array>
#include <optional>
#include <string>
#include <vector>

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
  double k1 = 0.0;  // radial, r^2
  double k2 = 0.0;  // radial, r^4
  double p1 = 0.0;  // tangential
  double p2 = 0.0;  // tangential
  double k3 = 0.0;  // radial, r^6

  double fy_px() const { return mu * fx_px; }
  bool HasDistortion() const { return k1 != 0 || k2 != 0 || p1 != 0 || p2 != 0 || k3 != 0; }
  // Empty when valid; otherwise every problem, one per line (C3), each naming the value.
  std::string Validate() const;
};

// The intrinsics as one vector, for estimation: this order everywhere (bundle columns, reports).
enum Intrinsic { kFx = 0, kMu, kCx, kCy, kK1, kK2, kP1, kP2, kK3, kNumIntrinsics };
using IntrinsicsVector = std::array<double, kNumIntrinsics>;
// "fx", "mu", "cx", "cy", "k1", "k2", "p1", "p2", "k3".
const char* IntrinsicName(int intrinsic);
// The index of a name above, or -1.
int IntrinsicIndex(const std::string& name);
IntrinsicsVector IntrinsicsOf(const CameraIntrinsics& cam);
// Which intrinsics an estimator moves (true) or holds (false), in the order of Intrinsic.
using IntrinsicsMask = std::array<bool, kNumIntrinsics>;
// f_x estimated, everything else held: the default of every bundle.
inline constexpr IntrinsicsMask kFocalLengthOnly = {true, false, false, false, false, false, false, false, false};
// The indices set in `mask`, ascending (the order of the estimated intrinsics in covariances).
std::vector<int> EstimatedIntrinsics(const IntrinsicsMask& mask);
// `cam` with the values of `values` (image size kept).
CameraIntrinsics WithIntrinsics(const CameraIntrinsics& cam, const IntrinsicsVector& values);

// Distorted normalised coordinates of the model above; templated for autodiff. k: k1, k2, p1, p2, k3.
template <typename T>
void DistortNormalized(const T& k1, const T& k2, const T& p1, const T& p2, const T& k3, const T& x, const T& y,
                       T* radial, T* tangential_x, T* tangential_y) {
  const T r2 = x * x + y * y;
  // Written so that zero coefficients add exact zeros: a k1-only camera gives the bits of x (1 + k1 r^2).
  *radial = T(1) + k1 * r2 + k2 * r2 * r2 + k3 * r2 * r2 * r2;
  *tangential_x = T(2) * p1 * x * y + p2 * (r2 + T(2) * x * x);
  *tangential_y = p1 * (r2 + T(2) * y * y) + T(2) * p2 * x * y;
}

// Projects a point in the camera frame with every intrinsic possibly an unknown: `in` holds them in the
// order of Intrinsic (fx, mu, cx, cy, k1, k2, p1, p2, k3). Returns false (uv untouched) for points at or
// behind the camera (z <= 0).
template <typename T>
bool ProjectWithIntrinsics(const T* in, const Vec3T<T>& p_in_cam, T* u, T* v) {
  if (!(p_in_cam.z() > T(0))) return false;
  const T x = p_in_cam.x() / p_in_cam.z();
  const T y = p_in_cam.y() / p_in_cam.z();
  T radial, tx, ty;
  DistortNormalized<T>(in[kK1], in[kK2], in[kP1], in[kP2], in[kK3], x, y, &radial, &tx, &ty);
  const T fx = in[kFx];
  *u = fx * x * radial + fx * tx + in[kCx];
  *v = fx * in[kMu] * y * radial + fx * in[kMu] * ty + in[kCy];
  return true;
}

// Projects with f_x and k1 possibly unknowns, every other intrinsic taken from `cam`. Returns false (and
// leaves uv untouched) for points at or behind the camera (z <= 0). Templated for autodiff.
template <typename T>
bool ProjectPoint(const CameraIntrinsics& cam, const T& fx, const T& k1, const Vec3T<T>& p_in_cam, T* u, T* v) {
  const T in[kNumIntrinsics] = {fx, T(cam.mu), T(cam.cx_px), T(cam.cy_px), k1, T(cam.k2), T(cam.p1), T(cam.p2), T(cam.k3)};
  return ProjectWithIntrinsics<T>(in, p_in_cam, u, v);
}

inline std::optional<Eigen::Vector2d> Project(const CameraIntrinsics& cam, const Eigen::Vector3d& p_in_cam) {
  double u = 0, v = 0;
  if (!ProjectPoint<double>(cam, cam.fx_px, cam.k1, p_in_cam, &u, &v)) return std::nullopt;
  return Eigen::Vector2d(u, v);
}

// The distorted normalised point (x_d, y_d) of (x, y) and, when `jacobian` is given, d(x_d, y_d)/d(x, y).
Eigen::Vector2d Distort(const CameraIntrinsics& cam, const Eigen::Vector2d& xy, Eigen::Matrix2d* jacobian = nullptr);

// Normalised, undistorted image coordinates (x, y) with z = 1 of a pixel, given f_x (which may differ
// from cam.fx_px while it is being estimated). The lens model is inverted by Newton's method on
// Distort (like cv::undistortPoints, but iterated until the step is below 1e-15, at most 50 steps).
Eigen::Vector2d PixelToNormalized(const CameraIntrinsics& cam, double fx_px, const Eigen::Vector2d& uv);

// Centred pixel coordinates of eq. (8): (u - c_x, (v - c_y) / mu); the single focal f_x then applies to
// both axes. Distortion is not removed.
Eigen::Vector2d CenteredPixel(const CameraIntrinsics& cam, const Eigen::Vector2d& uv);

bool InImage(const CameraIntrinsics& cam, const Eigen::Vector2d& uv, double margin_px);

}  // namespace selfcal
