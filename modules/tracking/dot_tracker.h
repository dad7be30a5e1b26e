// Frame-to-frame tracking of identified dots with vpDot2::track, with a status per dot and identity checks
// (../shared/RELIABILITY.md D1, D2, D4, D7).
//
// Pixels and grey levels as dot_detector.h. The caller keeps the identities: it passes the previous
// frame's dots (id -> centroid and size) and receives, in the same order, each id's status in the new
// frame. A dot whose status is not kTracked has a NaN centroid: the previous centroid is never carried
// over (D1).
//
// Per dot, TrackDots
//   1. seeds a vpDot2 at the previous centroid with the previous width and height, grey levels [0, T] and
//      calls vpDot2::track. T: with kLocal, half way between the darkest pixel of the region vpDot2 may
//      search (5 x the previous size around the previous centroid) and the median of 3 x the previous size
//      (the background), and kLost when these differ by less than min_contrast; otherwise the frame's
//      threshold. vpDot2 vpDot2 re-traces the blob under the
//      previous centroid, or, when that pixel is no longer dark, takes the blob nearest to it in a window
//      of 5x the previous size. A vpTrackingException (or any vpException) -> kLost;
//   2. measures the blob with the detector's checks (blob_analysis.h): clipped by the border margin ->
//      kBorder; any other check fails -> kRejected (counted by reason in `rejections`);
//   3. area jump: new area / previous area outside [1/max_area_ratio, max_area_ratio] -> kAreaJump;
// then over the whole set (D4)
//   4. merge: two or more ids (of any status but kLost) whose blobs are the same (each centroid inside the
//      other's bounding box, or centroids closer than merge_distance_px) -> all of them kMerged (two dots that fused, or one id that
//      jumped onto its neighbour);
//   5. geometric consistency: a robust homography (or affine map) from the previous to the new centroids of
//      the dots still kTracked; a dot whose transfer residual exceeds consistency_threshold_px -> kInconsistent
//      (an identity swap moves a dot by about one dot spacing against the motion of the others). With fewer
//      than min_dots_for_consistency dots, or when the fit finds too few inliers, the check is not made and
//      `consistency_checked` is false with the reason in `consistency_message`: the statuses then rest on
//      steps 1-4 only, and a caller that needs D4 must treat the frame as unverified.
#pragma once

#include <array>
#include <limits>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <visp3/core/vpImage.h>

#include "base/status.h"
#include "tracking/dot_detector.h"
#include "tracking/planar_fit.h"

namespace selfcal::tracking {

// One identified dot of the previous frame.
struct PreviousDot {
  int id = -1;
  Eigen::Vector2d centroid_px = Eigen::Vector2d::Zero();
  double area_px2 = 0;   // DotDetection::area_px2
  double width_px = 0;   // bounding box width and height
  double height_px = 0;
};

// The PreviousDot of an id from a detection or a tracked measurement.
PreviousDot MakePreviousDot(int id, const DotDetection& detection);

enum class TrackStatus {
  kTracked = 0,
  kLost,          // vpDot2 lost it (exception), or its blob left the image
  kBorder,        // found, but its bounding box is within the border margin (D2)
  kRejected,      // found, but it failed a detector check (contrast, shape, area range)
  kAreaJump,      // area changed by more than max_area_ratio (D4)
  kMerged,        // shares its blob with another id (D4)
  kInconsistent,  // does not follow the motion of the others: a likely identity swap (D4)
  kCount          // number of statuses, not a status
};
const char* TrackStatusName(TrackStatus status);

struct DotTrackerOptions {
  ThresholdMode threshold_mode = ThresholdMode::kLocal;
  int fixed_threshold = 128;
  DotAcceptanceOptions acceptance;       // the detector's checks, applied to every tracked blob
  double max_area_ratio = 1.6;           // step 3
  double merge_distance_px = 1.0;        // step 4
  RobustPlanarFitOptions consistency;    // step 5 (model, RANSAC iterations, seed); its threshold is ignored
  double consistency_threshold_px = 2.0; // step 5
  int min_dots_for_consistency = 6;

  Status Validate() const;
};

struct TrackedDot {
  int id = -1;
  TrackStatus status = TrackStatus::kLost;
  Eigen::Vector2d centroid_px = Eigen::Vector2d::Constant(std::numeric_limits<double>::quiet_NaN());  // NaN unless kTracked
  DotDetection measurement;         // the blob found (meaningful for every status but kLost)
  double motion_px = std::numeric_limits<double>::quiet_NaN();  // |new - previous| when a blob was found
  double consistency_residual_px = std::numeric_limits<double>::quiet_NaN();  // when the check ran
  std::string detail;               // why, for a status other than kTracked
};

struct TrackReport {
  std::vector<TrackedDot> dots;     // same order as the input
  std::array<int, static_cast<int>(TrackStatus::kCount)> counts{};
  RejectionCounts rejections;       // reasons behind kRejected / kBorder
  int threshold = -1;               // the frame's, or -1 with kLocal (see each measurement's)
  bool consistency_checked = false;
  std::string consistency_message;  // why the check did not run, or a summary when it did
  int Count(TrackStatus s) const { return counts[static_cast<size_t>(s)]; }
  // Dots flagged by the identity checks (merged + inconsistent): the swap count of D4.
  int IdentityFlags() const { return Count(TrackStatus::kMerged) + Count(TrackStatus::kInconsistent); }
  std::string Summary() const;      // "tracked=78 lost=1 inconsistent=1"
};

// Tracks `previous` into `image`. Throws InvalidArgument on invalid options, an empty image, duplicate
// ids, or a non-finite previous centroid (D7).
TrackReport TrackDots(const vpImage<unsigned char>& image, const std::vector<PreviousDot>& previous,
                      const DotTrackerOptions& options);

}  // namespace selfcal::tracking
