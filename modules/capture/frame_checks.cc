#include "capture/frame_checks.h"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace selfcal::capture {

std::string FrameCheckOptions::Validate() const {
  std::ostringstream out;
  auto grey = [&](double v, const char* name) {
    if (!std::isfinite(v) || v < 0 || v > 255) out << name << " = " << v << " must lie in [0, 255]\n";
  };
  auto fraction = [&](double v, const char* name) {
    if (!std::isfinite(v) || v < 0 || v > 1) out << name << " = " << v << " must lie in [0, 1]\n";
  };
  grey(min_mean_grey, "min_mean_grey");
  grey(max_mean_grey, "max_mean_grey");
  grey(min_stddev_grey, "min_stddev_grey");
  if (min_mean_grey >= max_mean_grey) {
    out << "min_mean_grey = " << min_mean_grey << " must be below max_mean_grey = " << max_mean_grey << "\n";
  }
  fraction(max_black_fraction, "max_black_fraction");
  fraction(max_saturated_fraction, "max_saturated_fraction");
  if (!std::isfinite(min_laplacian_variance) || min_laplacian_variance < 0) {
    out << "min_laplacian_variance = " << min_laplacian_variance << " must be finite and >= 0\n";
  }
  if (min_width_px < 1 || min_height_px < 1) out << "min_width_px and min_height_px must be >= 1\n";
  return out.str();
}

double LaplacianVariance(const vpImage<unsigned char>& image) {
  const int w = static_cast<int>(image.getWidth()), h = static_cast<int>(image.getHeight());
  if (w < 3 || h < 3) return 0.0;
  double sum = 0, sum2 = 0;
  for (int v = 1; v < h - 1; ++v) {
    const unsigned char* above = image[v - 1];
    const unsigned char* row = image[v];
    const unsigned char* below = image[v + 1];
    for (int u = 1; u < w - 1; ++u) {
      const double l = static_cast<double>(row[u - 1]) + row[u + 1] + above[u] + below[u] - 4.0 * row[u];
      sum += l;
      sum2 += l * l;
    }
  }
  const double n = static_cast<double>(w - 2) * (h - 2);
  const double mean = sum / n;
  return std::max(0.0, sum2 / n - mean * mean);
}

FrameStats ComputeFrameStats(const vpImage<unsigned char>& image, bool with_laplacian) {
  FrameStats stats;
  stats.width_px = static_cast<int>(image.getWidth());
  stats.height_px = static_cast<int>(image.getHeight());
  const size_t n = static_cast<size_t>(stats.width_px) * static_cast<size_t>(stats.height_px);
  if (n == 0) return stats;
  // Integer sums: exact whatever the image size up to 2^64 / 255^2 pixels.
  uint64_t sum = 0, sum2 = 0, black = 0, saturated = 0;
  const unsigned char* p = image.bitmap;
  for (size_t i = 0; i < n; ++i) {
    const uint64_t g = p[i];
    sum += g;
    sum2 += g * g;
    black += g == 0;
    saturated += g == 255;
  }
  const double count = static_cast<double>(n);
  stats.mean_grey = static_cast<double>(sum) / count;
  stats.stddev_grey = std::sqrt(std::max(0.0, static_cast<double>(sum2) / count - stats.mean_grey * stats.mean_grey));
  stats.black_fraction = static_cast<double>(black) / count;
  stats.saturated_fraction = static_cast<double>(saturated) / count;
  if (with_laplacian) stats.laplacian_variance = LaplacianVariance(image);
  return stats;
}

Status CheckFrame(const vpImage<unsigned char>& image, const FrameCheckOptions& options, const std::string& source) {
  const FrameStats s = ComputeFrameStats(image, options.min_laplacian_variance > 0);
  std::ostringstream why;
  if (s.width_px < options.min_width_px || s.height_px < options.min_height_px) {
    why << "the image is " << s.width_px << "x" << s.height_px << " px (empty or truncated)";
  } else if (s.mean_grey < options.min_mean_grey) {
    why << "all black: mean grey " << s.mean_grey << " < " << options.min_mean_grey << " (lens cap? no light?)";
  } else if (s.mean_grey > options.max_mean_grey) {
    why << "saturated: mean grey " << s.mean_grey << " > " << options.max_mean_grey << " (exposure too long?)";
  } else if (s.black_fraction > options.max_black_fraction) {
    why << "black: " << 100 * s.black_fraction << "% of the pixels are 0 (limit " << 100 * options.max_black_fraction
        << "%)";
  } else if (s.saturated_fraction > options.max_saturated_fraction) {
    why << "saturated: " << 100 * s.saturated_fraction << "% of the pixels are 255 (limit "
        << 100 * options.max_saturated_fraction << "%)";
  } else if (s.stddev_grey < options.min_stddev_grey) {
    why << "no contrast: grey standard deviation " << s.stddev_grey << " < " << options.min_stddev_grey;
  } else if (options.min_laplacian_variance > 0 && s.laplacian_variance < options.min_laplacian_variance) {
    why << "blurred: Laplacian variance " << s.laplacian_variance << " < " << options.min_laplacian_variance
        << " (captured while moving?)";
  }
  const std::string reason = why.str();
  if (reason.empty()) return Status::Ok();
  return CaptureFailure(CaptureError::kBadFrame, "bad frame from " + source + ": " + reason);
}

Status CheckFrameOrder(int64_t previous_sequence, double previous_exposure_time_s, const Frame& frame) {
  if (previous_sequence < 0) return Status::Ok();
  std::ostringstream why;
  if (frame.sequence == previous_sequence) {
    why << "duplicated frame: sequence number " << frame.sequence << " again";
  } else if (frame.sequence < previous_sequence) {
    why << "sequence number went back from " << previous_sequence << " to " << frame.sequence;
  } else if (!(frame.exposure_time_s > previous_exposure_time_s)) {
    why.precision(17);
    why << "exposure time " << frame.exposure_time_s << " s is not after the previous frame's "
        << previous_exposure_time_s << " s";
  }
  const std::string reason = why.str();
  if (reason.empty()) return Status::Ok();
  return CaptureFailure(CaptureError::kBadFrame, "bad frame from " + frame.source + ": " + reason);
}

}  // namespace selfcal::capture
