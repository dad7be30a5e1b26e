#include "sim/image_renderer.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <sstream>

#include <Eigen/LU>

#include "base/status.h"
#include "sim/image_formation.h"

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

// cos t and sin t of the rim points t = 2 pi k / kRimPoints, computed once.
struct RimAngles {
  double cos[kRimPoints], sin[kRimPoints];
};
const RimAngles& Angles() {
  static const RimAngles angles = [] {
    RimAngles a{};
    for (int k = 0; k < kRimPoints; ++k) {
      const double t = 2 * kPi * k / kRimPoints;
      a.cos[k] = std::cos(t);
      a.sin[k] = std::sin(t);
    }
    return a;
  }();
  return angles;
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
  const RimAngles& angles = Angles();
  bool in_front = c.z() > 0;
  for (int k = 0; k < kRimPoints && in_front; ++k) {
    in_front = (c + r * (angles.cos[k] * e1 + angles.sin[k] * e2)).z() > 1e-9;
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
    const Eigen::Vector3d p = c + r * (angles.cos[k] * e1 + angles.sin[k] * e2);
    const Eigen::Vector3d dp = r * (-angles.sin[k] * e1 + angles.cos[k] * e2);
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

// PixelToNormalized(camera, camera.fx_px, (u, v)), by a scalar Newton iteration when the lens is
// radial (p1 = p2 = 0): the 2-D iteration's steps then lie along the ray from the principal point
// (the distorted point is an eigenvector of the Jacobian), so it is this one on the radius, rho
// (1 + k1 rho^2 + k2 rho^4 + k3 rho^6) = rho_d, without the 2 x 2 solves, from a closer start. Both converge to the last
// bits; where they differ in the last bit a sample's verdict could change only within ~1e-15 of the rim.
Eigen::Vector2d Undistort(const CameraIntrinsics& camera, double u, double v) {
  const double xd = (u - camera.cx_px) / camera.fx_px;
  const double yd = ((v - camera.cy_px) / camera.mu) / camera.fx_px;
  if (!camera.HasDistortion()) return Eigen::Vector2d(xd, yd);
  const double rd = std::sqrt(xd * xd + yd * yd);
  if (camera.p1 != 0 || camera.p2 != 0 || rd == 0) return PixelToNormalized(camera, camera.fx_px, Eigen::Vector2d(u, v));
  const double k1 = camera.k1, k2 = camera.k2, k3 = camera.k3;
  const double rd2 = rd * rd;
  double rho = rd / (1 + k1 * rd2 + k2 * rd2 * rd2 + k3 * rd2 * rd2 * rd2);  // first order in the coefficients
  if (!(rho > 0)) rho = rd;
  for (int i = 0; i < 50; ++i) {
    const double r2 = rho * rho;
    const double radial = 1 + k1 * r2 + k2 * r2 * r2 + k3 * r2 * r2 * r2;
    const double slope = 1 + 3 * k1 * r2 + 5 * k2 * r2 * r2 + 7 * k3 * r2 * r2 * r2;
    const double step = (rho * radial - rd) / slope;
    if (!std::isfinite(step)) break;
    rho -= step;
    if (std::abs(step) <= 1e-15 * std::max(1.0, rho)) return Eigen::Vector2d(xd, yd) * (rho / rd);
  }
  return PixelToNormalized(camera, camera.fx_px, Eigen::Vector2d(u, v));  // not converged: the 2-D iteration's answer
}

// Where the ray through pixel point (u, v) meets the plane of the disc (centre c, normal n; camera
// frame, m); false when it meets it nowhere in front. The same arithmetic for samples and pixel corners.
bool PlanePoint(const CameraIntrinsics& camera, const Eigen::Vector3d& n, double n_dot_c, double u, double v,
                Eigen::Vector3d* point) {
  const Eigen::Vector2d xy = Undistort(camera, u, v);
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
  double spread2 = 0, farthest2 = 0;  // the largest squared distances: sqrt is monotone, one root each
  for (int k = 0; k < 4; ++k) {
    if (!corners[k]->ok) return 0;
    spread2 = std::max(spread2, (corners[k]->point - centre.point).squaredNorm());
    farthest2 = std::max(farthest2, (corners[k]->point - c).squaredNorm());
  }
  const double spread = std::sqrt(spread2), farthest = std::sqrt(farthest2);
  const double margin = 0.25 * spread;
  if (farthest + margin < r) return 1;
  if ((centre.point - c).norm() - spread - margin > r) return -1;
  return 0;
}

// The disc's blocks over a box of pixels: each pixel decided whole, and the samples of each undecided
// one by interpolation (Verdicts), so that only the samples nearest the rim are projected one by one.
class DiscBlocks {
 public:
  DiscBlocks(const CameraIntrinsics& camera, const Eigen::Vector3d& c, const Eigen::Vector3d& n, double r, int s,
             int i0, int i1, int j0, int j1)
      : camera_(camera), c_(c), n_(n), n_dot_c_(n.dot(c)), r_(r), s_(s), i0_(i0), j0_(j0), w_(i1 - i0 + 1),
        h_(j1 - j0 + 1), corners_(static_cast<size_t>(w_ + 1) * (h_ + 1)), centres_(static_cast<size_t>(w_) * h_),
        kind_(centres_.size(), 0), all_bits_(s == 8 ? ~uint64_t{0} : (uint64_t{1} << (s * s)) - 1) {
    for (int a = 0; a < s; ++a) offsets_[a] = (a + 0.5) / s - 0.5;
    fits_w_ = (w_ + 1) / 2;
    fits_.resize(static_cast<size_t>(fits_w_) * ((h_ + 1) / 2));
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

  // The samples of undecided pixel (i, j) decided without projecting each: f = |plane point - c|^2 - r^2
  // is interpolated biquadratically over the 2 x 2 pixels around it from its values at their 9 corners
  // (the map to the plane is a homography after the lens: over 2 px f is a quadratic up to third-order
  // terms ~1e-3 of a sample spacing). The interpolant's error at the 4 pixel centres, where the nodal
  // polynomial of the nodes -1, 0, 1 is within 3 % of its largest value, bounds it over the block; a
  // sample is decided when its interpolated f is beyond 50 times that bound. Sets the bits (b s + a) of
  // the samples surely inside in *dark and of those to be projected in *unsure (all of them when the box
  // is narrower than 2 px or a ray of the block misses the plane). The same corners and centres as the
  // pixels' decisions: no new projection.
  void Verdicts(int i, int j, uint64_t* dark, uint64_t* unsure) {
    *dark = 0;
    *unsure = all_bits_;
    if (w_ < 2 || h_ < 2) return;
    const int gi = i - i0_, gj = j - j0_;
    const int bi = gi / 2, bj = gj / 2;  // the block; an odd last column or row shares the one before's pixel
    const int ci = std::min(2 * bi, w_ - 2), cj = std::min(2 * bj, h_ - 2);  // the block's first corner
    BlockFit& fit = fits_[static_cast<size_t>(bj) * fits_w_ + bi];
    if (!fit.done) Fit(ci, cj, &fit);
    if (!fit.ok) return;
    uint64_t inside = 0, undecided = 0;
    const double u0 = i - (i0_ + ci + 0.5), v0 = j - (j0_ + cj + 0.5);  // pixel centre - block centre, px
    for (int b = 0; b < s_; ++b) {
      double wv[3];
      Weights(v0 + offsets_[b], wv);
      double g[3];
      for (int p = 0; p < 3; ++p) g[p] = wv[0] * fit.f[0][p] + wv[1] * fit.f[1][p] + wv[2] * fit.f[2][p];
      for (int a = 0; a < s_; ++a) {
        double wu[3];
        Weights(u0 + offsets_[a], wu);
        const double value = wu[0] * g[0] + wu[1] * g[1] + wu[2] * g[2];
        const int bit = b * s_ + a;
        inside |= static_cast<uint64_t>(value < -fit.tolerance) << bit;
        undecided |= static_cast<uint64_t>(value >= -fit.tolerance && value <= fit.tolerance) << bit;
      }
    }
    *dark = inside;
    *unsure = undecided;
  }

 private:
  // f at a 2 x 2 pixel block's 9 corners [row][column] and the margin of its interpolation.
  struct BlockFit {
    bool done = false, ok = false;
    double f[3][3] = {};
    double tolerance = 0;
  };
  void Fit(int ci, int cj, BlockFit* fit) const {
    fit->done = true;
    for (int q = 0; q < 3; ++q) {
      for (int p = 0; p < 3; ++p) {
        const PlaneSample& node = corners_[Corner(ci + p, cj + q)];
        if (!node.ok) return;
        fit->f[q][p] = (node.point - c_).squaredNorm() - r_ * r_;
      }
    }
    double error = 0;
    for (int q = 0; q < 2; ++q) {
      for (int p = 0; p < 2; ++p) {
        const PlaneSample& check = centres_[static_cast<size_t>(cj + q) * w_ + ci + p];
        if (!check.ok) return;
        double wu[3], wv[3];
        Weights(p == 0 ? -0.5 : 0.5, wu);
        Weights(q == 0 ? -0.5 : 0.5, wv);
        double value = 0;
        for (int k = 0; k < 3; ++k) value += wv[k] * (wu[0] * fit->f[k][0] + wu[1] * fit->f[k][1] + wu[2] * fit->f[k][2]);
        error = std::max(error, std::abs(value - ((check.point - c_).squaredNorm() - r_ * r_)));
      }
    }
    fit->tolerance = 50 * error + 1e-9 * r_ * r_;
    fit->ok = true;
  }

  size_t Corner(int gi, int gj) const { return static_cast<size_t>(gj) * (w_ + 1) + gi; }
  // Lagrange weights of the nodes at t = -1, 0, 1 (t: the offset from the block's centre, px).
  static void Weights(double t, double w[3]) {
    w[0] = 0.5 * t * (t - 1);
    w[1] = 1 - t * t;
    w[2] = 0.5 * t * (t + 1);
  }

  const CameraIntrinsics& camera_;
  Eigen::Vector3d c_, n_;
  double n_dot_c_, r_;
  int s_, i0_, j0_, w_, h_;
  std::vector<PlaneSample> corners_, centres_;
  std::vector<int8_t> kind_;
  uint64_t all_bits_;
  double offsets_[8];  // of the samples a = 0..s-1 from the pixel's centre, px
  int fits_w_;
  std::vector<BlockFit> fits_;  // per 2 x 2 block, row-major, filled when first needed
};

// The number of set bits of an 8-bit row and the sum of their positions, from a table.
struct RowBits {
  uint8_t count[256], position_sum[256];
};
const RowBits& RowBitTable() {
  static const RowBits table = [] {
    RowBits t{};
    for (int row = 0; row < 256; ++row) {
      for (int a = 0; a < 8; ++a) {
        if ((row >> a) & 1) t.count[row] += 1, t.position_sum[row] += static_cast<uint8_t>(a);
      }
    }
    return t;
  }();
  return table;
}

// The s x s samples of every pixel in the bounds (one pixel of margin: the rim points are 1.4 degrees
// apart) that see the disc (centre c, normal n, radius r; camera frame, m). Sets the dot's sample area
// and centroid; ORs its samples into `mask` (one bit per sample, all dots) and marks the dots whose
// samples it shares as overlapping neighbours (`owner`: the last dot that darkened a sample there);
// adds the box to frame->boxes. Samples DiscBlocks decides are not projected one by one: the same bits,
// and the same sums (exact integers, or in the samples' order).
void SampleDisc(const CameraIntrinsics& camera, const Eigen::Vector3d& c, const Eigen::Vector3d& n, double r, int s,
                const RimBounds& bounds, size_t d, std::vector<RenderedDot>* dots, FrameBuffers* frame) {
  const int width = camera.width_px, height = camera.height_px;
  const double inv_s2 = 1.0 / (s * s);
  RenderedDot& dot = (*dots)[d];
  const int i0 = std::max(0, static_cast<int>(std::floor(bounds.umin + 0.5)) - 1);
  const int i1 = std::min(width - 1, static_cast<int>(std::ceil(bounds.umax - 0.5)) + 1);
  const int j0 = std::max(0, static_cast<int>(std::floor(bounds.vmin + 0.5)) - 1);
  const int j1 = std::min(height - 1, static_cast<int>(std::ceil(bounds.vmax - 0.5)) + 1);
  // With s a power of two every sample coordinate is a multiple of 1 / (2 s): the coordinate sums are
  // integers in those units, exact in any order (the per-sample double sums were exact too), so whole
  // pixels add closed forms. Other s keep the ordered per-sample double sums.
  const bool exact_sums = (s & (s - 1)) == 0;
  const RowBits& row_bits = RowBitTable();
  const uint64_t full_bits = s == 8 ? ~uint64_t{0} : (uint64_t{1} << (s * s)) - 1;
  long long dark = 0, su2s = 0, sv2s = 0;  // sums of 2 s u and 2 s v (exact_sums)
  double su = 0, sv = 0;
  if (i0 <= i1 && j0 <= j1) {
    frame->boxes.push_back(PixelBox{i0, i1, j0, j1});
    std::vector<uint64_t>* mask = &frame->mask;  // dark samples, all dots
    std::vector<int>* owner = &frame->owner;     // the last dot that darkened a sample of the pixel
    DiscBlocks blocks(camera, c, n, r, s, i0, i1, j0, j1);
    for (int j = j0; j <= j1; ++j) {
      for (int i = i0; i <= i1; ++i) {
        const int8_t pixel = blocks.Pixel(i, j);
        if (pixel < 0) continue;
        uint64_t bits = full_bits, unsure = 0;
        if (pixel == 0) blocks.Verdicts(i, j, &bits, &unsure);
        for (; unsure != 0; unsure &= unsure - 1) {  // project the undecided samples
          const int bit = __builtin_ctzll(unsure);
          Eigen::Vector3d point;
          if (!PlanePoint(camera, n, blocks.n_dot_c(), i - 0.5 + (bit % s + 0.5) / s, j - 0.5 + (bit / s + 0.5) / s,
                          &point)) {
            continue;
          }
          if ((point - c).squaredNorm() <= r * r) bits |= uint64_t{1} << bit;
        }
        if (exact_sums) {  // per row b: sum over its dark a of (2 s i - s + 2 a + 1), and of (2 s j - s + 2 b + 1)
          for (int b = 0; b < s; ++b) {
            const unsigned row = static_cast<unsigned>((bits >> (b * s)) & ((1u << s) - 1));
            const int count = row_bits.count[row];
            dark += count;
            su2s += count * (2LL * s * i - s + 1) + 2 * row_bits.position_sum[row];
            sv2s += count * (2LL * s * j - s + 2 * b + 1);
          }
        } else {  // the double sums in the samples' order, b then a
          for (uint64_t rest = bits; rest != 0; rest &= rest - 1) {
            const int bit = __builtin_ctzll(rest);
            ++dark;
            su += i - 0.5 + (bit % s + 0.5) / s;
            sv += j - 0.5 + (bit / s + 0.5) / s;
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
  if (exact_sums) {
    su = static_cast<double>(su2s) / (2 * s);
    sv = static_cast<double>(sv2s) / (2 * s);
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
      bool near = da.overlapping && std::count(da.neighbours.begin(), da.neighbours.end(), db.id) > 0;
      // Some rim pair closer than the gap. A point of rim a farther than max_radius_px + gap from b's
      // centroid has no such partner (triangle inequality, with a margin for round-off).
      const double reach = db.max_radius_px + merge_gap_px + 1e-9;
      for (size_t k = 0; k < rims[a].size() && !near; ++k) {
        const Eigen::Vector2d& p = rims[a][k];
        if ((p - db.area_centroid_px).squaredNorm() > reach * reach) continue;
        for (const Eigen::Vector2d& q : rims[b]) {
          if (std::sqrt((p - q).squaredNorm()) < merge_gap_px) {
            near = true;
            break;
          }
        }
      }
      if (near) {
        da.near_other = db.near_other = true;
        if (std::count(da.neighbours.begin(), da.neighbours.end(), db.id) == 0) {
          da.neighbours.push_back(db.id);
          db.neighbours.push_back(da.id);
        }
      }
    }
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
  FrameLease lease(width, height);
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
    SampleDisc(camera, c, n, r, options.supersampling, bounds, d, &out.dots, &lease.buffers());
  }
  MarkNearNeighbours(rims, options.merge_gap_px, &out.dots);
  FormImage(&lease.buffers(), options, noise_seed, &out.image);
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
