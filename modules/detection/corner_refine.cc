#include "detection/corner_refine.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include <Eigen/Dense>

#include "base/status.h"

namespace selfcal::detection {

namespace {

// The image around a corner, smoothed by a Gaussian: a window of pixels [x0, x0 + w) x [y0, y0 + h), border
// pixels outside the image not allowed.
class SmoothedRegion {
 public:
  // False when the region leaves the image.
  bool Build(const vpImage<unsigned char>& image, int x0, int y0, int w, int h, double sigma) {
    const int k = sigma > 0 ? static_cast<int>(std::ceil(3 * sigma)) : 0;
    if (x0 - k < 0 || y0 - k < 0 || x0 + w + k > static_cast<int>(image.getWidth()) ||
        y0 + h + k > static_cast<int>(image.getHeight())) {
      return false;
    }
    x0_ = x0;
    y0_ = y0;
    w_ = w;
    h_ = h;
    std::vector<double> kernel(static_cast<size_t>(2 * k + 1), 1.0);
    double sum = 0;
    for (int i = -k; i <= k; ++i) sum += kernel[static_cast<size_t>(i + k)] = sigma > 0 ? std::exp(-0.5 * i * i / (sigma * sigma)) : 1.0;
    for (double& v : kernel) v /= sum;
    std::vector<double> rows(static_cast<size_t>((h + 2 * k) * w));  // horizontal pass, rows y0 - k ...
    for (int y = 0; y < h + 2 * k; ++y) {
      const unsigned char* row = image[static_cast<unsigned>(y0 - k + y)];
      for (int x = 0; x < w; ++x) {
        double v = 0;
        for (int i = -k; i <= k; ++i) v += kernel[static_cast<size_t>(i + k)] * row[x0 + x + i];
        rows[static_cast<size_t>(y * w + x)] = v;
      }
    }
    grey_.assign(static_cast<size_t>(w * h), 0.0);
    for (int y = 0; y < h; ++y) {
      for (int x = 0; x < w; ++x) {
        double v = 0;
        for (int i = -k; i <= k; ++i) v += kernel[static_cast<size_t>(i + k)] * rows[static_cast<size_t>((y + k + i) * w + x)];
        grey_[static_cast<size_t>(y * w + x)] = v;
      }
    }
    return true;
  }
  // Inside the region, one pixel clear of its far border.
  bool Holds(double u, double v) const { return u >= x0_ && v >= y0_ && u < x0_ + w_ - 1 && v < y0_ + h_ - 1; }
  double Bilinear(double u, double v) const {
    const int i = static_cast<int>(std::floor(u)) - x0_, j = static_cast<int>(std::floor(v)) - y0_;
    const double a = u - std::floor(u), b = v - std::floor(v);
    const double* r0 = &grey_[static_cast<size_t>(j * w_ + i)];
    const double* r1 = r0 + w_;
    return (1 - b) * ((1 - a) * r0[0] + a * r0[1]) + b * ((1 - a) * r1[0] + a * r1[1]);
  }

 private:
  int x0_ = 0, y0_ = 0, w_ = 0, h_ = 0;
  std::vector<double> grey_;
};

}  // namespace

// Weight 1 up to `inner`, falling linearly to 0 at inner + 1: a mask whose edge does not make the
// iteration jump between two sets of pixels.
double Ramp(double distance, double inner) { return std::clamp(inner + 1 - distance, 0.0, 1.0); }

RefinedCorner RefineCorner(const vpImage<unsigned char>& image, const Eigen::Vector2d& start,
                           const CornerRefineOptions& options) {
  SELFCAL_CHECK(options.radius_px >= 1.5, "RefineCorner: radius " << options.radius_px << " px < 1.5");
  const int n = static_cast<int>(std::ceil(options.radius_px)) + 1;
  const int side = 2 * n + 3;  // samples: the window and one more on each side for the gradients
  std::vector<double> patch(static_cast<size_t>(side * side));
  RefinedCorner out;
  // The corner stays within radius_px of the start: the samples within 2 n + 3 of its pixel.
  SmoothedRegion region;
  const int reach = 2 * n + 3;
  if (!region.Build(image, static_cast<int>(std::floor(start.x())) - reach, static_cast<int>(std::floor(start.y())) - reach,
                    2 * reach + 2, 2 * reach + 2, options.smoothing_sigma_px)) {
    return out;
  }
  const bool band = !options.edge_directions_px.empty();
  const double r2_max = options.radius_px * options.radius_px;
  Eigen::Vector2d p = start;
  for (int it = 1; it <= options.max_iterations; ++it) {
    out.iterations = it;
    if (!region.Holds(p.x() - n - 1, p.y() - n - 1) || !region.Holds(p.x() + n + 1, p.y() + n + 1)) return out;
    for (int b = 0; b < side; ++b) {
      for (int a = 0; a < side; ++a) {
        patch[static_cast<size_t>(b * side + a)] = region.Bilinear(p.x() + a - n - 1, p.y() + b - n - 1);
      }
    }
    auto at = [&](int x, int y) { return patch[static_cast<size_t>(y * side + x)]; };
    Eigen::Matrix2d normal = Eigen::Matrix2d::Zero();
    Eigen::Vector2d rhs = Eigen::Vector2d::Zero();
    for (int dy = -n; dy <= n; ++dy) {
      for (int dx = -n; dx <= n; ++dx) {
        const double r = std::sqrt(static_cast<double>(dx * dx + dy * dy));
        double weight = 0;
        if (band) {
          for (const Eigen::Vector2d& e : options.edge_directions_px) {
            weight = std::max(weight, Ramp(std::abs(e.x() * dy - e.y() * dx), options.band_px));
          }
          weight *= Ramp(r, options.radius_px);
        } else {
          weight = r > options.radius_px ? 0.0 : std::exp(-r * r / r2_max);
        }
        if (weight == 0) continue;
        const int a = dx + n + 1, b = dy + n + 1;
        // Scharr's kernels: the gradient's direction isotropic to ~1 deg on sharp edges, where central
        // differences lean towards the axes and bias a corner between edges that are not axis-aligned.
        const Eigen::Vector2d g(3 * (at(a + 1, b - 1) - at(a - 1, b - 1) + at(a + 1, b + 1) - at(a - 1, b + 1)) + 10 * (at(a + 1, b) - at(a - 1, b)),
                                3 * (at(a - 1, b + 1) - at(a - 1, b - 1) + at(a + 1, b + 1) - at(a + 1, b - 1)) + 10 * (at(a, b + 1) - at(a, b - 1)));
        const Eigen::Matrix2d ggt = weight * g * g.transpose();
        normal += ggt;
        rhs += ggt * Eigen::Vector2d(dx, dy);
      }
    }
    // Well-posed only with two edge directions: the smaller eigenvalue a fair share of the larger.
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(normal);
    if (!(eig.eigenvalues()(0) > 1e-3 * eig.eigenvalues()(1)) || !(eig.eigenvalues()(1) > 0)) return out;
    const Eigen::Vector2d step = normal.ldlt().solve(rhs);
    p += step;
    if ((p - start).norm() > options.radius_px) return out;
    if (step.norm() < options.epsilon_px) {
      out.ok = true;
      break;
    }
  }
  out.px = p;
  return out;
}

CheckedCorner RefineCornerChecked(const vpImage<unsigned char>& image, const Eigen::Vector2d& start,
                                  const CornerRefineOptions& options, double max_disagreement_px) {
  CheckedCorner out;
  CornerRefineOptions small = options;
  small.radius_px = 3;
  small.edge_directions_px.clear();
  out.small = RefineCorner(image, start, small);
  out.large = RefineCorner(image, start, options);
  out.agree = out.small.ok && out.large.ok && (out.small.px - out.large.px).norm() <= max_disagreement_px;
  return out;
}

}  // namespace selfcal::detection
