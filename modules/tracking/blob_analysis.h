// Module-internal: the measurement and the acceptance checks of one blob that vpDot2 has just traced,
// shared by DetectDots (dot_detector.h) and TrackDots (dot_tracker.h) so that a detected and a tracked dot
// mean the same thing. Pixel conventions and the checks are those of dot_detector.h.
#pragma once

#include <string>
#include <utility>

#include <visp3/blob/vpDot2.h>
#include <visp3/core/vpImage.h>

#include "tracking/dot_detector.h"

namespace selfcal::tracking::internal {

struct BlobVerdict {
  bool accepted = false;
  RejectReason reason = RejectReason::kCount;  // meaningful when !accepted
  std::string detail;                          // the measured value that failed, in words
};

// `dot` must have traced its blob with moments on (setComputeMoments(true)) and grey levels [0, threshold].
// Measures area, moments, ellipse, contrast and (options.refine_centroid) the intensity-weighted centroid,
// then applies, in this order: area, border, finite values, contrast, ellipsoid test, axis ratio, fill ratio.
// *out is filled (also on rejection, as far as measured). With required_seed (u, v), the blob must hold
// that pixel (kTrackerFailed otherwise).
BlobVerdict MeasureBlob(const vpImage<unsigned char>& image, int threshold, const vpDot2& dot,
                        const DotAcceptanceOptions& options, DotDetection* out,
                        const std::pair<int, int>* required_seed = nullptr);

// The darkest grey level of `box` and the median of `median_box` (both clipped to the image).
struct Levels {
  int darkest = 255;
  int median = 0;
};
Levels DarkestAndMedian(const vpImage<unsigned char>& image, const PixelBox& box);
Levels DarkestAndMedian(const vpImage<unsigned char>& image, const PixelBox& darkest_box, const PixelBox& median_box);

// vpDot2's bounding box in inclusive pixel bounds.
PixelBox BoxOf(const vpDot2& dot);

// A vpDot2 configured for dark blobs at levels [0, threshold] with vpDot2's own size and ellipsoid checks
// off (MeasureBlob applies counted equivalents) and moments on.
vpDot2 MakeDarkDot(int threshold);

}  // namespace selfcal::tracking::internal
