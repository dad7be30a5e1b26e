#include "tracking/dot_tracker.h"

#include <cmath>
#include <limits>
#include <optional>
#include <set>
#include <sstream>

#include <visp3/core/vpException.h>
#include <visp3/core/vpTrackingException.h>

#include "tracking/blob_analysis.h"
#include "tracking/blob_trace.h"

namespace selfcal::tracking {
namespace {

const double kNaN = std::numeric_limits<double>::quiet_NaN();

void SetStatus(TrackedDot* dot, TrackStatus status, const std::string& detail) {
  dot->status = status;
  dot->detail = detail;
  dot->centroid_px = Eigen::Vector2d::Constant(kNaN);  // D1: never a stale or doubtful centroid
}

// The local threshold for dot p: the darkest pixel of the region vpDot2 may search (5 x the previous
// size around the previous centroid) and the median (background) of 3 x that size set it; without
// contrast there is nothing to track, and t is marked lost (nullopt).
std::optional<int> LocalThreshold(const vpImage<unsigned char>& image, const PreviousDot& p,
                                  const DotTrackerOptions& options, TrackedDot* t) {
  auto around = [&](double half_sizes) {
    return PixelBox{static_cast<int>(std::floor(p.centroid_px.x() - half_sizes * p.width_px)),
                    static_cast<int>(std::floor(p.centroid_px.y() - half_sizes * p.height_px)),
                    static_cast<int>(std::ceil(p.centroid_px.x() + half_sizes * p.width_px)),
                    static_cast<int>(std::ceil(p.centroid_px.y() + half_sizes * p.height_px))};
  };
  const internal::Levels levels = internal::DarkestAndMedian(image, around(2.5), around(1.5));
  if (!(levels.median - levels.darkest >= options.acceptance.min_contrast)) {
    std::ostringstream s;
    s << "no dark blob near the previous centroid (contrast " << levels.median - levels.darkest << ", min "
      << options.acceptance.min_contrast << ")";
    SetStatus(t, TrackStatus::kLost, s.str());
    return std::nullopt;
  }
  return (levels.median + levels.darkest) / 2;
}

// Steps 1-3 for one dot: vpDot2 from the previous state, the acceptance checks, the area jump.
void TrackOne(const vpImage<unsigned char>& image, const PreviousDot& p, int global_threshold,
              const DotTrackerOptions& options, TrackedDot* t, RejectionCounts* rejections) {
  t->id = p.id;
  const double width = image.getWidth(), height = image.getHeight();
  if (p.centroid_px.x() < 0 || p.centroid_px.y() < 0 || p.centroid_px.x() > width - 1 ||
      p.centroid_px.y() > height - 1) {
    SetStatus(t, TrackStatus::kLost, "previous centroid outside the image");
    return;
  }
  int threshold = global_threshold;
  if (options.threshold_mode == ThresholdMode::kLocal) {
    const std::optional<int> local = LocalThreshold(image, p, options, t);
    if (!local) return;
    threshold = *local;
  }
  internal::TracedBlob dot;
  try {
    dot = internal::TrackDarkBlob(image, threshold, p.centroid_px, p.width_px, p.height_px);
  } catch (const vpTrackingException& e) {
    SetStatus(t, TrackStatus::kLost, std::string("vpDot2: ") + e.getMessage());
    return;
  } catch (const vpException& e) {
    SetStatus(t, TrackStatus::kLost, std::string("vpDot2 (") + e.getMessage() + ")");
    return;
  }
  const internal::BlobVerdict verdict = internal::MeasureBlob(image, threshold, dot, options.acceptance, &t->measurement);
  t->motion_px = (t->measurement.cog_binary_px - p.centroid_px).norm();
  if (!verdict.accepted) {
    rejections->Add(verdict.reason);
    if (verdict.reason == RejectReason::kBorder) {
      SetStatus(t, TrackStatus::kBorder, verdict.detail);
    } else if (verdict.reason == RejectReason::kTrackerFailed) {
      SetStatus(t, TrackStatus::kLost, verdict.detail);
    } else {
      SetStatus(t, TrackStatus::kRejected, std::string(RejectReasonName(verdict.reason)) + ": " + verdict.detail);
    }
    return;
  }
  t->motion_px = (t->measurement.centroid_px - p.centroid_px).norm();
  const double ratio = t->measurement.area_px2 / p.area_px2;
  if (ratio > options.max_area_ratio || ratio < 1.0 / options.max_area_ratio) {
    std::ostringstream s;
    s << "area " << p.area_px2 << " -> " << t->measurement.area_px2 << " px^2 (ratio " << ratio << ", max "
      << options.max_area_ratio << ")";
    SetStatus(t, TrackStatus::kAreaJump, s.str());
    return;
  }
  t->status = TrackStatus::kTracked;
  t->centroid_px = t->measurement.centroid_px;
}

// Step 4: ids that ended on the same blob, whatever else was wrong with it: two dots fusing into one
// blob also jump in area and may fail the shape checks, and "merged" says more than either.
void MarkMerged(double merge_distance_px, std::vector<TrackedDot>* dots) {
  auto found = [](const TrackedDot& t) { return t.status != TrackStatus::kLost; };
  std::vector<bool> merged(dots->size(), false);
  const double merge2 = merge_distance_px * merge_distance_px;
  for (size_t i = 0; i < dots->size(); ++i) {
    if (!found((*dots)[i])) continue;
    for (size_t j = i + 1; j < dots->size(); ++j) {
      if (!found((*dots)[j])) continue;
      const DotDetection& a = (*dots)[i].measurement;
      const DotDetection& b = (*dots)[j].measurement;
      // The same blob, possibly binarised at two thresholds: each centroid inside the other's box.
      auto inside = [](const Eigen::Vector2d& c, const PixelBox& box) {
        return c.x() >= box.u_min && c.x() <= box.u_max && c.y() >= box.v_min && c.y() <= box.v_max;
      };
      if ((inside(a.centroid_px, b.bbox) && inside(b.centroid_px, a.bbox)) ||
          (a.centroid_px - b.centroid_px).squaredNorm() <= merge2) {
        merged[i] = merged[j] = true;
      }
    }
  }
  for (size_t i = 0; i < dots->size(); ++i) {
    if (merged[i]) SetStatus(&(*dots)[i], TrackStatus::kMerged, "shares its blob with another id");
  }
}

// Step 5: geometric consistency of the dots still tracked, against a robust planar fit of their
// previous to current centroids; the outliers become kInconsistent.
void CheckConsistency(const std::vector<PreviousDot>& previous, const DotTrackerOptions& options,
                      TrackReport* report) {
  std::vector<size_t> tracked;
  std::vector<Eigen::Vector2d> from, to;
  for (size_t i = 0; i < report->dots.size(); ++i) {
    if (report->dots[i].status != TrackStatus::kTracked) continue;
    tracked.push_back(i);
    from.push_back(previous[i].centroid_px);
    to.push_back(report->dots[i].centroid_px);
  }
  if (static_cast<int>(tracked.size()) < options.min_dots_for_consistency) {
    std::ostringstream s;
    s << "consistency not checked: " << tracked.size() << " tracked dots, need "
      << options.min_dots_for_consistency;
    report->consistency_message = s.str();
    return;
  }
  RobustPlanarFitOptions fit_options = options.consistency;
  fit_options.inlier_threshold = options.consistency_threshold_px;
  const RobustPlanarFit fit = FitPlanarRobust(fit_options, from, to);
  if (!fit.ok) {
    report->consistency_message = "consistency not checked: " + fit.message;
    return;
  }
  report->consistency_checked = true;
  int flagged = 0;
  for (size_t k = 0; k < tracked.size(); ++k) {
    TrackedDot& t = report->dots[tracked[k]];
    t.consistency_residual_px = fit.residuals[k];
    if (!fit.inliers[k]) {
      std::ostringstream s;
      s << "residual " << fit.residuals[k] << " px to the " << PlanarModelName(fit_options.model)
        << " of the other dots (max " << options.consistency_threshold_px << ")";
      SetStatus(&t, TrackStatus::kInconsistent, s.str());
      ++flagged;
    }
  }
  std::ostringstream s;
  s << PlanarModelName(fit_options.model) << " over " << tracked.size() << " dots, " << flagged << " inconsistent";
  report->consistency_message = s.str();
}

}  // namespace

PreviousDot MakePreviousDot(int id, const DotDetection& detection) {
  PreviousDot p;
  p.id = id;
  p.centroid_px = detection.centroid_px;
  p.area_px2 = detection.area_px2;
  p.width_px = detection.bbox.width();
  p.height_px = detection.bbox.height();
  return p;
}

const char* TrackStatusName(TrackStatus status) {
  switch (status) {
    case TrackStatus::kTracked: return "tracked";
    case TrackStatus::kLost: return "lost";
    case TrackStatus::kBorder: return "border";
    case TrackStatus::kRejected: return "rejected";
    case TrackStatus::kAreaJump: return "area_jump";
    case TrackStatus::kMerged: return "merged";
    case TrackStatus::kInconsistent: return "inconsistent";
    case TrackStatus::kCount: break;
  }
  return "unknown";
}

std::string TrackReport::Summary() const {
  std::ostringstream s;
  for (int i = 0; i < static_cast<int>(TrackStatus::kCount); ++i) {
    if (counts[static_cast<size_t>(i)] == 0) continue;
    if (s.tellp() > 0) s << " ";
    s << TrackStatusName(static_cast<TrackStatus>(i)) << "=" << counts[static_cast<size_t>(i)];
  }
  return s.str();
}

Status DotTrackerOptions::Validate() const {
  std::ostringstream s;
  if (threshold_mode == ThresholdMode::kFixed && (fixed_threshold < 0 || fixed_threshold > 254)) {
    s << "fixed_threshold must be in [0, 254], got " << fixed_threshold << "\n";
  }
  if (!(max_area_ratio >= 1)) s << "max_area_ratio must be >= 1, got " << max_area_ratio << "\n";
  if (!(merge_distance_px >= 0)) s << "merge_distance_px must be >= 0, got " << merge_distance_px << "\n";
  if (!(consistency_threshold_px > 0)) {
    s << "consistency_threshold_px must be > 0, got " << consistency_threshold_px << "\n";
  }
  if (min_dots_for_consistency < 4) {
    s << "min_dots_for_consistency must be >= 4, got " << min_dots_for_consistency << "\n";
  }
  const Status a = acceptance.Validate();
  if (!a.ok()) s << a.message();
  const Status c = consistency.Validate();
  if (!c.ok()) s << c.message();
  return s.str().empty() ? Status::Ok() : Status::Error(ErrorCode::kInvalidInput, s.str());
}

TrackReport TrackDots(const vpImage<unsigned char>& image, const std::vector<PreviousDot>& previous,
                      const DotTrackerOptions& options) {
  const Status valid = options.Validate();
  SELFCAL_CHECK(valid.ok(), "invalid DotTrackerOptions:\n" << valid.message());
  SELFCAL_CHECK(image.getWidth() > 0 && image.getHeight() > 0, "empty image");
  std::set<int> ids;
  for (const PreviousDot& p : previous) {
    SELFCAL_CHECK(ids.insert(p.id).second, "duplicate id " << p.id << " in the previous dots");
    SELFCAL_CHECK(p.centroid_px.allFinite(), "previous centroid of id " << p.id << " is not finite");
    SELFCAL_CHECK(std::isfinite(p.area_px2) && p.area_px2 > 0 && p.width_px > 0 && p.height_px > 0,
                  "previous size of id " << p.id << " must be finite and positive");
  }

  TrackReport report;
  report.threshold = ChooseThreshold(image, options.threshold_mode, options.fixed_threshold);
  report.dots.resize(previous.size());
  for (size_t i = 0; i < previous.size(); ++i) {
    TrackOne(image, previous[i], report.threshold, options, &report.dots[i], &report.rejections);
  }
  MarkMerged(options.merge_distance_px, &report.dots);
  CheckConsistency(previous, options, &report);
  for (const TrackedDot& t : report.dots) ++report.counts[static_cast<size_t>(t.status)];
  return report;
}

}  // namespace selfcal::tracking
