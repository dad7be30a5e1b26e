// Dots of either polarity, and the blobs of a printed target told from texture, for `selfcal detect`
// (docs/detect.md, "Dot polarity" and "Texture").
//
// Polarity. tracking::DetectDots finds dark dots on a light background. Light dots on a dark background
// (the white-dot boards sold for OpenCV's calibration) are the dark dots of the inverted image 255 - I:
// every step of the detector (candidates, per-blob threshold, the intensity-weighted centroid with weights
// (background - I)+) is symmetric under that inversion, so a light dot's centroid is as unbiased as a dark
// one's. kAuto looks at both and the caller chooses per image (detect_points.cc: the polarity whose grid is
// found; else, or when both are, the larger ContrastScore).
//
// Texture. A printed target's dots share one size (up to the perspective across the board) and one
// contrast (one ink on one paper); wood grain, cables and shadows do not. ConsistentBlobs keeps the blobs
// whose log area and log contrast lie within max_deviations robust standard deviations (1.4826 MAD) of the
// medians of the densest cluster: the blob with the most others within a factor 2 in area and 1.65 in
// contrast seeds it (its neighbours form the cluster), so that a majority of texture blobs does not move
// the medians, and the MADs are floored (min_log_area_sigma, min_log_contrast_sigma) so that a perfectly
// uniform grid does not refuse its own slightly smaller far dots.
#pragma once

#include <string>
#include <vector>

#include <visp3/core/vpImage.h>

#include "base/status.h"
#include "tracking/dot_detector.h"

namespace selfcal::detection {

enum class Polarity { kDark, kLight, kAuto };
const char* PolarityName(Polarity polarity);  // "dark" / "light" / "auto"
Result<Polarity> ParsePolarity(const std::string& name);

struct BlobFilterOptions {
  bool enabled = true;
  double max_deviations = 4.0;          // robust standard deviations from the cluster's medians
  double min_log_area_sigma = 0.2;      // floors of the robust standard deviations (natural log)
  double min_log_contrast_sigma = 0.12;
  int min_blobs = 6;                    // fewer blobs than this are all kept: no statistics to speak of
  Status Validate() const;
};

// The dots of one polarity (kDark or kLight; throws InvalidArgument for kAuto): DetectDots on the image,
// or on its inversion.
tracking::DetectionReport DetectDotsOfPolarity(const vpImage<unsigned char>& image,
                                               const tracking::DotDetectorOptions& options, Polarity polarity);

// The indices of `dots` kept by the filter above, ascending; every index when disabled or too few dots.
std::vector<size_t> ConsistentBlobs(const std::vector<tracking::DotDetection>& dots, const BlobFilterOptions& options);

// The report with only the blobs ConsistentBlobs keeps; the others counted in `texture_blobs`.
struct FilteredDots {
  tracking::DetectionReport report;
  int texture_blobs = 0;  // blobs left out as inconsistent with the target's
};
FilteredDots FilterTexture(tracking::DetectionReport report, const BlobFilterOptions& options);

// How clearly a set of dots stands out: their count times their median contrast (grey levels).
double ContrastScore(const std::vector<tracking::DotDetection>& dots);

}  // namespace selfcal::detection
