#include "camera/camera.h"

#include <cmath>
#include <sstream>

#include <Eigen/Dense>

namespace selfcal {

namespace {

constexpr const char* kIntrinsicNames[kNumIntrinsics] = {"fx", "mu", "cx", "cy", "k1", "k2", "p1", "p2", "k3"};

}  // namespace

std::string CameraIntrinsics::Validate() const {
  std::ostringstream out;
  out.precision(17);
  auto finite = [](double v) { return std::isfinite(v); };
  if (width_px <= 0 || height_px <= 0) out << "image size " << width_px << "x" << height_px << " must be positive\n";
  if (!finite(fx_px) || fx_px <= 0) out << "fx_px = " << fx_px << " must be finite and > 0\n";
  if (!finite(mu) || mu <= 0) out << "mu = " << mu << " must be finite and > 0\n";
  if (!finite(cx_px) || cx_px < 0 || cx_px > width_px) out << "cx_px = " << cx_px << " must lie in [0, width]\n";
  if (!finite(cy_px) || cy_px < 0 || cy_px > height_px) out << "cy_px = " << cy_px << " must lie in [0, height]\n";
  if (!finite(k1) || std::abs(k1) > 10) out << "k1 = " << k1 << " must be finite and |k1| <= 10\n";
  if (!finite(k2) || std::abs(k2) > 1000) out << "k2 = " << k2 << " must be finite and |k2| <= 1000\n";
  if (!finite(k3) || std::abs(k3) > 1000) out << "k3 = " << k3 << " must be finite and |k3| <= 1000\n";
  if (!finite(p1) || std::abs(p1) > 1) out << "p1 = " << p1 << " must be finite and |p1| <= 1\n";
  if (!finite(p2) || std::abs(p2) > 1) out << "p2 = " << p2 << " must be finite and |p2| <= 1\n";
  return out.str();
}

const char* IntrinsicName(int intrinsic) {
  return intrinsic >= 0 && intrinsic < kNumIntrinsics ? kIntrinsicNames[intrinsic] : "?";
}

int IntrinsicIndex(const std::string& name) {
  for (int i = 0; i < kNumIntrinsics; ++i) {
    if (name == kIntrinsicNames[i]) return i;
  }
  return -1;
}

IntrinsicsVector IntrinsicsOf(const CameraIntrinsics& cam) {
  return {cam.fx_px, cam.mu, cam.cx_px, cam.cy_px, cam.k1, cam.k2, cam.p1, cam.p2, cam.k3};
}

std::vector<int> EstimatedIntrinsics(const IntrinsicsMask& mask) {
  std::vector<int> out;
  for (int i = 0; i < kNumIntrinsics; ++i) {
    if (mask[i]) out.push_back(i);
  }
  return out;
}

CameraIntrinsics WithIntrinsics(const CameraIntrinsics& cam, const IntrinsicsVector& values) {
  CameraIntrinsics out = cam;
  out.fx_px = values[kFx];
  out.mu = values[kMu];
  out.cx_px = values[kCx];
  out.cy_px = values[kCy];
  out.k1 = values[kK1];
  out.k2 = values[kK2];
  out.p1 = values[kP1];
  out.p2 = values[kP2];
  out.k3 = values[kK3];
  return out;
}

Eigen::Vector2d Distort(const CameraIntrinsics& cam, const Eigen::Vector2d& xy, Eigen::Matrix2d* jacobian) {
  const double x = xy.x(), y = xy.y();
  double radial, tx, ty;
  DistortNormalized<double>(cam.k1, cam.k2, cam.p1, cam.p2, cam.k3, x, y, &radial, &tx, &ty);
  if (jacobian != nullptr) {
    const double r2 = x * x + y * y;
    // d radial / d r^2, so d radial / dx = 2 x dr.
    const double dr = cam.k1 + 2 * cam.k2 * r2 + 3 * cam.k3 * r2 * r2;
    *jacobian << radial + 2 * dr * x * x + 2 * cam.p1 * y + 6 * cam.p2 * x,
        2 * dr * x * y + 2 * cam.p1 * x + 2 * cam.p2 * y,
        2 * dr * x * y + 2 * cam.p1 * x + 2 * cam.p2 * y,
        radial + 2 * dr * y * y + 6 * cam.p1 * y + 2 * cam.p2 * x;
  }
  return Eigen::Vector2d(x * radial + tx, y * radial + ty);
}

Eigen::Vector2d CenteredPixel(const CameraIntrinsics& cam, const Eigen::Vector2d& uv) {
  return Eigen::Vector2d(uv.x() - cam.cx_px, (uv.y() - cam.cy_px) / cam.mu);
}

Eigen::Vector2d PixelToNormalized(const CameraIntrinsics& cam, double fx_px, const Eigen::Vector2d& uv) {
  const Eigen::Vector2d distorted = CenteredPixel(cam, uv) / fx_px;
  if (!cam.HasDistortion()) return distorted;
  Eigen::Vector2d x = distorted;
  for (int i = 0; i < 50; ++i) {
    Eigen::Matrix2d jacobian;
    const Eigen::Vector2d error = Distort(cam, x, &jacobian) - distorted;
    const Eigen::Vector2d step = jacobian.partialPivLu().solve(error);
    if (!step.allFinite()) break;
    x -= step;
    if (step.norm() <= 1e-15 * std::max(1.0, x.norm())) break;
  }
  return x;
}

bool InImage(const CameraIntrinsics& cam, const Eigen::Vector2d& uv, double margin_px) {
  return uv.x() >= -0.5 + margin_px && uv.y() >= -0.5 + margin_px && uv.x() <= cam.width_px - 0.5 - margin_px &&
         uv.y() <= cam.height_px - 0.5 - margin_px;
}

}  // namespace selfcal
