#include "sim/image_formation.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "capture/capture_test_util.h"
#include "sim/image_renderer.h"
#include "support/sim_worlds.h"

namespace selfcal::sim {
namespace {

// Standard normal CDF.
double Phi(double x) { return 0.5 * std::erfc(-x / std::sqrt(2.0)); }

// The ziggurat's deviates are standard normal: moments, tail fractions beyond the ziggurat's base
// (3.44) and further, and the Kolmogorov-Smirnov distance, over n = 2^21 deviates. Standard errors:
// mean 1 / sqrt(n) = 6.9e-4, variance sqrt(2 / n) = 9.8e-4, fraction p: sqrt(p / n); tolerances 5 of
// them. The KS distance's 0.1 % critical value is 1.95 / sqrt(n) = 1.3e-3.
TEST(GaussianNoise, DeviatesAreStandardNormal) {
  const size_t n = size_t{1} << 21;
  std::vector<double> x(n);
  GaussianNoise noise(20261203);
  noise.Fill(x.data(), n);
  double sum = 0, sum2 = 0, sum4 = 0;
  size_t beyond_1 = 0, beyond_base = 0, beyond_4 = 0;
  for (double v : x) {
    ASSERT_TRUE(std::isfinite(v));
    sum += v;
    sum2 += v * v;
    sum4 += v * v * v * v;
    beyond_1 += std::abs(v) > 1;
    beyond_base += std::abs(v) > 3.442619855899;
    beyond_4 += std::abs(v) > 4;
  }
  const double mean = sum / n, variance = sum2 / n - mean * mean;
  EXPECT_NEAR(mean, 0.0, 5 / std::sqrt(n));
  EXPECT_NEAR(variance, 1.0, 5 * std::sqrt(2.0 / n));
  EXPECT_NEAR(sum4 / n, 3.0, 5 * std::sqrt(96.0 / n));  // E x^4 = 3, var x^4 = 105 - 9
  auto expect_fraction = [n](size_t count, double beyond, const char* what) {
    const double p = 2 * (1 - Phi(beyond));
    EXPECT_NEAR(static_cast<double>(count) / n, p, 5 * std::sqrt(p / n) + 1.0 / n) << what;
  };
  expect_fraction(beyond_1, 1, "|x| > 1");
  expect_fraction(beyond_base, 3.442619855899, "|x| > R (the tail)");
  expect_fraction(beyond_4, 4, "|x| > 4");
  std::sort(x.begin(), x.end());
  double ks = 0;
  for (size_t k = 0; k < n; k += 7) {  // every 7th order statistic
    const double cdf = Phi(x[k]);
    ks = std::max({ks, std::abs(cdf - static_cast<double>(k) / n), std::abs(cdf - static_cast<double>(k + 1) / n)});
  }
  EXPECT_LT(ks, 1.95 / std::sqrt(n));
}

// The same seed gives the same deviates, Next and Fill alike; neighbouring seeds are unrelated.
TEST(GaussianNoise, SeededAndReproducible) {
  std::vector<double> a(1000), b(1000), c(1000);
  GaussianNoise(5).Fill(a.data(), a.size());
  GaussianNoise one_by_one(5);
  for (double& v : b) v = one_by_one.Next();
  EXPECT_EQ(a, b);
  GaussianNoise(6).Fill(c.data(), c.size());
  double correlation = 0;
  for (size_t k = 0; k < a.size(); ++k) correlation += a[k] * c[k];
  EXPECT_LT(std::abs(correlation / a.size()), 5 / std::sqrt(1000.0));  // independent: ~ 1 / sqrt(n)
  EXPECT_NE(a, c);
}

// The blur the renderer had before it blurred only around the dots: every pixel of the frame, border
// replicated, horizontal then vertical, the taps in ascending order.
std::vector<double> FullFrameBlur(std::vector<double> image, int width, int height, double sigma) {
  const int radius = static_cast<int>(std::ceil(4.0 * sigma));
  std::vector<double> kernel(2 * radius + 1);
  double sum = 0;
  for (int k = -radius; k <= radius; ++k) sum += kernel[k + radius] = std::exp(-0.5 * k * k / (sigma * sigma));
  for (double& w : kernel) w /= sum;
  std::vector<double> tmp(image.size());
  for (int v = 0; v < height; ++v) {
    for (int u = 0; u < width; ++u) {
      double acc = 0;
      for (int k = -radius; k <= radius; ++k) {
        acc += kernel[k + radius] * image[static_cast<size_t>(v) * width + std::clamp(u + k, 0, width - 1)];
      }
      tmp[static_cast<size_t>(v) * width + u] = acc;
    }
  }
  for (int v = 0; v < height; ++v) {
    for (int u = 0; u < width; ++u) {
      double acc = 0;
      for (int k = -radius; k <= radius; ++k) {
        acc += kernel[k + radius] * tmp[static_cast<size_t>(std::clamp(v + k, 0, height - 1)) * width + u];
      }
      image[static_cast<size_t>(v) * width + u] = acc;
    }
  }
  return image;
}

// Blurring only the dots' boxes widened by the blur's radius gives the full-frame blur's image, byte for
// byte: dots alone, overlapping, clipped by the borders and in a corner, three blur widths. With one
// sample per pixel the unblurred grey levels are exactly the background's and the dots' (200 and 40),
// so the unblurred render is the reference blur's input.
TEST(ImageFormation, BlurAroundTheDotsIsTheFullFrameBlur) {
  const CameraIntrinsics camera;
  DotScene scene;
  const Eigen::Vector3d facing = -Eigen::Vector3d::UnitZ();
  scene.radius_m = 0.004;
  scene.centres_in_base = {{0.0, 0.0, 0.6},       {0.1, 0.05, 0.6},  {0.104, 0.05, 0.6},  // alone; overlapping
                           {-0.1915, 0.0, 0.6},   {0.0, -0.1438, 0.6},                     // left, top borders
                           {0.1915, 0.1438, 0.6}, {0.03, 0.02, 0.45}};                     // corner; nearer
  scene.normals_in_base.assign(scene.centres_in_base.size(), facing);
  RenderOptions sharp;
  sharp.supersampling = 1;  // coverage 0 or 1: the unblurred grey levels are exactly 200 and 40
  sharp.noise_std_grey = 0;
  sharp.blur_sigma_px = 0;
  const RenderedImage unblurred = RenderDots(camera, Rigid3(), scene, sharp, 1);
  std::vector<double> grey(unblurred.image.getSize());
  for (size_t k = 0; k < grey.size(); ++k) grey[k] = unblurred.image.bitmap[k];
  for (double sigma : {0.4, 1.0, 2.6}) {
    RenderOptions blurred = sharp;
    blurred.blur_sigma_px = sigma;
    const RenderedImage image = RenderDots(camera, Rigid3(), scene, blurred, 1);
    const std::vector<double> reference = FullFrameBlur(grey, camera.width_px, camera.height_px, sigma);
    int differing = 0;
    for (size_t k = 0; k < grey.size(); ++k) {
      const long rounded = std::clamp(std::lround(reference[k]), 0L, 255L);
      differing += image.image.bitmap[k] != rounded;
    }
    EXPECT_EQ(differing, 0) << "sigma " << sigma;
  }
}

// The per-thread buffers are left clean: a frame rendered after others, and on other threads at the
// same time, is the frame rendered first.
TEST(ImageFormation, FramesDoNotDependOnEarlierOrConcurrentFrames) {
  sim::SimOptions options;
  options.separation_dot_radius_m = kDefaultDotRadiusM;
  const SimResult world = testing::PumaArcWorld(options);
  ASSERT_TRUE(world.ok) << world.message;
  const DotScene scene = MakeDotScene(world.truth);
  RenderOptions render;
  render.noise_std_grey = 2;
  render.blur_sigma_px = 0.8;
  auto frame = [&](size_t pose, uint64_t seed) {
    return RenderDots(world.truth.camera_true, world.truth.base_from_cam[pose], scene, render, seed);
  };
  const RenderedImage first = frame(0, 3);
  frame(5, 4);
  RenderOptions wide = render;
  wide.blur_sigma_px = 3;
  RenderDots(world.truth.camera_true, world.truth.base_from_cam[9], scene, wide, 5);
  EXPECT_TRUE(capture::testing::SameImage(frame(0, 3).image, first.image));
  std::vector<RenderedImage> parallel(4);
  std::vector<std::thread> threads;
  for (size_t t = 0; t < parallel.size(); ++t) {
    threads.emplace_back([&, t] { parallel[t] = frame(t % 2 == 0 ? 0 : 7, t % 2 == 0 ? 3 : 8); });
  }
  for (std::thread& t : threads) t.join();
  EXPECT_TRUE(capture::testing::SameImage(parallel[0].image, first.image));
  EXPECT_TRUE(capture::testing::SameImage(parallel[2].image, first.image));
  EXPECT_TRUE(capture::testing::SameImage(parallel[1].image, parallel[3].image));
  EXPECT_FALSE(capture::testing::SameImage(parallel[1].image, first.image));
}

}  // namespace
}  // namespace selfcal::sim
