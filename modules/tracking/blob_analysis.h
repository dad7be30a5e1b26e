// Module-internal: the measurement and the acceptance checks of one blob that vpDot2 has just traced
// (blob_trace.h),
// shared by DetectDots (dot_detector.h) and TrackDots (dot_tracker.h) so that a detected and a tracked dot
// mean the same thing. Pixel conventions and the checks are those of dot_detector.h.
#pragma once

#include <string>
#include <utility>

#include <visp3/core/vpImage.h>

#include "tracking/blob_trace.h"
#include "tracking/dot_detector.h"

namespace selfcal::tracking::internal {

struct BlobVerdict {
  bool accepted = false;
  RejectReason reason = RejectReason::kCount;  // meaningful when !accepted
  std::string detail;                          // the measured value that failed, in words
};

// `dot` is the blob vpDot2 traced at grey levels [0, threshold] (TrackDarkBlob).
// Measures area, moments, ellipse, contrast and (options.refine_centroid) the intensity-weighted centroid,
// then applies, in this order: area, border, finite values, contrast, ellipsoid test, axis ratio, fill ratio.
// *out is filled (also on rejection, as far as measured). With required_seed (u, v), the blob must hold
// that pixel (kTrackerFailed otherwise).
BlobVerdict MeasureBlob(const vpImage<unsigned char>& image, int threshold, const TracedBlob& dot,
                        const DotAcceptanceOptions& options, DotDetection* out,
                        const std::pair<int, int>* required_seed = nullptr);

// The darkest grey level of `box` and the median of `median_box` (both clipped to the image).
struct Levels {
  int darkest = 255;
  int median = 0;
};
Levels DarkestAndMedian(const vpImage<unsigned char>& image, const PixelBox& box);
Levels DarkestAndMedian(const vpImage<unsigned char>& image, const PixelBox& darkest_box, const PixelBox& median_box);

}  // namespace selfcal::tracking::internal
