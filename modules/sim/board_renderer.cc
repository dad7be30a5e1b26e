#include "sim/board_renderer.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <vector>

#include "base/status.h"
#include "sim/image_formation.h"

namespace selfcal::sim {

namespace {

// The grey level seen along the normalised ray (x, y, 1).
class BoardRay {
 public:
  BoardRay(const Rigid3& cam_from_board, const BoardTexture& grey_at, double off_plane)
      : board_from_cam_(cam_from_board.Inverse()), grey_at_(grey_at), off_plane_(off_plane) {}

  double GreyAt(const Eigen::Vector2d& xy) const {
    // The ray t (x, y, 1) in the board frame: origin o, direction d; the plane z = 0.
    const Eigen::Vector3d& o = board_from_cam_.translation;
    const Eigen::Vector3d d = board_from_cam_.rotation * Eigen::Vector3d(xy.x(), xy.y(), 1.0);
    if (std::abs(d.z()) < 1e-15) return off_plane_;
    const double t = -o.z() / d.z();
    if (!(t > 0)) return off_plane_;
    return grey_at_(o.x() + t * d.x(), o.y() + t * d.y());
  }

 private:
  Rigid3 board_from_cam_;
  const BoardTexture& grey_at_;
  double off_plane_;
};

// Separable Gaussian blur of a width x height image, border replicated.
void BlurInPlace(std::vector<double>* grey, int width, int height, double sigma) {
  const int radius = static_cast<int>(std::ceil(4 * sigma));
  std::vector<double> kernel(static_cast<size_t>(2 * radius + 1));
  double sum = 0;
  for (int k = -radius; k <= radius; ++k) sum += kernel[static_cast<size_t>(k + radius)] = std::exp(-0.5 * k * k / (sigma * sigma));
  for (double& k : kernel) k /= sum;
  std::vector<double> tmp(grey->size());
  auto at = [&](const std::vector<double>& img, int u, int v) {
    return img[static_cast<size_t>(std::clamp(v, 0, height - 1)) * static_cast<size_t>(width) +
               static_cast<size_t>(std::clamp(u, 0, width - 1))];
  };
  for (int v = 0; v < height; ++v) {
    for (int u = 0; u < width; ++u) {
      double s = 0;
      for (int k = -radius; k <= radius; ++k) s += kernel[static_cast<size_t>(k + radius)] * at(*grey, u + k, v);
      tmp[static_cast<size_t>(v) * static_cast<size_t>(width) + static_cast<size_t>(u)] = s;
    }
  }
  for (int v = 0; v < height; ++v) {
    for (int u = 0; u < width; ++u) {
      double s = 0;
      for (int k = -radius; k <= radius; ++k) s += kernel[static_cast<size_t>(k + radius)] * at(tmp, u, v + k);
      (*grey)[static_cast<size_t>(v) * static_cast<size_t>(width) + static_cast<size_t>(u)] = s;
    }
  }
}

}  // namespace

std::string BoardRenderOptions::Validate() const {
  std::ostringstream s;
  if (supersampling < 1 || supersampling > 16) s << "supersampling must be in [1, 16], got " << supersampling << "\n";
  if (!(blur_sigma_px >= 0 && blur_sigma_px <= 20)) s << "blur_sigma_px must be in [0, 20], got " << blur_sigma_px << "\n";
  if (!(noise_std_grey >= 0 && noise_std_grey <= 100)) s << "noise_std_grey must be in [0, 100], got " << noise_std_grey << "\n";
  return s.str();
}

BoardRenderer::BoardRenderer(const CameraIntrinsics& camera) : camera_(camera) {
  const std::string problems = camera.Validate();
  SELFCAL_CHECK(problems.empty(), "BoardRenderer:\n" << problems);
  const int width = camera.width_px, height = camera.height_px;
  corner_rays_.reserve(static_cast<size_t>(width + 1) * static_cast<size_t>(height + 1));
  for (int j = 0; j <= height; ++j) {
    for (int i = 0; i <= width; ++i) corner_rays_.push_back(PixelToNormalized(camera, camera.fx_px, Eigen::Vector2d(i - 0.5, j - 0.5)));
  }
}

vpImage<unsigned char> BoardRenderer::Render(const Rigid3& cam_from_board, const BoardTexture& grey_at,
                                             const BoardRenderOptions& options) const {
  const std::string problems = options.Validate();
  SELFCAL_CHECK(problems.empty(), "BoardRenderer::Render:\n" << problems);
  const int width = camera_.width_px, height = camera_.height_px, s = options.supersampling;
  const BoardRay ray(cam_from_board, grey_at, options.off_plane_grey);
  const size_t stride = static_cast<size_t>(width + 1);
  std::vector<double> corner(corner_rays_.size());
  for (size_t k = 0; k < corner.size(); ++k) corner[k] = ray.GreyAt(corner_rays_[k]);
  std::vector<double> grey(static_cast<size_t>(width) * static_cast<size_t>(height));
  for (int v = 0; v < height; ++v) {
    for (int u = 0; u < width; ++u) {
      const size_t k00 = static_cast<size_t>(v) * stride + static_cast<size_t>(u), k01 = k00 + 1, k10 = k00 + stride, k11 = k10 + 1;
      // The ray at (a, b) in [0, 1]^2 across the pixel, bilinear in its corners' rays.
      auto ray_at = [&](double a, double b) {
        return ((1 - a) * (1 - b)) * corner_rays_[k00] + (a * (1 - b)) * corner_rays_[k01] + ((1 - a) * b) * corner_rays_[k10] +
               (a * b) * corner_rays_[k11];
      };
      const double c = ray.GreyAt(ray_at(0.5, 0.5));
      double g = c;
      if (corner[k00] != c || corner[k01] != c || corner[k10] != c || corner[k11] != c) {
        double sum = 0;
        for (int b = 0; b < s; ++b) {
          for (int a = 0; a < s; ++a) sum += ray.GreyAt(ray_at((a + (b + 0.5) / s) / s, (b + (a + 0.5) / s) / s));
        }
        g = sum / (s * s);
      }
      grey[static_cast<size_t>(v) * static_cast<size_t>(width) + static_cast<size_t>(u)] = g;
    }
  }
  if (options.blur_sigma_px > 0) BlurInPlace(&grey, width, height, options.blur_sigma_px);
  GaussianNoise noise(options.noise_seed);
  vpImage<unsigned char> image(static_cast<unsigned>(height), static_cast<unsigned>(width));
  for (int v = 0; v < height; ++v) {
    for (int u = 0; u < width; ++u) {
      double g = grey[static_cast<size_t>(v) * static_cast<size_t>(width) + static_cast<size_t>(u)];
      if (options.noise_std_grey > 0) g += options.noise_std_grey * noise.Next();
      image[static_cast<unsigned>(v)][static_cast<unsigned>(u)] = static_cast<unsigned char>(std::clamp(std::lround(g), 0L, 255L));
    }
  }
  return image;
}

BoardTexture ChessboardTexture(int rows, int cols, double square_m, double dark_grey, double light_grey) {
  return [=](double x, double y) {
    const double i = std::floor(x / square_m), j = std::floor(y / square_m);
    if (i < 0 || j < 0 || i >= cols || j >= rows) return light_grey;
    return (static_cast<long>(i) + static_cast<long>(j)) % 2 == 0 ? dark_grey : light_grey;
  };
}

BoardTexture CircleGridTexture(int rows, int cols, bool asymmetric, double spacing_m, double radius_m, double dot_grey,
                               double board_grey, double margin_m, BoardTexture surround) {
  const double width_m = (asymmetric ? 2 * cols - 1 : cols - 1) * spacing_m, height_m = (rows - 1) * spacing_m;
  return [=](double x, double y) {
    if (x < -margin_m || y < -margin_m || x > width_m + margin_m || y > height_m + margin_m) {
      return surround ? surround(x, y) : board_grey;
    }
    // The nearest disc centre is on one of the three rows nearest y.
    const long r0 = std::lround(y / spacing_m);
    for (long r = std::max(0L, r0 - 1); r <= std::min(static_cast<long>(rows) - 1, r0 + 1); ++r) {
      const double shift = asymmetric ? static_cast<double>(r % 2) : 0.0, step = asymmetric ? 2.0 : 1.0;
      const long c = std::clamp(std::lround((x / spacing_m - shift) / step), 0L, static_cast<long>(cols) - 1);
      const double dx = x - (step * static_cast<double>(c) + shift) * spacing_m, dy = y - static_cast<double>(r) * spacing_m;
      if (dx * dx + dy * dy <= radius_m * radius_m) return dot_grey;
    }
    return board_grey;
  };
}

}  // namespace selfcal::sim
