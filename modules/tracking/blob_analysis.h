// Module-internal: the measurement and the acceptance checks of one blob that vpDot2 has just traced
// (blob_trace.h), shared by DetectDots (dot_detector.h) and TrackDots (dot_tracker.h) so that a detected
// and a tracked dot mean the same thing. Pixel conventions and the checks are those of dot_detector.h.
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
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

// Grey levels counted for their median (the mean of the middle two for an even count): the same order
// statistics as sorting them, without the sort. Sixteen coarse bins of 16 levels each find a rank's bin
// before its level.
struct GreyHistogram {
  std::array<int, 256> counts{};
  std::array<int, 16> coarse{};
  size_t n = 0;
  void Clear() {
    counts.fill(0);
    coarse.fill(0);
    n = 0;
  }
  void Add(unsigned char level) {
    ++counts[level];
    ++coarse[level >> 4];
    ++n;
  }
  // The level sorted to index `rank` (< n).
  double AtRank(size_t rank) const {
    size_t seen = 0;
    int bin = 0;
    for (; bin < 15; ++bin) {
      if (seen + static_cast<size_t>(coarse[static_cast<size_t>(bin)]) > rank) break;
      seen += static_cast<size_t>(coarse[static_cast<size_t>(bin)]);
    }
    int level = 16 * bin;
    for (; level < 255; ++level) {
      seen += static_cast<size_t>(counts[static_cast<size_t>(level)]);
      if (seen > rank) break;
    }
    return static_cast<double>(level);
  }
  double Median() const {
    if (n == 0) return std::nan("");
    const size_t mid = n / 2;
    const double m = AtRank(mid);
    return n % 2 == 0 ? 0.5 * (m + AtRank(mid - 1)) : m;
  }
};

// lround (half away from zero) without the library call: the same integer for any |x| < 2^63.
inline long RoundHalfAway(double x) {
  const long t = static_cast<long>(x);  // towards zero
  const double frac = x - static_cast<double>(t);  // exact
  if (frac >= 0.5) return t + 1;
  if (frac <= -0.5) return t - 1;
  return t;
}

// Grey levels counted in four histograms in turn (runs of one level then do not wait on one counter),
// added up by Total.
struct LevelCounts {
  std::array<std::array<std::uint32_t, 256>, 4> parts{};
  void Add(const unsigned char* levels, int n) {
    int i = 0;
    for (; i + 4 <= n; i += 4) {
      ++parts[0][levels[i]];
      ++parts[1][levels[i + 1]];
      ++parts[2][levels[i + 2]];
      ++parts[3][levels[i + 3]];
    }
    for (; i < n; ++i) ++parts[0][levels[i]];
  }
  std::uint32_t Count(int level) const {
    const size_t l = static_cast<size_t>(level);
    return parts[0][l] + parts[1][l] + parts[2][l] + parts[3][l];
  }
  std::array<std::uint32_t, 256> Total() const {
    std::array<std::uint32_t, 256> total;
    for (int l = 0; l < 256; ++l) total[static_cast<size_t>(l)] = Count(l);
    return total;
  }
  // The first level at which the count from level 0 reaches half of n (of n levels added), 255 if none
  // below: whole bins of 16 levels are passed before the level is looked for.
  int HalfLevel(std::int64_t n) const {
    std::int64_t seen = 0;
    int level = 0;
    for (; level < 240; level += 16) {
      std::int64_t bin = 0;
      for (int l = level; l < level + 16; ++l) bin += Count(l);
      if (2 * (seen + bin) >= n) break;
      seen += bin;
    }
    for (; level < 255; ++level) {
      seen += Count(level);
      if (2 * seen >= n) break;
    }
    return level;
  }
};

// The darkest grey level of `box` and the median of `median_box` (both clipped to the image).
struct Levels {
  int darkest = 255;
  int median = 0;
};
Levels DarkestAndMedian(const vpImage<unsigned char>& image, const PixelBox& box);
Levels DarkestAndMedian(const vpImage<unsigned char>& image, const PixelBox& darkest_box, const PixelBox& median_box);

}  // namespace selfcal::tracking::internal
