#include "camera/camera.h"

#include <cmath>
#include <sstream>

namespace selfcal {

std::string CameraIntrinsics::Validate() const {
  std::ostringstream out;
  auto finite = [](double v) { return std::isfinite(v); };
  if (width_px <= 0 || height_px <= 0) out << "image size " << width_px << "x" << height_px << " must be positive\n";
  if (!finite(fx_px) || fx_px <= 0) out << "fx_px = " << fx_px << " must be finite and > 0\n";
  if (!finite(mu) || mu <= 0) out << "mu = " << mu << " must be finite and > 0\n";
  if (!finite(cx_px) || cx_px < 0 || cx_px > width_px) out << "cx_px = " << cx_px << " must lie in [0, width]\n";
  if (!finite(cy_px) || cy_px < 0 || cy_px > height_px) out << "cy_px = " << cy_px << " must lie in [0, height]\n";
  if (!finite(k1) || std::abs(k1) > 10) out << "k1 = " << k1 << " must be finite and |k1| <= 10\n";
  return out.str();
}

Eigen::Vector2d CenteredPixel(const CameraIntrinsics& cam, const Eigen::Vector2d& uv) {
  return Eigen::Vector2d(uv.x() - cam.cx_px, (uv.y() - cam.cy_px) / cam.mu);
}

Eigen::Vector2d PixelToNormalized(const CameraIntrinsics& cam, double fx_px, const Eigen::Vector2d& uv) {
  const Eigen::Vector2d distorted = CenteredPixel(cam, uv) / fx_px;
  if (cam.k1 == 0.0) return distorted;
  Eigen::Vector2d x = distorted;
  for (int i = 0; i < 20; ++i) x = distorted / (1.0 + cam.k1 * x.squaredNorm());
  return x;
}

bool InImage(const CameraIntrinsics& cam, const Eigen::Vector2d& uv, double margin_px) {
  return uv.x() >= -0.5 + margin_px && uv.y() >= -0.5 + margin_px && uv.x() <= cam.width_px - 0.5 - margin_px &&
         uv.y() <= cam.height_px - 0.5 - margin_px;
}

}  // namespace selfcal
