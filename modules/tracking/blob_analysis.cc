#include "tracking/blob_analysis.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <optional>
#include <sstream>
#include <vector>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "tracking/blob_window.h"

namespace selfcal::tracking::internal {
namespace {

constexpr int kEllipseSamples = 20;  // as vpDot2::isValid

// Buffers reused from blob to blob (MeasureBlob runs for every candidate and every tracked dot of a
// frame); each user clears what it fills.
struct Scratch {
  BlobWindow win;
  std::vector<PixelRun> runs;
  GreyHistogram values, ring;
};


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

// The blob's grey levels and the raw sums of its pixel centres, relative to the bbox corner (px).
struct BlobSums {
  GreyHistogram& values;
  double su = 0, sv = 0, suu = 0, suv = 0, svv = 0;
};

// Area, dot level and second moments from the blob's own pixels (pixel centres, in double: vpDot2's
// moments are accumulated from float increments such as u^3 / 3 and lose most of their digits for
// small blobs far from the image origin; a 3 px disc at u = 512 came out with an axis ratio of 0.7).
// The sums are of integers, added run by run in 64-bit integers: the same values a pixel-by-pixel double
// sum gives (every partial sum is an integer below 2^53).
BlobSums SumBlob(const vpImage<unsigned char>& image, const std::vector<PixelRun>& runs, const PixelBox& bbox,
                 GreyHistogram* values) {
  values->Clear();
  BlobSums b{*values};
  auto squares = [](std::int64_t k) { return k * (k + 1) * (2 * k + 1) / 6; };  // 0^2 + ... + k^2
  std::int64_t su = 0, sv = 0, suu = 0, suv = 0, svv = 0;
  for (const PixelRun& run : runs) {
    const unsigned char* row = image[run.v];
    for (int u = run.u_begin; u <= run.u_end; ++u) b.values.Add(row[u]);
    const std::int64_t x0 = run.u_begin - bbox.u_min, x1 = run.u_end - bbox.u_min, y = run.v - bbox.v_min;
    const std::int64_t count = x1 - x0 + 1, sum_x = (x0 + x1) * count / 2;
    su += sum_x;
    sv += y * count;
    suu += squares(x1) - (x0 > 0 ? squares(x0 - 1) : 0);
    suv += y * sum_x;
    svv += y * y * count;
  }
  b.su = static_cast<double>(su);
  b.sv = static_cast<double>(sv);
  b.suu = static_cast<double>(suu);
  b.suv = static_cast<double>(suv);
  b.svv = static_cast<double>(svv);
  return b;
}

// Background: the free pixels of the ring between the bbox dilated by gap and by gap + width.
void BackgroundRing(const vpImage<unsigned char>& image, const BlobWindow& win, const PixelBox& bbox,
                    const DotAcceptanceOptions& options, GreyHistogram* ring_out) {
  GreyHistogram& ring = *ring_out;
  ring.Clear();
  const int g = options.ring_gap_px, r = options.ring_gap_px + options.ring_width_px;
  const int u_begin = std::max(win.u0, bbox.u_min - r), u_end = std::min(win.u0 + win.w - 1, bbox.u_max + r);
  auto add = [&](const unsigned char* pixels, const std::uint8_t* cells, int from, int to) {
    for (int u = from; u <= to; ++u) {
      if (cells[u - win.u0] == kFree) ring.Add(pixels[u]);
    }
  };
  for (int v = std::max(win.v0, bbox.v_min - r); v <= std::min(win.v0 + win.h - 1, bbox.v_max + r); ++v) {
    const unsigned char* pixels = image[v];
    const std::uint8_t* cells = win.Row(v);
    if (v >= bbox.v_min - g && v <= bbox.v_max + g) {  // skips the gap and the bbox
      add(pixels, cells, u_begin, std::min(u_end, bbox.u_min - g - 1));
      add(pixels, cells, std::max(u_begin, bbox.u_max + g + 1), u_end);
    } else {
      add(pixels, cells, u_begin, u_end);
    }
  }
}

// D2: the largest coverage by the dot of a blob pixel within `margin` px of the image border; nullopt
// when the bbox keeps clear of the margin. A (nearly) fully dark one there means the dot goes on past
// the edge and its centroid is biased.
std::optional<double> WorstBorderCoverage(const vpImage<unsigned char>& image, const BlobWindow& win,
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
    const int ui = static_cast<int>(RoundHalfAway(d.cog_binary_px.x() + c * ai - s * bi));
    const int vi = static_cast<int>(RoundHalfAway(d.cog_binary_px.y() + s * ai + c * bi));
    if (ui < 0 || vi < 0 || ui >= width || vi >= height || static_cast<int>(image[vi][ui]) > threshold) ++inner_bad;
    const double ao = (2.0 - p) * (d.semi_major_px + 1.0) * cos_t;
    const double bo = (2.0 - p) * (d.semi_minor_px + 1.0) * sin_t;
    const int uo = static_cast<int>(RoundHalfAway(d.cog_binary_px.x() + c * ao - s * bo));
    const int vo = static_cast<int>(RoundHalfAway(d.cog_binary_px.y() + s * ao + c * bo));
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
// other blobs (and their rims) excluded. Replaces d->centroid_px when it lies inside the bbox. The
// background is a median of grey levels, so twice every weight is an integer: the sums are kept doubled
// in 64-bit integers, the exact values a double sum gives (every partial sum a multiple of 0.5 below 2^52).
void RefineCentroid(const vpImage<unsigned char>& image, const BlobWindow& win, int refine_margin_px, DotDetection* d) {
  const int width = static_cast<int>(image.getWidth());
  const int height = static_cast<int>(image.getHeight());
  const int rm = refine_margin_px;
  const int twice_background = static_cast<int>(2.0 * d->background_level);
  std::int64_t sw2 = 0, su2 = 0, sv2 = 0;
  const int u_begin = std::max(0, d->bbox.u_min - rm), u_end = std::min(width - 1, d->bbox.u_max + rm);
  for (int v = std::max(0, d->bbox.v_min - rm); v <= std::min(height - 1, d->bbox.v_max + rm); ++v) {
    const unsigned char* pixels = image[v];
    const std::uint8_t* cells = win.Row(v);
    std::int64_t row_w2 = 0, row_u2 = 0;
    for (int u = u_begin; u <= u_end; ++u) {
      const int w2 = twice_background - 2 * static_cast<int>(pixels[u]);
      if (cells[u - win.u0] == kOther || w2 <= 0) continue;
      row_w2 += w2;
      row_u2 += static_cast<std::int64_t>(w2) * u;
    }
    sw2 += row_w2;
    su2 += row_u2;
    sv2 += row_w2 * v;
  }
  if (sw2 > 0) {
    const double sw = 0.5 * static_cast<double>(sw2), su = 0.5 * static_cast<double>(su2), sv = 0.5 * static_cast<double>(sv2);
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
  LevelCounts counts;
  const int mu0 = std::max(0, median_box.u_min), mu1 = std::min(w - 1, median_box.u_max);
  int n = 0;
  for (int v = std::max(0, median_box.v_min); v <= std::min(h - 1, median_box.v_max); ++v) {
    counts.Add(image[v] + mu0, mu1 - mu0 + 1);
    n += std::max(0, mu1 - mu0 + 1);
  }
  levels.median = counts.HalfLevel(n);
  const int u0 = std::max(0, darkest_box.u_min), u1 = std::min(w - 1, darkest_box.u_max);
  unsigned char darkest = 255;
#if defined(__SSE2__)
  __m128i darkest16 = _mm_set1_epi8(-1);  // sixteen columns at a time
#endif
  for (int v = std::max(0, darkest_box.v_min); v <= std::min(h - 1, darkest_box.v_max); ++v) {
    const unsigned char* row = image[v];
    int u = u0;
#if defined(__SSE2__)
    if (u1 - u0 + 1 >= 16) {
      for (; u + 15 <= u1; u += 16) {
        darkest16 = _mm_min_epu8(darkest16, _mm_loadu_si128(reinterpret_cast<const __m128i*>(row + u)));
      }
      if (u <= u1) {  // the last sixteen columns, overlapping the ones done
        darkest16 = _mm_min_epu8(darkest16, _mm_loadu_si128(reinterpret_cast<const __m128i*>(row + u1 - 15)));
      }
      continue;
    }
#endif
    for (; u <= u1; ++u) darkest = std::min(darkest, row[u]);
  }
#if defined(__SSE2__)
  darkest16 = _mm_min_epu8(darkest16, _mm_srli_si128(darkest16, 8));
  darkest16 = _mm_min_epu8(darkest16, _mm_srli_si128(darkest16, 4));
  darkest16 = _mm_min_epu8(darkest16, _mm_srli_si128(darkest16, 2));
  darkest16 = _mm_min_epu8(darkest16, _mm_srli_si128(darkest16, 1));
  darkest = std::min(darkest, static_cast<unsigned char>(_mm_cvtsi128_si32(darkest16) & 0xff));
#endif
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
  const int margin = std::max(options.refine_margin_px, options.ring_gap_px + options.ring_width_px);
  if (!ClassifyBlobWindow(image, threshold, d.bbox, margin, required_seed, &scratch.win, &scratch.runs)) {
    return Reject(RejectReason::kTrackerFailed, required_seed != nullptr
                                                    ? "vpDot2 traced a blob without the seed pixel"
                                                    : "no 8-connected dark blob spans vpDot2's bounding box");
  }
  const BlobWindow& win = scratch.win;

  BlobSums blob = SumBlob(image, scratch.runs, d.bbox, &scratch.values);
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
