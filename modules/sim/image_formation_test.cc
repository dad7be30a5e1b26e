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
