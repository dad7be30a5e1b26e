// The frame rate a session keeps up with on a real camera at 1280x720 and 1920x1200 (docs/performance.md):
// each step a live frame goes through in `selfcal run`, timed on rendered dot frames of that size:
//   (a) MJPEG decoding (capture::DecodeMjpegFrame) of the frame encoded as a USB camera sends it
//       (YCbCr 4:2:2, quality 85),
//   (b) the per-frame checks every live source applies (capture::CheckFrame, default options),
//   (c) tracking the 80 dots of the previous frame into this one with the session's tracker options
//       (tracking::TrackDots, acquisition::DefaultSessionTracker(): what the session loop does per frame),
//   (d) the whole path, (a) + (b) + (c), whose rate is the figure reported.
// The frames: the 10 x 8 dot sheet of the simulated cell seen larger: the 640x480 layout of tracking_bench
// scaled by min(width / 640, height / 480), dots anti-aliased (8 x 8 supersampled), grey noise sigma 2,
// seeded; the second frame moved by 0.3 deg and (1.2, -0.8) px x the scale.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <random>
#include <vector>

#include <Eigen/Core>
#include <jpeglib.h>
#include <visp3/core/vpImage.h>

#include "acquisition/session_runner.h"
#include "capture/frame_checks.h"
#include "capture/mjpeg_decode.h"
#include "tracking/dot_detector.h"
#include "tracking/dot_tracker.h"

namespace selfcal {
namespace {

struct Frames {
  int width = 0, height = 0;
  vpImage<unsigned char> first, second;
  std::vector<unsigned char> mjpeg;  // `second`, as the camera would send it
  std::vector<tracking::PreviousDot> previous;  // the dots of `first`
};

vpImage<unsigned char> RenderDiscs(int width, int height, const std::vector<Eigen::Vector2d>& centres, double radius,
                                   uint64_t seed) {
  constexpr int kSub = 8;
  constexpr double kBackground = 200, kDot = 40;
  std::vector<double> img(static_cast<size_t>(width) * height, kBackground);
  for (const Eigen::Vector2d& c : centres) {
    for (int v = static_cast<int>(c.y() - radius - 1); v <= static_cast<int>(c.y() + radius + 1); ++v) {
      for (int u = static_cast<int>(c.x() - radius - 1); u <= static_cast<int>(c.x() + radius + 1); ++u) {
        int in = 0;
        for (int j = 0; j < kSub; ++j) {
          for (int i = 0; i < kSub; ++i) {
            const double du = u - 0.5 + (i + 0.5) / kSub - c.x(), dv = v - 0.5 + (j + 0.5) / kSub - c.y();
            in += du * du + dv * dv <= radius * radius ? 1 : 0;
          }
        }
        img[static_cast<size_t>(v) * width + u] += (kDot - kBackground) * in / (kSub * kSub);
      }
    }
  }
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> noise(0.0, 2.0);
  vpImage<unsigned char> out(static_cast<unsigned>(height), static_cast<unsigned>(width));
  for (size_t i = 0; i < img.size(); ++i) {
    out.bitmap[i] = static_cast<unsigned char>(std::clamp(std::lround(img[i] + noise(rng)), 0L, 255L));
  }
  return out;
}

// Baseline JPEG, YCbCr 4:2:2, quality 85: what UVC cameras send in MJPEG mode (OpenCV 4.6's imencode cannot
// choose the subsampling).
std::vector<unsigned char> EncodeLikeAUsbCamera(const vpImage<unsigned char>& grey) {
  jpeg_compress_struct cinfo{};
  jpeg_error_mgr err{};
  cinfo.err = jpeg_std_error(&err);
  jpeg_create_compress(&cinfo);
  unsigned char* out = nullptr;
  unsigned long size = 0;
  jpeg_mem_dest(&cinfo, &out, &size);
  cinfo.image_width = grey.getWidth();
  cinfo.image_height = grey.getHeight();
  cinfo.input_components = 3;
  cinfo.in_color_space = JCS_RGB;
  jpeg_set_defaults(&cinfo);
  jpeg_set_quality(&cinfo, 85, TRUE);
  cinfo.comp_info[0].h_samp_factor = 2;  // 4:2:2
  cinfo.comp_info[0].v_samp_factor = 1;
  jpeg_start_compress(&cinfo, TRUE);
  std::vector<unsigned char> row(3 * grey.getWidth());
  while (cinfo.next_scanline < cinfo.image_height) {
    const unsigned v = cinfo.next_scanline;
    for (unsigned u = 0; u < grey.getWidth(); ++u) row[3 * u] = row[3 * u + 1] = row[3 * u + 2] = grey[v][u];
    JSAMPROW rows[1] = {row.data()};
    jpeg_write_scanlines(&cinfo, rows, 1);
  }
  jpeg_finish_compress(&cinfo);
  std::vector<unsigned char> bytes(out, out + size);
  jpeg_destroy_compress(&cinfo);
  std::free(out);
  return bytes;
}

const Frames& FramesOf(int width, int height) {
  static std::map<std::pair<int, int>, Frames> cache;
  Frames& f = cache[{width, height}];
  if (f.width != 0) return f;
  f.width = width;
  f.height = height;
  const double s = std::min(width / 640.0, height / 480.0);
  const Eigen::Vector2d centre(0.5 * width, 0.5 * height), origin = centre - s * Eigen::Vector2d(320, 240);
  std::mt19937_64 rng(2024);
  std::uniform_real_distribution<double> jitter(-5.0, 5.0);
  std::vector<Eigen::Vector2d> centres, moved;
  const double a = 0.3 * M_PI / 180;
  for (int r = 0; r < 8; ++r) {
    for (int c = 0; c < 10; ++c) {
      const Eigen::Vector2d p = origin + s * Eigen::Vector2d(70.0 + 55.0 * c + jitter(rng), 50.0 + 55.0 * r + jitter(rng));
      centres.push_back(p);
      const Eigen::Vector2d d = p - centre;
      moved.push_back(centre + Eigen::Vector2d(std::cos(a) * d.x() - std::sin(a) * d.y(),
                                               std::sin(a) * d.x() + std::cos(a) * d.y()) +
                      s * Eigen::Vector2d(1.2, -0.8));
    }
  }
  f.first = RenderDiscs(width, height, centres, 5.0 * s, 1);
  f.second = RenderDiscs(width, height, moved, 5.0 * s, 2);
  f.mjpeg = EncodeLikeAUsbCamera(f.second);
  const tracking::DetectionReport detected = tracking::DetectDots(f.first, tracking::DotDetectorOptions());
  for (size_t k = 0; k < detected.dots.size(); ++k) {
    f.previous.push_back(tracking::MakePreviousDot(static_cast<int>(k), detected.dots[k]));
  }
  return f;
}

vpImage<unsigned char> Decode(const Frames& f, benchmark::State& state) {
  Result<vpImage<unsigned char>> image = capture::DecodeMjpegFrame(f.mjpeg.data(), f.mjpeg.size(), "bench", f.width, f.height);
  if (!image.ok()) state.SkipWithError(image.status().message().c_str());
  return image.ok() ? std::move(image).value() : vpImage<unsigned char>();
}

int Track(const Frames& f, const vpImage<unsigned char>& image) {
  const tracking::TrackReport r = tracking::TrackDots(image, f.previous, acquisition::DefaultSessionTracker());
  return r.Count(tracking::TrackStatus::kTracked);
}

void BM_DecodeMjpeg(benchmark::State& state) {
  const Frames& f = FramesOf(static_cast<int>(state.range(0)), static_cast<int>(state.range(1)));
  for (auto _ : state) benchmark::DoNotOptimize(Decode(f, state));
  state.counters["mjpeg_kB"] = static_cast<double>(f.mjpeg.size()) / 1000;
}

void BM_CheckFrame(benchmark::State& state) {
  const Frames& f = FramesOf(static_cast<int>(state.range(0)), static_cast<int>(state.range(1)));
  for (auto _ : state) {
    if (!capture::CheckFrame(f.second, capture::FrameCheckOptions(), "bench").ok()) state.SkipWithError("frame check");
  }
}

void BM_TrackDots80(benchmark::State& state) {
  const Frames& f = FramesOf(static_cast<int>(state.range(0)), static_cast<int>(state.range(1)));
  int tracked = 0;
  for (auto _ : state) tracked = Track(f, f.second);
  if (tracked != 80 || f.previous.size() != 80) state.SkipWithError("not all 80 dots detected and tracked");
}

void BM_LiveFramePath(benchmark::State& state) {
  const Frames& f = FramesOf(static_cast<int>(state.range(0)), static_cast<int>(state.range(1)));
  int tracked = 0;
  for (auto _ : state) {
    const vpImage<unsigned char> image = Decode(f, state);
    if (!capture::CheckFrame(image, capture::FrameCheckOptions(), "bench").ok()) state.SkipWithError("frame check");
    tracked = Track(f, image);
  }
  if (tracked != 80) state.SkipWithError("not all 80 dots tracked in the decoded frame");
  state.counters["frames_per_s"] = benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}

#define SELFCAL_SIZES ->Args({1280, 720})->Args({1920, 1200})->ArgNames({"w", "h"})->Unit(benchmark::kMillisecond)
BENCHMARK(BM_DecodeMjpeg) SELFCAL_SIZES;
BENCHMARK(BM_CheckFrame) SELFCAL_SIZES;
BENCHMARK(BM_TrackDots80) SELFCAL_SIZES;
BENCHMARK(BM_LiveFramePath) SELFCAL_SIZES;

}  // namespace
}  // namespace selfcal

BENCHMARK_MAIN();
