// Speed of the tracking module on one synthetic 640x480 frame of 80 anti-aliased dark dots (~10 px
// across, 8 x 8 supersampled, grey noise sigma 2, seeded), the second frame moved by a small motion
// (0.3 deg rotation, (1.2, -0.8) px shift): (a) tracking the 80 dots of the first frame into the second
// with vpDot2 and the identity checks, (b) the full detector on the second frame, (c) OpenCV's
// SimpleBlobDetector on the same frame, for scale.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <opencv2/features2d.hpp>
#include <visp3/core/vpImage.h>

#include "tracking/dot_detector.h"
#include "tracking/dot_tracker.h"

namespace selfcal {
namespace {

constexpr int kWidth = 640, kHeight = 480;

struct Frames {
  vpImage<unsigned char> first, second;
  std::vector<Eigen::Vector2d> centres;  // in the first frame
};

vpImage<unsigned char> RenderDiscs(const std::vector<Eigen::Vector2d>& centres, const std::vector<double>& radii,
                                   std::uint64_t seed) {
  constexpr int kSub = 8;
  constexpr double kBackground = 200, kDot = 40;
  std::vector<double> img(static_cast<size_t>(kWidth * kHeight), kBackground);
  for (size_t k = 0; k < centres.size(); ++k) {
    const Eigen::Vector2d c = centres[k];
    const double r = radii[k];
    for (int v = static_cast<int>(c.y() - r - 1); v <= static_cast<int>(c.y() + r + 1); ++v) {
      for (int u = static_cast<int>(c.x() - r - 1); u <= static_cast<int>(c.x() + r + 1); ++u) {
        int in = 0;
        for (int j = 0; j < kSub; ++j) {
          for (int i = 0; i < kSub; ++i) {
            const double du = u - 0.5 + (i + 0.5) / kSub - c.x(), dv = v - 0.5 + (j + 0.5) / kSub - c.y();
            in += du * du + dv * dv <= r * r ? 1 : 0;
          }
        }
        img[static_cast<size_t>(v * kWidth + u)] += (kDot - kBackground) * in / (kSub * kSub);
      }
    }
  }
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> noise(0.0, 2.0);
  vpImage<unsigned char> out(kHeight, kWidth);
  for (int v = 0; v < kHeight; ++v) {
    for (int u = 0; u < kWidth; ++u) {
      out[v][u] = static_cast<unsigned char>(std::clamp(std::lround(img[static_cast<size_t>(v * kWidth + u)] + noise(rng)), 0L, 255L));
    }
  }
  return out;
}

const Frames& TestFrames() {
  static const Frames frames = [] {
    std::mt19937_64 rng(2024);
    std::uniform_real_distribution<double> jitter(-5.0, 5.0), radius(4.5, 5.5);
    Frames f;
    std::vector<double> radii;
    for (int r = 0; r < 8; ++r) {
      for (int c = 0; c < 10; ++c) {
        f.centres.emplace_back(70.0 + 55.0 * c + jitter(rng), 50.0 + 55.0 * r + jitter(rng));
        radii.push_back(radius(rng));
      }
    }
    const double a = 0.3 * M_PI / 180;
    std::vector<Eigen::Vector2d> moved;
    for (const Eigen::Vector2d& p : f.centres) {
      const Eigen::Vector2d d = p - Eigen::Vector2d(320, 240);
      moved.push_back(Eigen::Vector2d(320, 240) + Eigen::Vector2d(std::cos(a) * d.x() - std::sin(a) * d.y(),
                                                                  std::sin(a) * d.x() + std::cos(a) * d.y()) +
                      Eigen::Vector2d(1.2, -0.8));
    }
    f.first = RenderDiscs(f.centres, radii, 1);
    f.second = RenderDiscs(moved, radii, 2);
    return f;
  }();
  return frames;
}

void BM_TrackDots80(benchmark::State& state) {
  const Frames& f = TestFrames();
  const tracking::DetectionReport first = tracking::DetectDots(f.first, tracking::DotDetectorOptions());
  std::vector<tracking::PreviousDot> previous;
  for (size_t k = 0; k < first.dots.size(); ++k) previous.push_back(tracking::MakePreviousDot(static_cast<int>(k), first.dots[k]));
  int tracked = 0;
  for (auto _ : state) {
    const tracking::TrackReport r = tracking::TrackDots(f.second, previous, tracking::DotTrackerOptions());
    tracked = r.Count(tracking::TrackStatus::kTracked);
  }
  if (tracked != 80) state.SkipWithError("not all 80 dots tracked");
  state.counters["dots_tracked"] = tracked;
}
BENCHMARK(BM_TrackDots80)->Unit(benchmark::kMicrosecond);

void BM_DetectDots(benchmark::State& state) {
  const Frames& f = TestFrames();
  tracking::DotDetectorOptions options;
  options.threshold_mode = state.range(0) == 0 ? tracking::ThresholdMode::kLocal : tracking::ThresholdMode::kOtsu;
  size_t found = 0;
  for (auto _ : state) found = tracking::DetectDots(f.second, options).dots.size();
  if (found != 80) state.SkipWithError("not all 80 dots detected");
  state.counters["dots_found"] = static_cast<double>(found);
}
BENCHMARK(BM_DetectDots)->Arg(0)->Arg(1)->ArgName("otsu")->Unit(benchmark::kMicrosecond);

void BM_OpenCvSimpleBlobDetector(benchmark::State& state) {
  const Frames& f = TestFrames();
  const cv::Mat mat(kHeight, kWidth, CV_8UC1, const_cast<unsigned char*>(f.second.bitmap));
  cv::SimpleBlobDetector::Params params;  // default thresholds 10..200 step 10
  params.filterByColor = true;
  params.blobColor = 0;
  params.filterByArea = true;
  params.minArea = 20;
  params.maxArea = 500;
  const cv::Ptr<cv::SimpleBlobDetector> detector = cv::SimpleBlobDetector::create(params);
  std::vector<cv::KeyPoint> keypoints;
  for (auto _ : state) detector->detect(mat, keypoints);
  if (keypoints.size() != 80) state.SkipWithError("SimpleBlobDetector did not find the 80 dots");
  state.counters["dots_found"] = static_cast<double>(keypoints.size());
}
BENCHMARK(BM_OpenCvSimpleBlobDetector)->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace selfcal

BENCHMARK_MAIN();
