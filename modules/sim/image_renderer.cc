#include "sim/image_renderer.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <random>
#include <sstream>

#include <Eigen/LU>

#include "base/status.h"

namespace selfcal::sim {

namespace {

constexpr int kRimPoints = 256;

// Orthonormal in-plane axes of a disc with unit normal n.
void PlaneAxes(const Eigen::Vector3d& n, Eigen::Vector3d* e1, Eigen::Vector3d* e2) {
  const Eigen::Vector3d helper = std::abs(n.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
  *e1 = n.cross(helper).normalized();
  *e2 = n.cross(*e1);
}

// Pixel position of a camera-frame point and its derivative along the rim, through the full camera
// model (pinhole + k1): the chain rule of camera/camera.h's ProjectPoint.
void ProjectWithDerivative(const CameraIntrinsics& cam, const Eigen::Vector3d& p, const Eigen::Vector3d& dp,
                           Eigen::Vector2d* uv, Eigen::Vector2d* duv) {
  const double x = p.x() / p.z(), y = p.y() / p.z();
  const double dx = (dp.x() * p.z() - p.x() * dp.z()) / (p.z() * p.z());
  const double dy = (dp.y() * p.z() - p.y() * dp.z()) / (p.z() * p.z());
  const double s = 1.0 + cam.k1 * (x * x + y * y);
  const double ds = 2.0 * cam.k1 * (x * dx + y * dy);
  *uv = Eigen::Vector2d(cam.fx_px * x * s + cam.cx_px, cam.fx_px * cam.mu * y * s + cam.cy_px);
  *duv = Eigen::Vector2d(cam.fx_px * (dx * s + x * ds), cam.fx_px * cam.mu * (dy * s + y * ds));
}

// Separable Gaussian blur of a row-major float image, border replicated. Away from the border the taps
// need no clamping (the same terms in the same order).
void GaussianBlur(std::vector<double>* image, int width, int height, double sigma) {
  const int radius = static_cast<int>(std::ceil(4.0 * sigma));
  std::vector<double> kernel(2 * radius + 1);
  double sum = 0;
  for (int k = -radius; k <= radius; ++k) sum += kernel[k + radius] = std::exp(-0.5 * k * k / (sigma * sigma));
  for (double& w : kernel) w /= sum;
  const double* weights = kernel.data() + radius;  // weights[k], k in [-radius, radius]
  std::vector<double> tmp(image->size());
  const std::vector<double>& in = *image;
  for (int v = 0; v < height; ++v) {
    const double* row = &in[static_cast<size_t>(v) * width];
    for (int u = 0; u < width; ++u) {
      double acc = 0;
      if (u >= radius && u + radius < width) {
        for (int k = -radius; k <= radius; ++k) acc += weights[k] * row[u + k];
      } else {
        for (int k = -radius; k <= radius; ++k) acc += weights[k] * row[std::clamp(u + k, 0, width - 1)];
      }
      tmp[static_cast<size_t>(v) * width + u] = acc;
    }
  }
  std::vector<double> acc(static_cast<size_t>(width));
  for (int v = 0; v < height; ++v) {
    std::fill(acc.begin(), acc.end(), 0.0);
    for (int k = -radius; k <= radius; ++k) {  // row by row: the same sum per pixel, k ascending
      const double* row = &tmp[static_cast<size_t>(std::clamp(v + k, 0, height - 1)) * width];
      for (int u = 0; u < width; ++u) acc[static_cast<size_t>(u)] += weights[k] * row[u];
    }
    std::copy(acc.begin(), acc.end(), image->begin() + static_cast<std::ptrdiff_t>(v) * width);
  }
}

// Pixel bounds of a projected rim (px, pixel centres at integers).
struct RimBounds {
  double umin = 1e300, umax = -1e300, vmin = 1e300, vmax = -1e300;
};

// The rim of the disc (centre c, plane axes e1, e2, radius r; camera frame, m) as seen by the camera:
// false when part of it is not in front. Its projection gives the bounding box and, by Green's theorem,
// the exact area and centroid: A = 1/2 int(x y' - y x'), A cx = 1/2 int(x^2 y'), A cy = -1/2 int(y^2 x')
// (coordinates relative to the projected centre for conditioning). Fills the dot's geometric fields
// and `rim`, the projected rim points.
bool TraceRim(const CameraIntrinsics& camera, const Eigen::Vector3d& c, const Eigen::Vector3d& e1,
              const Eigen::Vector3d& e2, double r, RenderedDot* dot, std::vector<Eigen::Vector2d>* rim,
              RimBounds* bounds) {
  bool in_front = c.z() > 0;
  for (int k = 0; k < kRimPoints && in_front; ++k) {
    const double t = 2 * kPi * k / kRimPoints;
    in_front = (c + r * (std::cos(t) * e1 + std::sin(t) * e2)).z() > 1e-9;
  }
  if (!in_front) return false;
  dot->in_front = true;
  dot->projected_centre_px = *Project(camera, c);
  const Eigen::Vector2d origin = dot->projected_centre_px;
  double area2 = 0, mx = 0, my = 0;
  double& umin = bounds->umin;
  double& umax = bounds->umax;
  double& vmin = bounds->vmin;
  double& vmax = bounds->vmax;
  rim->reserve(kRimPoints);
  for (int k = 0; k < kRimPoints; ++k) {
    const double t = 2 * kPi * k / kRimPoints;
    const Eigen::Vector3d p = c + r * (std::cos(t) * e1 + std::sin(t) * e2);
    const Eigen::Vector3d dp = r * (-std::sin(t) * e1 + std::cos(t) * e2);
    Eigen::Vector2d uv, duv;
    ProjectWithDerivative(camera, p, dp, &uv, &duv);
    rim->push_back(uv);
    umin = std::min(umin, uv.x()), umax = std::max(umax, uv.x());
    vmin = std::min(vmin, uv.y()), vmax = std::max(vmax, uv.y());
    const Eigen::Vector2d q = uv - origin;
    area2 += q.x() * duv.y() - q.y() * duv.x();
    mx += q.x() * q.x() * duv.y();
    my -= q.y() * q.y() * duv.x();
  }
  const double dt = 2 * kPi / kRimPoints;
  const double area = 0.5 * area2 * dt;
  dot->area_px2 = std::abs(area);
  dot->area_centroid_px = origin + Eigen::Vector2d(0.5 * mx * dt / area, 0.5 * my * dt / area);
  dot->min_radius_px = 1e300;
  for (const Eigen::Vector2d& uv : *rim) {
    const double distance = (uv - dot->area_centroid_px).norm();
    dot->max_radius_px = std::max(dot->max_radius_px, distance);
    dot->min_radius_px = std::min(dot->min_radius_px, distance);
  }
  dot->fully_inside =
      umin >= -0.5 && vmin >= -0.5 && umax <= camera.width_px - 0.5 && vmax <= camera.height_px - 0.5;
  return true;
}

// Where the ray through pixel point (u, v) meets the plane of the disc (centre c, normal n; camera
// frame, m); false when it meets it nowhere in front. The same arithmetic for samples and pixel corners.
bool PlanePoint(const CameraIntrinsics& camera, const Eigen::Vector3d& n, double n_dot_c, double u, double v,
                Eigen::Vector3d* point) {
  const Eigen::Vector2d xy = PixelToNormalized(camera, camera.fx_px, Eigen::Vector2d(u, v));
  const Eigen::Vector3d ray(xy.x(), xy.y(), 1.0);
  const double denominator = n.dot(ray);
  if (denominator == 0) return false;
  const double t = n_dot_c / denominator;
  if (t <= 0) return false;
  *point = t * ray;
  return true;
}

// A point of the image mapped to the disc's plane (PlanePoint), or not (ok false).
struct PlaneSample {
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  bool ok = false;
};

// A square block of samples: all inside the disc (+1), all outside (-1), or undecided (0, to be sampled
// one by one), from the plane points of the block's corners and centre. The map from the block to the
// plane is affine to second order (its curvature over a pixel is ~1e-6 of a pixel), so the block's points
// lie within `spread` (the largest corner distance from the centre's point) of the centre's point and in
// the convex hull of the corners' points up to that curvature. A quarter of `spread` of margin on both
// tests keeps every decided block's samples on the side the per-sample test puts them.
int8_t DecideBlock(const PlaneSample* const corners[4], const PlaneSample& centre, const Eigen::Vector3d& c, double r) {
  if (!centre.ok) return 0;
  double spread = 0, farthest = 0;
  for (int k = 0; k < 4; ++k) {
    if (!corners[k]->ok) return 0;
    spread = std::max(spread, (corners[k]->point - centre.point).norm());
    farthest = std::max(farthest, (corners[k]->point - c).norm());
  }
  const double margin = 0.25 * spread;
  if (farthest + margin < r) return 1;
  if ((centre.point - c).norm() - spread - margin > r) return -1;
  return 0;
}

// The disc's blocks over a box of pixels: each pixel decided whole, and each undecided one by quarters
// (when s is even), so that only the samples near the rim are projected one by one.
class DiscBlocks {
 public:
  DiscBlocks(const CameraIntrinsics& camera, const Eigen::Vector3d& c, const Eigen::Vector3d& n, double r, int s,
             int i0, int i1, int j0, int j1)
      : camera_(camera), c_(c), n_(n), n_dot_c_(n.dot(c)), r_(r), s_(s), i0_(i0), j0_(j0), w_(i1 - i0 + 1),
        h_(j1 - j0 + 1), corners_(static_cast<size_t>(w_ + 1) * (h_ + 1)), centres_(static_cast<size_t>(w_) * h_),
        kind_(centres_.size(), 0) {
    for (int gj = 0; gj <= h_; ++gj) {
      for (int gi = 0; gi <= w_; ++gi) corners_[Corner(gi, gj)] = At(i0 + gi - 0.5, j0 + gj - 0.5);
    }
    for (int gj = 0; gj < h_; ++gj) {
      for (int gi = 0; gi < w_; ++gi) {
        const size_t k = static_cast<size_t>(gj) * w_ + gi;
        centres_[k] = At(i0 + gi, j0 + gj);
        const PlaneSample* const corners[4] = {&corners_[Corner(gi, gj)], &corners_[Corner(gi + 1, gj)],
                                               &corners_[Corner(gi, gj + 1)], &corners_[Corner(gi + 1, gj + 1)]};
        kind_[k] = DecideBlock(corners, centres_[k], c_, r_);
      }
    }
  }

  PlaneSample At(double u, double v) const {
    PlaneSample sample;
    sample.ok = PlanePoint(camera_, n_, n_dot_c_, u, v, &sample.point);
    return sample;
  }
  double n_dot_c() const { return n_dot_c_; }
  int8_t Pixel(int i, int j) const { return kind_[static_cast<size_t>(j - j0_) * w_ + (i - i0_)]; }

  // The kinds of the four quarters of undecided pixel (i, j), row-major (0 each when s is odd).
  std::array<int8_t, 4> Quarters(int i, int j) const {
    std::array<int8_t, 4> quarters{0, 0, 0, 0};
    if (s_ % 2 != 0) return quarters;
    const int gi = i - i0_, gj = j - j0_;
    PlaneSample grid[3][3];  // [row][column]: pixel corners, edge midpoints, centre
    grid[0][0] = corners_[Corner(gi, gj)];
    grid[0][2] = corners_[Corner(gi + 1, gj)];
    grid[2][0] = corners_[Corner(gi, gj + 1)];
    grid[2][2] = corners_[Corner(gi + 1, gj + 1)];
    grid[1][1] = centres_[static_cast<size_t>(gj) * w_ + gi];
    grid[0][1] = At(i, j - 0.5);
    grid[1][0] = At(i - 0.5, j);
    grid[1][2] = At(i + 0.5, j);
    grid[2][1] = At(i, j + 0.5);
    for (int qb = 0; qb < 2; ++qb) {
      for (int qa = 0; qa < 2; ++qa) {
        const PlaneSample* const corners[4] = {&grid[qb][qa], &grid[qb][qa + 1], &grid[qb + 1][qa],
                                               &grid[qb + 1][qa + 1]};
        quarters[static_cast<size_t>(2 * qb + qa)] =
            DecideBlock(corners, At(i - 0.25 + 0.5 * qa, j - 0.25 + 0.5 * qb), c_, r_);
      }
    }
    return quarters;
  }

 private:
  size_t Corner(int gi, int gj) const { return static_cast<size_t>(gj) * (w_ + 1) + gi; }

  const CameraIntrinsics& camera_;
  Eigen::Vector3d c_, n_;
  double n_dot_c_, r_;
  int s_, i0_, j0_, w_, h_;
  std::vector<PlaneSample> corners_, centres_;
  std::vector<int8_t> kind_;
};

// The s x s samples of every pixel in the bounds (one pixel of margin: the rim points are 1.4 degrees
// apart) that see the disc (centre c, normal n, radius r; camera frame, m). Sets the dot's sample area
// and centroid; ORs its samples into `mask` (one bit per sample, all dots) and marks the dots whose
// samples it shares as overlapping neighbours (`owner`: the last dot that darkened a sample there).
// Blocks DiscBlocks decides are not projected sample by sample: the same bits and sums, in the same order.
void SampleDisc(const CameraIntrinsics& camera, const Eigen::Vector3d& c, const Eigen::Vector3d& n, double r, int s,
                const RimBounds& bounds, size_t d, std::vector<RenderedDot>* dots, std::vector<uint64_t>* mask,
                std::vector<int>* owner) {
  const int width = camera.width_px, height = camera.height_px;
  const double inv_s2 = 1.0 / (s * s);
  RenderedDot& dot = (*dots)[d];
  const int i0 = std::max(0, static_cast<int>(std::floor(bounds.umin + 0.5)) - 1);
  const int i1 = std::min(width - 1, static_cast<int>(std::ceil(bounds.umax - 0.5)) + 1);
  const int j0 = std::max(0, static_cast<int>(std::floor(bounds.vmin + 0.5)) - 1);
  const int j1 = std::min(height - 1, static_cast<int>(std::ceil(bounds.vmax - 0.5)) + 1);
  long long dark = 0;
  double su = 0, sv = 0;
  if (i0 <= i1 && j0 <= j1) {
    const DiscBlocks blocks(camera, c, n, r, s, i0, i1, j0, j1);
    for (int j = j0; j <= j1; ++j) {
      for (int i = i0; i <= i1; ++i) {
        const int8_t pixel = blocks.Pixel(i, j);
        if (pixel < 0) continue;
        std::array<int8_t, 4> quarters{pixel, pixel, pixel, pixel};
        if (pixel == 0) quarters = blocks.Quarters(i, j);
        uint64_t bits = 0;
        for (int b = 0; b < s; ++b) {
          const double v = j - 0.5 + (b + 0.5) / s;
          for (int a = 0; a < s; ++a) {
            const double u = i - 0.5 + (a + 0.5) / s;
            const int8_t kind = quarters[static_cast<size_t>(2 * (2 * b >= s) + (2 * a >= s))];
            if (kind < 0) continue;
            if (kind == 0) {
              Eigen::Vector3d point;
              if (!PlanePoint(camera, n, blocks.n_dot_c(), u, v, &point)) continue;
              if (!((point - c).squaredNorm() <= r * r)) continue;
            }
            bits |= uint64_t{1} << (b * s + a);
            ++dark;
            su += u;
            sv += v;
          }
        }
        if (bits == 0) continue;
        const size_t at = static_cast<size_t>(j) * width + i;
        if (((*mask)[at] & bits) != 0 && (*owner)[at] >= 0) {
          RenderedDot& other = (*dots)[(*owner)[at]];
          dot.overlapping = other.overlapping = true;
          if (std::find(dot.neighbours.begin(), dot.neighbours.end(), other.id) == dot.neighbours.end()) {
            dot.neighbours.push_back(other.id);
            other.neighbours.push_back(dot.id);
          }
        }
        (*mask)[at] |= bits;
        (*owner)[at] = dot.id;
      }
    }
  }
  dot.visible = dark > 0;
  dot.clipped = dot.visible && !dot.fully_inside;
  dot.sample_area_px2 = dark * inv_s2;
  if (dark > 0) dot.sample_centroid_px = Eigen::Vector2d(su / dark, sv / dark);
}

// Near neighbours: rims closer than merge_gap_px (cheap test on the bounding circles first).
void MarkNearNeighbours(const std::vector<std::vector<Eigen::Vector2d>>& rims, double merge_gap_px,
                        std::vector<RenderedDot>* dots) {
  for (size_t a = 0; a < dots->size(); ++a) {
    RenderedDot& da = (*dots)[a];
    if (!da.visible) continue;
    for (size_t b = a + 1; b < dots->size(); ++b) {
      RenderedDot& db = (*dots)[b];
      if (!db.visible) continue;
      const double centre_distance = (da.area_centroid_px - db.area_centroid_px).norm();
      if (centre_distance > da.max_radius_px + db.max_radius_px + merge_gap_px) continue;
      double closest = 1e300;
      for (const Eigen::Vector2d& p : rims[a]) {
        for (const Eigen::Vector2d& q : rims[b]) closest = std::min(closest, (p - q).squaredNorm());
      }
      if (da.overlapping && std::count(da.neighbours.begin(), da.neighbours.end(), db.id) > 0) closest = 0;
      if (std::sqrt(closest) < merge_gap_px) {
        da.near_other = db.near_other = true;
        if (std::count(da.neighbours.begin(), da.neighbours.end(), db.id) == 0) {
          da.neighbours.push_back(db.id);
          db.neighbours.push_back(da.id);
        }
      }
    }
  }
}

// std::clamp(std::lround(g), 0, 255) without the library call: lround rounds halves away from zero, and
// g - trunc(g) is exact, so for g > 0 this is the same integer; g <= 0 gives 0 either way.
inline unsigned char RoundToGrey(double g) {
  if (!(g > 0)) return 0;
  if (g >= 255) return 255;
  const int whole = static_cast<int>(g);
  return static_cast<unsigned char>(g - whole >= 0.5 ? whole + 1 : whole);
}

// Image formation: coverage -> grey, blur, noise, quantisation.
void FormImage(const std::vector<uint64_t>& mask, int width, int height, const RenderOptions& options,
               uint64_t noise_seed, vpImage<unsigned char>* image) {
  const int s = options.supersampling;
  const double inv_s2 = 1.0 / (s * s);
  std::vector<double> grey(mask.size(), options.background_grey);
  const double contrast = options.background_grey - options.dot_grey;
  for (size_t k = 0; k < mask.size(); ++k) {
    if (mask[k] != 0) grey[k] -= contrast * __builtin_popcountll(mask[k]) * inv_s2;
  }
  if (options.blur_sigma_px > 0) GaussianBlur(&grey, width, height, options.blur_sigma_px);
  image->resize(static_cast<unsigned>(height), static_cast<unsigned>(width));
  std::mt19937_64 rng(noise_seed);
  std::normal_distribution<double> noise(0.0, 1.0);
  for (size_t k = 0; k < grey.size(); ++k) {
    double g = grey[k];
    if (options.noise_std_grey > 0) g += options.noise_std_grey * noise(rng);
    image->bitmap[k] = RoundToGrey(g);
  }
}

}  // namespace

std::string RenderOptions::Validate() const {
  std::ostringstream out;
  if (supersampling < 1 || supersampling > 8) out << "supersampling = " << supersampling << " must lie in [1, 8]\n";
  auto grey = [&](double g, const char* name) {
    if (!std::isfinite(g) || g < 0 || g > 255) out << name << " = " << g << " must lie in [0, 255]\n";
  };
  grey(background_grey, "background_grey");
  grey(dot_grey, "dot_grey");
  if (!std::isfinite(blur_sigma_px) || blur_sigma_px < 0 || blur_sigma_px > 20) {
    out << "blur_sigma_px = " << blur_sigma_px << " must lie in [0, 20]\n";
  }
  if (!std::isfinite(noise_std_grey) || noise_std_grey < 0 || noise_std_grey > 100) {
    out << "noise_std_grey = " << noise_std_grey << " must lie in [0, 100]\n";
  }
  if (!std::isfinite(merge_gap_px) || merge_gap_px < 0) out << "merge_gap_px = " << merge_gap_px << " must be >= 0\n";
  return out.str();
}

DotScene MakeDotScene(const SimTruth& truth, double radius_m) {
  SELFCAL_CHECK(std::isfinite(radius_m) && radius_m > 0, "dot radius " << radius_m << " m must be > 0");
  SELFCAL_CHECK(!truth.base_from_cam.empty(), "the simulated world has no camera pose");
  DotScene scene;
  scene.radius_m = radius_m;
  scene.centres_in_base = truth.dots_in_base;
  if (!truth.dot_radius_scale.empty()) {
    SELFCAL_CHECK(truth.dot_radius_scale.size() == truth.dots_in_base.size(),
                  truth.dot_radius_scale.size() << " radius scales for " << truth.dots_in_base.size() << " dots");
    for (double scale : truth.dot_radius_scale) scene.radii_m.push_back(scale * radius_m);
  }
  for (const Eigen::Vector3d& p : truth.dots_in_base) {
    Eigen::Vector3d towards = Eigen::Vector3d::Zero();
    for (const Rigid3& c : truth.base_from_cam) towards += (c.translation - p).normalized();
    scene.normals_in_base.push_back(towards.normalized());
  }
  return scene;
}

Eigen::Vector2d EllipseCentrePx(const CameraIntrinsics& camera, const Eigen::Vector3d& centre_in_cam,
                                const Eigen::Vector3d& normal_in_cam, double radius_m) {
  Eigen::Vector3d e1, e2;
  PlaneAxes(normal_in_cam.normalized(), &e1, &e2);
  Eigen::Matrix3d h;
  h.col(0) = e1;
  h.col(1) = e2;
  h.col(2) = centre_in_cam;
  Eigen::Matrix3d k = Eigen::Matrix3d::Identity();
  k(0, 0) = camera.fx_px;
  k(1, 1) = camera.fx_px * camera.mu;
  k(0, 2) = camera.cx_px;
  k(1, 2) = camera.cy_px;
  const Eigen::Matrix3d q = Eigen::Vector3d(1, 1, -radius_m * radius_m).asDiagonal();
  // Pixels -> plane coordinates: (K H)^-1; the conic transforms with its inverse on both sides.
  const Eigen::Matrix3d to_plane = (k * h).inverse();
  const Eigen::Matrix3d c = to_plane.transpose() * q * to_plane;
  return -c.topLeftCorner<2, 2>().inverse() * c.topRightCorner<2, 1>();
}

RenderedImage RenderDots(const CameraIntrinsics& camera, const Rigid3& base_from_cam, const DotScene& scene,
                         const RenderOptions& options, uint64_t noise_seed) {
  {
    const std::string problems = options.Validate() + camera.Validate();
    SELFCAL_CHECK(problems.empty(), "invalid rendering options:\n" << problems);
    SELFCAL_CHECK(scene.normals_in_base.size() == scene.centres_in_base.size(),
                  scene.normals_in_base.size() << " normals for " << scene.centres_in_base.size() << " dots");
    SELFCAL_CHECK(std::isfinite(scene.radius_m) && scene.radius_m > 0, "dot radius " << scene.radius_m);
    SELFCAL_CHECK(scene.radii_m.empty() || scene.radii_m.size() == scene.centres_in_base.size(),
                  scene.radii_m.size() << " radii for " << scene.centres_in_base.size() << " dots");
    for (double r : scene.radii_m) SELFCAL_CHECK(std::isfinite(r) && r > 0, "dot radius " << r);
  }
  const int width = camera.width_px, height = camera.height_px;
  const Rigid3 cam_from_base = base_from_cam.Inverse();

  RenderedImage out;
  out.dots.resize(scene.centres_in_base.size());
  std::vector<uint64_t> mask(static_cast<size_t>(width) * height, 0);  // dark samples, all dots
  std::vector<int> owner(static_cast<size_t>(width) * height, -1);     // last dot that darkened a sample here
  std::vector<std::vector<Eigen::Vector2d>> rims(out.dots.size());

  for (size_t d = 0; d < out.dots.size(); ++d) {
    out.dots[d].id = static_cast<int>(d);
    const double r = scene.RadiusOf(d);
    const Eigen::Vector3d c = cam_from_base * scene.centres_in_base[d];
    const Eigen::Vector3d n = (cam_from_base.rotation * scene.normals_in_base[d]).normalized();
    Eigen::Vector3d e1, e2;
    PlaneAxes(n, &e1, &e2);
    RimBounds bounds;
    if (!TraceRim(camera, c, e1, e2, r, &out.dots[d], &rims[d], &bounds)) continue;
    SampleDisc(camera, c, n, r, options.supersampling, bounds, d, &out.dots, &mask, &owner);
  }
  MarkNearNeighbours(rims, options.merge_gap_px, &out.dots);
  FormImage(mask, width, height, options, noise_seed, &out.image);
  return out;
}

std::vector<int> NameByNearestDisc(const RenderedImage& image, const std::vector<Eigen::Vector2d>& points,
                                   double radius_px, const std::vector<int>& ids) {
  std::vector<int> names(points.size(), kNoDot);
  std::vector<int> claims(image.dots.size(), 0);
  for (size_t k = 0; k < points.size(); ++k) {
    double best = radius_px;
    for (const RenderedDot& dot : image.dots) {
      if (!dot.visible || (!ids.empty() && std::find(ids.begin(), ids.end(), dot.id) == ids.end())) continue;
      const double d = (points[k] - dot.projected_centre_px).norm();
      if (d < best) {
        best = d;
        names[k] = dot.id;
      }
    }
    if (names[k] >= 0) ++claims[names[k]];
  }
  for (int& name : names) {
    if (name >= 0 && claims[name] > 1) name = kAmbiguousDot;
  }
  return names;
}

}  // namespace selfcal::sim
