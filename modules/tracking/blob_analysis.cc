#include "tracking/blob_analysis.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <optional>
#include <sstream>
#include <vector>

namespace selfcal::tracking::internal {
namespace {

constexpr int kEllipseSamples = 20;  // as vpDot2::isValid

// Window-local classification of pixels around the blob.
enum Cell : std::uint8_t { kFree = 0, kBlob = 1, kOther = 2 };

struct Window {
  int u0 = 0, v0 = 0, w = 0, h = 0;
  std::vector<std::uint8_t> cells;
  bool Contains(int u, int v) const { return u >= u0 && v >= v0 && u < u0 + w && v < v0 + h; }
  std::uint8_t& At(int u, int v) { return cells[static_cast<size_t>((v - v0) * w + (u - u0))]; }
  std::uint8_t At(int u, int v) const { return cells[static_cast<size_t>((v - v0) * w + (u - u0))]; }
};

// Grey levels counted for their median (the mean of the middle two for an even count): the same order
// statistics as sorting them, without the sort.
struct GreyHistogram {
  std::array<int, 256> counts{};
  size_t n = 0;
  void Clear() {
    counts.fill(0);
    n = 0;
  }
  void Add(unsigned char level) {
    ++counts[level];
    ++n;
  }
  double Median() const {
    if (n == 0) return std::nan("");
    auto at_rank = [&](size_t rank) {  // the value sorted to index `rank`
      size_t seen = 0;
      int level = 0;
      for (; level < 255; ++level) {
        seen += static_cast<size_t>(counts[static_cast<size_t>(level)]);
        if (seen > rank) break;
      }
      return static_cast<double>(level);
    };
    const size_t mid = n / 2;
    const double m = at_rank(mid);
    return n % 2 == 0 ? 0.5 * (m + at_rank(mid - 1)) : m;
  }
};

// Buffers reused from blob to blob (MeasureBlob runs for every candidate and every tracked dot of a
// frame); each user clears what it fills.
struct Scratch {
  Window win;
  std::vector<std::pair<int, int>> seeds, stack, filled;
  GreyHistogram values, ring;
};

// Blob pixels: the 8-connected dark pixels, inside the bbox, of the first seed whose component spans
// exactly the bbox vpDot2 reported (other blobs may reach into that box). Every other dark pixel of the
// window, dilated by one pixel (their anti-aliased rim), is "other" and stays out of the background ring
// and of the weighted centroid. nullopt when no seed gives vpDot2's blob.
bool ClassifyWindow(const vpImage<unsigned char>& image, int threshold, const PixelBox& bbox, int margin,
                    Scratch* scratch) {
  constexpr std::uint8_t kDarkUnassigned = 3;  // a dark pixel not yet given to the blob or the others
  Window& win = scratch->win;
  const int width = static_cast<int>(image.getWidth());
  const int height = static_cast<int>(image.getHeight());
  win.u0 = std::max(0, bbox.u_min - margin);
  win.v0 = std::max(0, bbox.v_min - margin);
  win.w = std::min(width - 1, bbox.u_max + margin) - win.u0 + 1;
  win.h = std::min(height - 1, bbox.v_max + margin) - win.v0 + 1;
  win.cells.resize(static_cast<size_t>(win.w * win.h));
  for (int y = 0; y < win.h; ++y) {
    const unsigned char* row = image[win.v0 + y] + win.u0;
    std::uint8_t* cells = &win.cells[static_cast<size_t>(y * win.w)];
    for (int x = 0; x < win.w; ++x) cells[x] = static_cast<int>(row[x]) <= threshold ? kDarkUnassigned : std::uint8_t{kFree};
  }
  // The fill stays inside the bbox; window coordinates from here on.
  const int x0 = bbox.u_min - win.u0, y0 = bbox.v_min - win.v0, x1 = bbox.u_max - win.u0, y1 = bbox.v_max - win.v0;
  const PixelBox local_bbox{x0, y0, x1, y1};
  std::uint8_t* cells = win.cells.data();
  const int w = win.w;
  bool found = false;
  std::vector<std::pair<int, int>>& stack = scratch->stack;
  std::vector<std::pair<int, int>>& filled = scratch->filled;
  stack.clear();
  for (const auto& [seed_u, seed_v] : scratch->seeds) {
    const int sx = seed_u - win.u0, sy = seed_v - win.v0;
    if (sx < x0 || sx > x1 || sy < y0 || sy > y1) continue;
    if (cells[sy * w + sx] != kDarkUnassigned) continue;
    PixelBox span{sx, sy, sx, sy};
    filled.clear();
    cells[sy * w + sx] = kBlob;
    stack.emplace_back(sx, sy);
    while (!stack.empty()) {
      const auto [x, y] = stack.back();
      stack.pop_back();
      filled.emplace_back(x, y);
      span.u_min = std::min(span.u_min, x);
      span.v_min = std::min(span.v_min, y);
      span.u_max = std::max(span.u_max, x);
      span.v_max = std::max(span.v_max, y);
      for (int ny = std::max(y0, y - 1); ny <= std::min(y1, y + 1); ++ny) {
        for (int nx = std::max(x0, x - 1); nx <= std::min(x1, x + 1); ++nx) {
          if (cells[ny * w + nx] != kDarkUnassigned) continue;
          cells[ny * w + nx] = kBlob;
          stack.emplace_back(nx, ny);
        }
      }
    }
    if (span == local_bbox) {
      found = true;
      break;
    }
    for (const auto& [x, y] : filled) cells[y * w + x] = kDarkUnassigned;  // another blob reaching into the box
  }
  if (!found) return false;
  // Every other dark pixel and its free neighbours are "other" (a neighbour made other here is not dark, so
  // it does not spread further).
  for (int y = 0; y < win.h; ++y) {
    for (int x = 0; x < w; ++x) {
      if (cells[y * w + x] != kDarkUnassigned) continue;
      for (int ny = std::max(0, y - 1); ny <= std::min(win.h - 1, y + 1); ++ny) {
        for (int nx = std::max(0, x - 1); nx <= std::min(w - 1, x + 1); ++nx) {
          if (cells[ny * w + nx] == kFree) cells[ny * w + nx] = kOther;
        }
      }
      cells[y * w + x] = kOther;
    }
  }
  return true;
}

BlobVerdict Reject(RejectReason reason, const std::string& detail) {
  BlobVerdict verdict;
  verdict.accepted = false;
  verdict.reason = reason;
  verdict.detail = detail;
  return verdict;
}

std::string Describe(const char* what, double value, const char* limit_name, double limit) {
  std::ostringstream s;
  s << what << " " << value << " (" << limit_name << " " << limit << ")";
  return s.str();
}

// Seeds for the blob's pixels: the required one alone if given; else every pixel of the box's top row,
// which the blob touches. That is enough, and the first border pixel of vpDot2's trace (a copy of its
// border list) is not needed: at most one 8-connected dark component can span the box. Two would hold a
// left-right 8-path (A) and a top-bottom 8-path (B) that share no pixel and are nowhere 8-adjacent; B's
// diagonal steps then each have a corner pixel outside A, so B widens to a top-bottom 4-path outside A,
// which the left-right 8-path A rules out (the Hex theorem). Whichever seed reaches it, the blob is the same.
void BlobSeeds(const PixelBox& bbox, const std::pair<int, int>* required_seed,
               std::vector<std::pair<int, int>>* seeds_out) {
  std::vector<std::pair<int, int>>& seeds = *seeds_out;
  seeds.clear();
  if (required_seed != nullptr) {
    seeds.push_back(*required_seed);
    return;
  }
  for (int u = bbox.u_min; u <= bbox.u_max; ++u) seeds.emplace_back(u, bbox.v_min);
}

// The blob's grey levels and the raw sums of its pixel centres, relative to the bbox corner (px).
struct BlobSums {
  GreyHistogram& values;
  double su = 0, sv = 0, suu = 0, suv = 0, svv = 0;
};

// Area, dot level and second moments from the blob's own pixels (pixel centres, in double: vpDot2's
// moments are accumulated from float increments such as u^3 / 3 and lose most of their digits for
// small blobs far from the image origin; a 3 px disc at u = 512 came out with an axis ratio of 0.7).
BlobSums SumBlob(const vpImage<unsigned char>& image, const Window& win, const PixelBox& bbox,
                 GreyHistogram* values) {
  values->Clear();
  BlobSums b{*values};
  for (int v = bbox.v_min; v <= bbox.v_max; ++v) {
    for (int u = bbox.u_min; u <= bbox.u_max; ++u) {
      if (win.At(u, v) != kBlob) continue;
      b.values.Add(image[v][u]);
      const double x = u - bbox.u_min, y = v - bbox.v_min;  // local, to keep the sums small
      b.su += x;
      b.sv += y;
      b.suu += x * x;
      b.suv += x * y;
      b.svv += y * y;
    }
  }
  return b;
}

// Background: the free pixels of the ring between the bbox dilated by gap and by gap + width.
void BackgroundRing(const vpImage<unsigned char>& image, const Window& win, const PixelBox& bbox,
                    const DotAcceptanceOptions& options, GreyHistogram* ring_out) {
  GreyHistogram& ring = *ring_out;
  ring.Clear();
  const int g = options.ring_gap_px, r = options.ring_gap_px + options.ring_width_px;
  for (int v = bbox.v_min - r; v <= bbox.v_max + r; ++v) {
    const bool inner_row = v >= bbox.v_min - g && v <= bbox.v_max + g;  // skips the gap and the bbox
    for (int u = bbox.u_min - r; u <= bbox.u_max + r; ++u) {
      if (inner_row && u == bbox.u_min - g) u = bbox.u_max + g + 1;
      if (u > bbox.u_max + r) break;
      if (!win.Contains(u, v) || win.At(u, v) != kFree) continue;
      ring.Add(image[v][u]);
    }
  }
}

// D2: the largest coverage by the dot of a blob pixel within `margin` px of the image border; nullopt
// when the bbox keeps clear of the margin. A (nearly) fully dark one there means the dot goes on past
// the edge and its centroid is biased.
std::optional<double> WorstBorderCoverage(const vpImage<unsigned char>& image, const Window& win,
                                          const DotDetection& d, int margin) {
  const int width = static_cast<int>(image.getWidth());
  const int height = static_cast<int>(image.getHeight());
  const int m = margin;
  if (!(d.bbox.u_min < m || d.bbox.v_min < m || d.bbox.u_max > width - 1 - m || d.bbox.v_max > height - 1 - m)) {
    return std::nullopt;
  }
  double worst = 0;
  for (int v = d.bbox.v_min; v <= d.bbox.v_max; ++v) {
    for (int u = d.bbox.u_min; u <= d.bbox.u_max; ++u) {
      if (win.At(u, v) != kBlob) continue;
      if (u >= m && v >= m && u <= width - 1 - m && v <= height - 1 - m) continue;
      const double coverage =
          d.contrast > 0 ? (d.background_level - image[v][u]) / d.contrast : 1.0;
      worst = std::max(worst, coverage);
    }
  }
  return worst;
}

// The ellipse of the second moments: semi-axes (2 sqrt of the eigenvalues), angle and fill ratio.
void SetEllipse(DotDetection* d) {
  const double half_sum = 0.5 * (d->n20_px2 + d->n02_px2);
  const double root =
      std::sqrt(0.25 * (d->n20_px2 - d->n02_px2) * (d->n20_px2 - d->n02_px2) + d->n11_px2 * d->n11_px2);
  d->semi_major_px = 2.0 * std::sqrt(std::max(0.0, half_sum + root));
  d->semi_minor_px = 2.0 * std::sqrt(std::max(0.0, half_sum - root));
  d->angle_rad = 0.5 * std::atan2(2.0 * d->n11_px2, d->n20_px2 - d->n02_px2);
  d->fill_ratio = d->semi_minor_px > 0 ? d->area_px2 / (M_PI * d->semi_major_px * d->semi_minor_px) : 0.0;
}

// vpDot2's ellipsoid test, counted here instead of silently inside vpDot2: samples on a shrunken
// ellipse that are not dark (inner) and on a grown one that are (outer). Empty when it passes.
std::string EllipseTestFailure(const vpImage<unsigned char>& image, int threshold, const DotDetection& d,
                               const DotAcceptanceOptions& options) {
  const int width = static_cast<int>(image.getWidth());
  const int height = static_cast<int>(image.getHeight());
  const double p = options.ellipse_shape_precision;
  const double c = std::cos(d.angle_rad), s = std::sin(d.angle_rad);
  const int max_bad = static_cast<int>(kEllipseSamples * options.ellipse_bad_points_fraction);
  int inner_bad = 0, outer_bad = 0;
  static const std::array<std::pair<double, double>, kEllipseSamples> kCosSin = [] {
    std::array<std::pair<double, double>, kEllipseSamples> table;
    for (int k = 0; k < kEllipseSamples; ++k) {
      const double t = 2.0 * M_PI * k / kEllipseSamples;
      table[static_cast<size_t>(k)] = {std::cos(t), std::sin(t)};
    }
    return table;
  }();
  for (int k = 0; k < kEllipseSamples; ++k) {
    const auto [cos_t, sin_t] = kCosSin[static_cast<size_t>(k)];
    const double ai = p * std::max(0.0, d.semi_major_px - 1.0) * cos_t;
    const double bi = p * std::max(0.0, d.semi_minor_px - 1.0) * sin_t;
    const int ui = static_cast<int>(std::lround(d.cog_binary_px.x() + c * ai - s * bi));
    const int vi = static_cast<int>(std::lround(d.cog_binary_px.y() + s * ai + c * bi));
    if (ui < 0 || vi < 0 || ui >= width || vi >= height || static_cast<int>(image[vi][ui]) > threshold) ++inner_bad;
    const double ao = (2.0 - p) * (d.semi_major_px + 1.0) * cos_t;
    const double bo = (2.0 - p) * (d.semi_minor_px + 1.0) * sin_t;
    const int uo = static_cast<int>(std::lround(d.cog_binary_px.x() + c * ao - s * bo));
    const int vo = static_cast<int>(std::lround(d.cog_binary_px.y() + s * ao + c * bo));
    if (uo < 0 || vo < 0 || uo >= width || vo >= height) continue;
    if (static_cast<int>(image[vo][uo]) <= threshold) ++outer_bad;
  }
  if (inner_bad <= max_bad && outer_bad <= max_bad) return "";
  std::ostringstream s_detail;
  s_detail << "ellipsoid test: " << inner_bad << " inner and " << outer_bad << " outer samples of "
           << kEllipseSamples << " wrong (max " << max_bad << ")";
  return s_detail.str();
}

// Intensity-weighted centroid: weights (background - I)+ over the bbox dilated by refine_margin_px,
// other blobs (and their rims) excluded. Replaces d->centroid_px when it lies inside the bbox.
void RefineCentroid(const vpImage<unsigned char>& image, const Window& win, int refine_margin_px, DotDetection* d) {
  const int width = static_cast<int>(image.getWidth());
  const int height = static_cast<int>(image.getHeight());
  const int rm = refine_margin_px;
  double sw = 0, su = 0, sv = 0;
  for (int v = std::max(0, d->bbox.v_min - rm); v <= std::min(height - 1, d->bbox.v_max + rm); ++v) {
    for (int u = std::max(0, d->bbox.u_min - rm); u <= std::min(width - 1, d->bbox.u_max + rm); ++u) {
      if (win.At(u, v) == kOther) continue;
      const double w = d->background_level - static_cast<double>(image[v][u]);
      if (w <= 0) continue;
      sw += w;
      su += w * u;
      sv += w * v;
    }
  }
  if (sw > 0) {
    const Eigen::Vector2d c_w(su / sw, sv / sw);
    if (c_w.allFinite() && c_w.x() >= d->bbox.u_min && c_w.x() <= d->bbox.u_max && c_w.y() >= d->bbox.v_min &&
        c_w.y() <= d->bbox.v_max) {
      d->centroid_px = c_w;
      d->refined = true;
    }
  }
}

}  // namespace

Levels DarkestAndMedian(const vpImage<unsigned char>& image, const PixelBox& box) {
  return DarkestAndMedian(image, box, box);
}

Levels DarkestAndMedian(const vpImage<unsigned char>& image, const PixelBox& darkest_box, const PixelBox& median_box) {
  const int w = static_cast<int>(image.getWidth()), h = static_cast<int>(image.getHeight());
  Levels levels;
  // Four histograms filled in turn, then added: runs of one grey level do not wait on one counter.
  std::array<std::array<int, 256>, 4> parts{};
  const int mu0 = std::max(0, median_box.u_min), mu1 = std::min(w - 1, median_box.u_max);
  int n = 0;
  for (int v = std::max(0, median_box.v_min); v <= std::min(h - 1, median_box.v_max); ++v) {
    const unsigned char* row = image[v];
    int u = mu0;
    for (; u + 3 <= mu1; u += 4) {
      ++parts[0][row[u]];
      ++parts[1][row[u + 1]];
      ++parts[2][row[u + 2]];
      ++parts[3][row[u + 3]];
    }
    for (; u <= mu1; ++u) ++parts[0][row[u]];
    n += std::max(0, mu1 - mu0 + 1);
  }
  std::array<int, 256> hist;
  for (size_t i = 0; i < 256; ++i) hist[i] = parts[0][i] + parts[1][i] + parts[2][i] + parts[3][i];
  for (int seen = 0; levels.median < 255; ++levels.median) {
    seen += hist[static_cast<size_t>(levels.median)];
    if (2 * seen >= n) break;
  }
  const int u0 = std::max(0, darkest_box.u_min), u1 = std::min(w - 1, darkest_box.u_max);
  unsigned char darkest = 255;
  for (int v = std::max(0, darkest_box.v_min); v <= std::min(h - 1, darkest_box.v_max); ++v) {
    const unsigned char* row = image[v];
    for (int u = u0; u <= u1; ++u) darkest = std::min(darkest, row[u]);
  }
  levels.darkest = darkest;
  return levels;
}

BlobVerdict MeasureBlob(const vpImage<unsigned char>& image, int threshold, const TracedBlob& dot,
                        const DotAcceptanceOptions& options, DotDetection* out,
                        const std::pair<int, int>* required_seed) {
  DotDetection& d = *out;
  d = DotDetection();
  const int width = static_cast<int>(image.getWidth());
  const int height = static_cast<int>(image.getHeight());

  d.bbox = dot.bbox;
  d.threshold = threshold;
  d.cog_binary_px = dot.cog_px;
  d.centroid_px = d.cog_binary_px;
  d.polygon_area_px2 = dot.polygon_area_px2;
  if (d.bbox.u_min < 0 || d.bbox.v_min < 0 || d.bbox.u_max >= width || d.bbox.v_max >= height ||
      d.bbox.width() <= 0 || d.bbox.height() <= 0) {
    return Reject(RejectReason::kTrackerFailed, "vpDot2 returned a bounding box outside the image");
  }
  thread_local Scratch scratch;
  BlobSeeds(d.bbox, required_seed, &scratch.seeds);
  const int margin = std::max(options.refine_margin_px, options.ring_gap_px + options.ring_width_px);
  if (!ClassifyWindow(image, threshold, d.bbox, margin, &scratch)) {
    return Reject(RejectReason::kTrackerFailed, required_seed != nullptr
                                                    ? "vpDot2 traced a blob without the seed pixel"
                                                    : "no 8-connected dark blob spans vpDot2's bounding box");
  }
  const Window& win = scratch.win;

  BlobSums blob = SumBlob(image, win, d.bbox, &scratch.values);
  d.area_px2 = static_cast<double>(blob.values.n);
  if (d.area_px2 < options.min_area_px2) {
    return Reject(RejectReason::kTooSmall, Describe("area", d.area_px2, "min", options.min_area_px2));
  }
  if (d.area_px2 > options.max_area_px2) {
    return Reject(RejectReason::kTooLarge, Describe("area", d.area_px2, "max", options.max_area_px2));
  }

  GreyHistogram& ring = scratch.ring;
  BackgroundRing(image, win, d.bbox, options, &ring);
  if (ring.n < 8) {
    return Reject(RejectReason::kLowContrast, "fewer than 8 background pixels around the blob");
  }
  d.background_level = ring.Median();
  d.dot_level = blob.values.Median();
  d.contrast = d.background_level - d.dot_level;

  const std::optional<double> worst = WorstBorderCoverage(image, win, d, options.border_margin_px);
  if (worst && *worst >= options.max_edge_coverage) {
    return Reject(RejectReason::kBorder, Describe("coverage of a pixel within the border margin", *worst, "max",
                                                  options.max_edge_coverage));
  }
  const double n = d.area_px2;
  d.n20_px2 = blob.suu / n - (blob.su / n) * (blob.su / n);
  d.n11_px2 = blob.suv / n - (blob.su / n) * (blob.sv / n);
  d.n02_px2 = blob.svv / n - (blob.sv / n) * (blob.sv / n);

  // D7: vpDot2's centre of gravity and the moments must be finite.
  if (!d.cog_binary_px.allFinite() || !std::isfinite(d.polygon_area_px2) || !std::isfinite(d.n20_px2) ||
      !std::isfinite(d.n11_px2) || !std::isfinite(d.n02_px2)) {
    return Reject(RejectReason::kNonFinite, "non-finite vpDot2 centre of gravity or moments");
  }
  SetEllipse(&d);

  if (!(d.contrast >= options.min_contrast)) {
    return Reject(RejectReason::kLowContrast, Describe("contrast", d.contrast, "min", options.min_contrast));
  }
  if (options.ellipse_shape_precision > 0) {
    const std::string failure = EllipseTestFailure(image, threshold, d, options);
    if (!failure.empty()) return Reject(RejectReason::kEllipseTest, failure);
  }
  const double axis_ratio = d.semi_major_px > 0 ? d.semi_minor_px / d.semi_major_px : 0.0;
  if (axis_ratio < options.min_axis_ratio) {
    return Reject(RejectReason::kElongated, Describe("axis ratio", axis_ratio, "min", options.min_axis_ratio));
  }
  if (d.fill_ratio < options.min_fill_ratio || d.fill_ratio > options.max_fill_ratio) {
    std::ostringstream s_detail;
    s_detail << "fill ratio " << d.fill_ratio << " outside [" << options.min_fill_ratio << ", "
             << options.max_fill_ratio << "]";
    return Reject(RejectReason::kFillRatio, s_detail.str());
  }
  if (options.refine_centroid) RefineCentroid(image, win, options.refine_margin_px, &d);
  BlobVerdict ok;
  ok.accepted = true;
  return ok;
}

}  // namespace selfcal::tracking::internal
