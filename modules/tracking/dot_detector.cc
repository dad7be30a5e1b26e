#include "tracking/dot_detector.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <sstream>

#include <visp3/core/vpException.h>

#include "tracking/blob_analysis.h"
#include "tracking/blob_trace.h"
#include "tracking/dark_components.h"

namespace selfcal::tracking {
namespace {

void AddProblem(std::ostringstream* s, bool bad, const std::string& text) {
  if (bad) *s << text << "\n";
}

}  // namespace

const char* RejectReasonName(RejectReason reason) {
  switch (reason) {
    case RejectReason::kTooSmall: return "too_small";
    case RejectReason::kTooLarge: return "too_large";
    case RejectReason::kBorder: return "border";
    case RejectReason::kTrackerFailed: return "vpdot2_failed";
    case RejectReason::kNonFinite: return "non_finite";
    case RejectReason::kLowContrast: return "low_contrast";
    case RejectReason::kEllipseTest: return "ellipse_test";
    case RejectReason::kElongated: return "elongated";
    case RejectReason::kFillRatio: return "fill_ratio";
    case RejectReason::kDuplicate: return "duplicate";
    case RejectReason::kCount: break;
  }
  return "unknown";
}

int RejectionCounts::Total() const { return std::accumulate(by_reason.begin(), by_reason.end(), 0); }

std::string RejectionCounts::ToString() const {
  std::ostringstream s;
  for (int r = 0; r < static_cast<int>(RejectReason::kCount); ++r) {
    if (by_reason[static_cast<size_t>(r)] == 0) continue;
    if (s.tellp() > 0) s << " ";
    s << RejectReasonName(static_cast<RejectReason>(r)) << "=" << by_reason[static_cast<size_t>(r)];
  }
  return s.str();
}

Status DotAcceptanceOptions::Validate() const {
  std::ostringstream s;
  AddProblem(&s, !(min_area_px2 >= 4), "min_area_px2 must be >= 4 (vpDot2 needs a border polygon), got " + std::to_string(min_area_px2));
  AddProblem(&s, !(max_area_px2 >= min_area_px2), "max_area_px2 must be >= min_area_px2, got " + std::to_string(max_area_px2));
  AddProblem(&s, border_margin_px < 0, "border_margin_px must be >= 0, got " + std::to_string(border_margin_px));
  AddProblem(&s, !(max_edge_coverage >= 0 && max_edge_coverage <= 1),
             "max_edge_coverage must be in [0, 1], got " + std::to_string(max_edge_coverage));
  AddProblem(&s, !(min_contrast >= 0 && min_contrast <= 255), "min_contrast must be in [0, 255], got " + std::to_string(min_contrast));
  AddProblem(&s, !(ellipse_shape_precision >= 0 && ellipse_shape_precision <= 1),
             "ellipse_shape_precision must be in [0, 1], got " + std::to_string(ellipse_shape_precision));
  AddProblem(&s, !(ellipse_bad_points_fraction >= 0 && ellipse_bad_points_fraction <= 1),
             "ellipse_bad_points_fraction must be in [0, 1], got " + std::to_string(ellipse_bad_points_fraction));
  AddProblem(&s, !(min_axis_ratio >= 0 && min_axis_ratio <= 1), "min_axis_ratio must be in [0, 1], got " + std::to_string(min_axis_ratio));
  AddProblem(&s, !(min_fill_ratio >= 0 && max_fill_ratio >= min_fill_ratio),
             "need 0 <= min_fill_ratio <= max_fill_ratio, got " + std::to_string(min_fill_ratio) + ", " + std::to_string(max_fill_ratio));
  AddProblem(&s, ring_gap_px < 0, "ring_gap_px must be >= 0, got " + std::to_string(ring_gap_px));
  AddProblem(&s, ring_width_px < 1, "ring_width_px must be >= 1, got " + std::to_string(ring_width_px));
  AddProblem(&s, refine_margin_px < 0, "refine_margin_px must be >= 0, got " + std::to_string(refine_margin_px));
  const std::string problems = s.str();
  return problems.empty() ? Status::Ok() : Status::Error(ErrorCode::kInvalidInput, problems);
}

Status DotDetectorOptions::Validate() const {
  std::ostringstream s;
  AddProblem(&s, threshold_mode == ThresholdMode::kFixed && (fixed_threshold < 0 || fixed_threshold > 254),
             "fixed_threshold must be in [0, 254], got " + std::to_string(fixed_threshold));
  AddProblem(&s, !(duplicate_distance_px >= 0), "duplicate_distance_px must be >= 0, got " + std::to_string(duplicate_distance_px));
  AddProblem(&s, adaptive_window_px < 3 || adaptive_window_px % 2 == 0,
             "adaptive_window_px must be odd and >= 3, got " + std::to_string(adaptive_window_px));
  AddProblem(&s, adaptive_offset < 0 || adaptive_offset > 255, "adaptive_offset must be in [0, 255], got " + std::to_string(adaptive_offset));
  const Status acceptance_status = acceptance.Validate();
  if (!acceptance_status.ok()) s << acceptance_status.message();
  const std::string problems = s.str();
  return problems.empty() ? Status::Ok() : Status::Error(ErrorCode::kInvalidInput, problems);
}

int OtsuThreshold(const vpImage<unsigned char>& image) {
  const unsigned int n = image.getSize();
  internal::LevelCounts counts;  // integer counts: the same values as counting in double, faster
  for (unsigned int i = 0; i < n; i += 1u << 30) counts.Add(image.bitmap + i, static_cast<int>(std::min(n - i, 1u << 30)));
  const std::array<std::uint32_t, 256> total = counts.Total();
  std::array<double, 256> hist;
  for (size_t l = 0; l < 256; ++l) hist[l] = static_cast<double>(total[l]);
  double total_sum = 0;
  for (int t = 0; t < 256; ++t) total_sum += t * hist[static_cast<size_t>(t)];
  double w0 = 0, sum0 = 0, best = -1;
  int best_t = 127;
  for (int t = 0; t < 255; ++t) {
    w0 += hist[static_cast<size_t>(t)];
    sum0 += t * hist[static_cast<size_t>(t)];
    const double w1 = n - w0;
    if (w0 <= 0 || w1 <= 0) continue;
    const double mean0 = sum0 / w0, mean1 = (total_sum - sum0) / w1;
    const double between = w0 * w1 * (mean0 - mean1) * (mean0 - mean1);
    if (between > best) {
      best = between;
      best_t = t;
    }
  }
  return best_t;
}

int ChooseThreshold(const vpImage<unsigned char>& image, ThresholdMode mode, int fixed_threshold) {
  switch (mode) {
    case ThresholdMode::kFixed: return fixed_threshold;
    case ThresholdMode::kOtsu: return OtsuThreshold(image);
    case ThresholdMode::kLocal: break;
  }
  return -1;
}

int LocalThreshold(const vpImage<unsigned char>& image, const PixelBox& box) {
  const int grow = std::max(box.width(), box.height());
  const PixelBox around{box.u_min - grow, box.v_min - grow, box.u_max + grow, box.v_max + grow};
  const internal::Levels levels = internal::DarkestAndMedian(image, box, around);
  return (levels.median + levels.darkest) / 2;
}

DetectionReport DetectDots(const vpImage<unsigned char>& image, const DotDetectorOptions& options) {
  const Status valid = options.Validate();
  SELFCAL_CHECK(valid.ok(), "invalid DotDetectorOptions:\n" << valid.message());
  SELFCAL_CHECK(image.getWidth() > 0 && image.getHeight() > 0, "empty image");
  const DotAcceptanceOptions& acc = options.acceptance;

  DetectionReport report;
  report.threshold = ChooseThreshold(image, options.threshold_mode, options.fixed_threshold);
  const bool local = options.threshold_mode == ThresholdMode::kLocal;
  const std::vector<internal::Component> components =
      local ? internal::AdaptiveDarkComponents(image, options.adaptive_window_px, options.adaptive_offset)
            : internal::GlobalDarkComponents(image, report.threshold);
  report.candidates = static_cast<int>(components.size());

  for (const internal::Component& c : components) {
    // Cheap checks first, on the component, so that vpDot2 never traces the background. With kLocal the
    // component also holds the dot's anti-aliased rim, so only a component far above max_area is refused.
    if (c.count < acc.min_area_px2) {
      report.rejections.Add(RejectReason::kTooSmall);
      continue;
    }
    if (c.count > (local ? 2.0 : 1.0) * acc.max_area_px2) {
      report.rejections.Add(RejectReason::kTooLarge);
      continue;
    }
    const int threshold = local ? LocalThreshold(image, c.bbox) : report.threshold;
    if (c.darkest > threshold) {  // no contrast at all: the blob would be empty
      report.rejections.Add(RejectReason::kLowContrast);
      continue;
    }
    // vpDot2 seeded at the darkest pixel (initTracking with size 0); the blob it traces must be the one
    // holding that pixel (its window-search fallback may return another).
    internal::TracedBlob dot;
    try {
      dot = internal::TrackDarkBlob(image, threshold, Eigen::Vector2d(c.darkest_u, c.darkest_v), 0, 0);
    } catch (const vpException&) {
      report.rejections.Add(RejectReason::kTrackerFailed);
      continue;
    }
    DotDetection detection;
    const std::pair<int, int> seed(c.darkest_u, c.darkest_v);
    const internal::BlobVerdict verdict = internal::MeasureBlob(image, threshold, dot, acc, &detection, &seed);
    if (!verdict.accepted) {
      report.rejections.Add(verdict.reason);
      continue;
    }
    // The same blob from two candidates (possible with kLocal): keep it once.
    const bool seen = std::any_of(report.dots.begin(), report.dots.end(), [&](const DotDetection& d) {
      return d.bbox == detection.bbox && d.threshold == detection.threshold && d.area_px2 == detection.area_px2;
    });
    if (seen) {
      report.rejections.Add(RejectReason::kDuplicate);
      continue;
    }
    report.dots.push_back(detection);
  }

  // D6: refuse every dot that has another accepted dot within duplicate_distance_px.
  std::vector<bool> duplicate(report.dots.size(), false);
  const double d2 = options.duplicate_distance_px * options.duplicate_distance_px;
  for (size_t i = 0; i < report.dots.size(); ++i) {
    for (size_t j = i + 1; j < report.dots.size(); ++j) {
      if ((report.dots[i].centroid_px - report.dots[j].centroid_px).squaredNorm() < d2) {
        duplicate[i] = duplicate[j] = true;
      }
    }
  }
  std::vector<DotDetection> kept;
  kept.reserve(report.dots.size());
  for (size_t i = 0; i < report.dots.size(); ++i) {
    if (duplicate[i]) {
      report.rejections.Add(RejectReason::kDuplicate);
    } else {
      kept.push_back(report.dots[i]);
    }
  }
  report.dots = std::move(kept);
  return report;
}

}  // namespace selfcal::tracking
