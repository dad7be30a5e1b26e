// Test-only: a tiny supersampled renderer of dark shapes on a light background, for the tracking tests.
//
// Pixel (u, v) covers [u - 0.5, u + 0.5] x [v - 0.5, v + 0.5] (origin at the centre of the top-left pixel,
// as dot_detector.h). Its value is background + sum over shapes of coverage * (level - background), where
// coverage is the fraction of supersample x supersample sub-pixel centres inside the shape; then optional
// Gaussian noise (seeded std::mt19937_64), rounding and clamping to 0..255. Shapes must not overlap.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <random>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <Eigen/LU>
#include <visp3/core/vpImage.h>

namespace selfcal::tracking::testing {

struct Shape {
  std::function<bool(double u, double v)> inside;
  double u_min, v_min, u_max, v_max;  // bounds of the shape (px), for speed
  double level;                       // grey level of the shape
};

inline Shape Ellipse(const Eigen::Vector2d& c, double a, double b, double angle_rad, double level) {
  const double ca = std::cos(angle_rad), sa = std::sin(angle_rad);
  const double r = std::max(a, b);
  return Shape{[=](double u, double v) {
                 const double du = u - c.x(), dv = v - c.y();
                 const double x = ca * du + sa * dv, y = -sa * du + ca * dv;
                 return (x * x) / (a * a) + (y * y) / (b * b) <= 1.0;
               },
               c.x() - r, c.y() - r, c.x() + r, c.y() + r, level};
}

inline Shape Disc(const Eigen::Vector2d& c, double r, double level) { return Ellipse(c, r, r, 0.0, level); }

inline Shape Ring(const Eigen::Vector2d& c, double r_in, double r_out, double level) {
  return Shape{[=](double u, double v) {
                 const double d2 = (u - c.x()) * (u - c.x()) + (v - c.y()) * (v - c.y());
                 return d2 <= r_out * r_out && d2 >= r_in * r_in;
               },
               c.x() - r_out, c.y() - r_out, c.x() + r_out, c.y() + r_out, level};
}

// Axis-aligned rectangle [u0, u1] x [v0, v1].
inline Shape Rect(double u0, double v0, double u1, double v1, double level) {
  return Shape{[=](double u, double v) { return u >= u0 && u <= u1 && v >= v0 && v <= v1; }, u0, v0, u1, v1, level};
}

// A disc of radius r_m at p_m on a plane, seen through the homography image_from_plane (px per plane unit).
inline Shape ProjectedDisc(const Eigen::Matrix3d& image_from_plane, const Eigen::Vector2d& p_m, double r_m, double level) {
  const Eigen::Matrix3d plane_from_image = image_from_plane.inverse();
  double u0 = 1e9, v0 = 1e9, u1 = -1e9, v1 = -1e9;
  for (int k = 0; k < 16; ++k) {
    const double t = 2 * M_PI * k / 16;
    const Eigen::Vector2d q = p_m + 1.2 * r_m * Eigen::Vector2d(std::cos(t), std::sin(t));
    const Eigen::Vector2d x = (image_from_plane * q.homogeneous()).hnormalized();
    u0 = std::min(u0, x.x());
    v0 = std::min(v0, x.y());
    u1 = std::max(u1, x.x());
    v1 = std::max(v1, x.y());
  }
  return Shape{[=](double u, double v) {
                 const Eigen::Vector2d q = (plane_from_image * Eigen::Vector3d(u, v, 1)).hnormalized();
                 return (q - p_m).squaredNorm() <= r_m * r_m;
               },
               u0, v0, u1, v1, level};
}

inline vpImage<unsigned char> Render(int width, int height, double background, const std::vector<Shape>& shapes,
                                     int supersample = 8, double noise_sigma = 0.0, std::uint64_t seed = 1) {
  std::vector<double> img(static_cast<size_t>(width * height), background);
  const double step = 1.0 / supersample;
  for (const Shape& s : shapes) {
    const int ua = std::max(0, static_cast<int>(std::floor(s.u_min - 1)));
    const int va = std::max(0, static_cast<int>(std::floor(s.v_min - 1)));
    const int ub = std::min(width - 1, static_cast<int>(std::ceil(s.u_max + 1)));
    const int vb = std::min(height - 1, static_cast<int>(std::ceil(s.v_max + 1)));
    for (int v = va; v <= vb; ++v) {
      for (int u = ua; u <= ub; ++u) {
        int in = 0;
        for (int j = 0; j < supersample; ++j) {
          for (int i = 0; i < supersample; ++i) {
            if (s.inside(u - 0.5 + (i + 0.5) * step, v - 0.5 + (j + 0.5) * step)) ++in;
          }
        }
        img[static_cast<size_t>(v * width + u)] += (s.level - background) * in / (supersample * supersample);
      }
    }
  }
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> noise(0.0, noise_sigma > 0 ? noise_sigma : 1.0);
  vpImage<unsigned char> out(static_cast<unsigned int>(height), static_cast<unsigned int>(width));
  for (int v = 0; v < height; ++v) {
    for (int u = 0; u < width; ++u) {
      double x = img[static_cast<size_t>(v * width + u)];
      if (noise_sigma > 0) x += noise(rng);
      out[v][u] = static_cast<unsigned char>(std::clamp(std::lround(x), 0L, 255L));
    }
  }
  return out;
}

// `count` dark shapes of every kind a blob tracer meets, at random (seeded) places, levels and sizes on a
// `width` x `height` grey-200 image: filled discs and ellipses, rings (a hole), one-pixel-thin lines both
// ways and lone pixels, shapes cut by the image edge and touching or nested ones, with grey noise.
inline vpImage<unsigned char> RandomDarkShapes(std::uint64_t seed, int width, int height, int count, double noise_sigma) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(0, 1);
  std::vector<Shape> shapes;
  for (int k = 0; k < count; ++k) {
    const Eigen::Vector2d c(unit(rng) * (width + 10) - 5, unit(rng) * (height + 10) - 5);
    const double level = 10 + 140 * unit(rng);
    switch (static_cast<int>(unit(rng) * 5)) {
      case 0: shapes.push_back(Disc(c, 0.6 + 8 * unit(rng), level)); break;
      case 1: shapes.push_back(Ring(c, 1.5 + 3 * unit(rng), 5 + 4 * unit(rng), level)); break;
      case 2: shapes.push_back(Rect(c.x(), c.y(), c.x() + 1 + 25 * unit(rng), c.y() + 0.4 + 2 * unit(rng), level)); break;
      case 3: shapes.push_back(Ellipse(c, 2 + 9 * unit(rng), 0.7 + 3 * unit(rng), 3 * unit(rng), level)); break;
      default: shapes.push_back(Rect(c.x(), c.y(), c.x() + 0.5 + 2 * unit(rng), c.y() + 1 + 30 * unit(rng), level)); break;
    }
  }
  return Render(width, height, 200, shapes, 4, noise_sigma, seed);
}

}  // namespace selfcal::tracking::testing
