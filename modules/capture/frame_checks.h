// Per-frame sanity checks (../shared/RELIABILITY.md V6, optional blur V9): a frame that is empty, all black
// (lens cap, dead sensor), saturated (blown exposure), flat (no contrast), blurred (captured while the
// arm vibrated), or out of order is refused with CaptureError::kBadFrame before anyone detects dots in
// it. Thresholds are in grey levels (0..255) of the 8-bit grey image.
#pragma once

#include <cstdint>
#include <string>

#include <visp3/core/vpImage.h>

#include "base/status.h"
#include "capture/frame_source.h"

namespace selfcal::capture {

struct FrameCheckOptions {
  double min_mean_grey = 15.0;          // darker on average: black frame (lens cap, no light)
  double max_mean_grey = 240.0;         // brighter on average: saturated
  double min_stddev_grey = 3.0;         // flatter: no scene (a uniform grey test pattern, a covered lens)
  double max_black_fraction = 0.5;      // fraction of pixels at 0
  double max_saturated_fraction = 0.5;  // fraction of pixels at 255
  // Variance of the 4-neighbour Laplacian over interior pixels (grey^2) below which the frame counts as
  // blurred (V9). 0 disables the check (the default: the value depends on the scene; calibrate it on a
  // frame taken at rest).
  double min_laplacian_variance = 0.0;
  int min_width_px = 8;
  int min_height_px = 8;
  // Empty when valid; otherwise every problem, one per line.
  std::string Validate() const;
};

struct FrameStats {
  int width_px = 0;
  int height_px = 0;
  double mean_grey = 0;
  double stddev_grey = 0;
  double black_fraction = 0;       // pixels == 0
  double saturated_fraction = 0;   // pixels == 255
  double laplacian_variance = -1;  // -1 when not computed
};

// One pass over the image (two with the Laplacian).
FrameStats ComputeFrameStats(const vpImage<unsigned char>& image, bool with_laplacian);

// Variance of the discrete Laplacian L = I(u-1,v) + I(u+1,v) + I(u,v-1) + I(u,v+1) - 4 I(u,v) over the
// interior pixels: large for sharp edges, small for blurred ones (Pech-Pacheco et al. 2000).
double LaplacianVariance(const vpImage<unsigned char>& image);

// OK, or kBadFrame naming `source` and the failed figure with its threshold.
Status CheckFrame(const vpImage<unsigned char>& image, const FrameCheckOptions& options, const std::string& source);

// Order of consecutive frames of one source: the sequence number must advance (equal: a duplicated
// frame) and the exposure time must increase strictly. `previous_sequence` < 0 means no previous frame.
// kBadFrame naming `source`. Gaps in the sequence (dropped frames) are allowed.
Status CheckFrameOrder(int64_t previous_sequence, double previous_exposure_time_s, const Frame& frame);

}  // namespace selfcal::capture
