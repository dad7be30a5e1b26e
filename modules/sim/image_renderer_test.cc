#include "sim/image_renderer.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "capture/capture_test_util.h"
#include "capture/frame_checks.h"
#include "sim/trajectory_generator.h"
#include "support/sim_worlds.h"
#include "support/test_robots.h"

namespace selfcal::sim {
namespace {

// Tolerance of a supersample centroid against the exact area centroid at S = 8 (1/8 px sample
// spacing): the count of samples in a disc of radius R samples fluctuates along the rim with a +-1/2
// sample error per rim sample of random sign, so the centroid error is about
// sqrt(2 pi R) * R / (pi R^2) samples ~ 0.9 R^-1/2 samples; for the ~6 px dots (R = 48 samples) that
// is 0.13 samples = 0.016 px at worst over many positions and typically 0.003 px. Measured maximum
// over the positions below: see the tests.
constexpr double kSampleCentroidTolPx = 0.01;

// One dot seen by a camera at the base origin (cam = base).
DotScene OneDot(const Eigen::Vector3d& centre, const Eigen::Vector3d& normal, double radius_m) {
  DotScene scene;
  scene.centres_in_base = {centre};
  scene.normals_in_base = {normal.normalized()};
  scene.radius_m = radius_m;
  return scene;
}

RenderOptions Clean() {
  RenderOptions o;
  o.noise_std_grey = 0;
  o.blur_sigma_px = 0;
  return o;
}

// Intensity-weighted centroid of (background - grey) in a window: what a detector would measure.
Eigen::Vector2d ImageCentroid(const vpImage<unsigned char>& image, const Eigen::Vector2d& around, int half,
                              double background) {
  double w = 0, su = 0, sv = 0;
  for (int v = static_cast<int>(around.y()) - half; v <= static_cast<int>(around.y()) + half; ++v) {
    for (int u = static_cast<int>(around.x()) - half; u <= static_cast<int>(around.x()) + half; ++u) {
      const double dark = background - image[v][u];
      w += dark;
      su += dark * u;
      sv += dark * v;
    }
  }
  return Eigen::Vector2d(su / w, sv / w);
}

TEST(ImageRenderer, FrontoParallelDiscCentroidIsTheProjectedCentre) {
  const CameraIntrinsics camera;  // 640x480, f 1000, no distortion
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> xy(-0.15, 0.15);
  double worst_sample = 0;
  for (int trial = 0; trial < 20; ++trial) {
    const Eigen::Vector3d centre(xy(rng), 0.75 * xy(rng), 0.6);
    const double r = 0.004;
    // A disc parallel to the image plane projects to a circle centred on the projected centre.
    const RenderedImage out = RenderDots(camera, Rigid3(), OneDot(centre, -Eigen::Vector3d::UnitZ(), r), Clean(), 1);
    const RenderedDot& dot = out.dots[0];
    ASSERT_TRUE(dot.Clean());
    EXPECT_LT((dot.area_centroid_px - dot.projected_centre_px).norm(), 1e-9);
    const double radius_px = camera.fx_px * r / centre.z();
    EXPECT_NEAR(dot.area_px2, kPi * radius_px * radius_px, 1e-9 * dot.area_px2);
    EXPECT_NEAR(dot.sample_area_px2, dot.area_px2, 0.01 * dot.area_px2);
    const double sample_error = (dot.sample_centroid_px - dot.projected_centre_px).norm();
    worst_sample = std::max(worst_sample, sample_error);
    EXPECT_LT(sample_error, kSampleCentroidTolPx) << "trial " << trial;
    // The rendered image itself (quantised to 8 bits): its intensity centroid matches too.
    const Eigen::Vector2d measured = ImageCentroid(out.image, dot.projected_centre_px, 12, 200);
    EXPECT_LT((measured - dot.sample_centroid_px).norm(), 0.01) << "trial " << trial;
  }
  RecordProperty("worst_sample_centroid_error_px", std::to_string(worst_sample));
  std::printf("fronto-parallel: worst supersample centroid error %.5f px\n", worst_sample);
}

// The rendered coverage of a disc is its area. Fronto-parallel discs (k1 = 0: circles of radius
// R = f r / z px) at random positions and depths 0.45-0.75 m (R = 5.3-8.9 px), S x S samples per pixel.
// The dark-sample count errs only along the rim: about 2 pi R S sample cells there, each off by a
// fraction of a sample of random sign (variance ~1/12), so its std is about sqrt(2 pi R S / 12)
// samples, that / S^2 in px^2 (0.07 px^2 at R = 6.5 px, S = 8: 0.05 % of the area); tolerances 5 of
// them per disc and 5 / sqrt(n) of them for the mean over the discs (no bias). The image holds the same
// coverage (background 255, dot 0: coverage = (255 - grey) / 255) up to the rounding of the partly
// covered pixels, at most 0.5 / 255 each. S = 8, 4 (the exact coordinate sums) and 3 (the ordered ones).
TEST(ImageRenderer, RenderedCoverageIsTheDiscArea) {
  const CameraIntrinsics camera;
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> xy(-0.15, 0.15), depth(0.45, 0.75);
  for (int s : {8, 4, 3}) {
    RenderOptions options = Clean();
    options.supersampling = s;
    options.background_grey = 255;
    options.dot_grey = 0;
    const int n = 30;
    double sum_error = 0, sum_std = 0, sum_error2 = 0;
    for (int trial = 0; trial < n; ++trial) {
      const Eigen::Vector3d centre(xy(rng), 0.75 * xy(rng), depth(rng));
      const double r = 0.004;
      const RenderedImage out = RenderDots(camera, Rigid3(), OneDot(centre, -Eigen::Vector3d::UnitZ(), r), options, 1);
      const RenderedDot& dot = out.dots[0];
      ASSERT_TRUE(dot.Clean());
      const double radius_px = camera.fx_px * r / centre.z();
      const double area = kPi * radius_px * radius_px;
      const double sample_std = std::sqrt(2 * kPi * radius_px * s / 12.0) / (s * s);
      double coverage = 0;
      int partial = 0;
      for (unsigned k = 0; k < out.image.getSize(); ++k) {
        const int g = out.image.bitmap[k];
        coverage += (255 - g) / 255.0;
        partial += g > 0 && g < 255;
      }
      EXPECT_NEAR(dot.sample_area_px2, area, 5 * sample_std) << "S = " << s << ", trial " << trial;
      EXPECT_NEAR(coverage, dot.sample_area_px2, partial * 0.5 / 255 + 1e-9) << "S = " << s << ", trial " << trial;
      EXPECT_LT((dot.sample_centroid_px - dot.projected_centre_px).norm(), 5 * sample_std / (2 * radius_px))
          << "S = " << s << ", trial " << trial;
      sum_error += dot.sample_area_px2 - area;
      sum_error2 += (dot.sample_area_px2 - area) * (dot.sample_area_px2 - area);
      sum_std += sample_std;
    }
    EXPECT_NEAR(sum_error / n, 0.0, 5 * sum_std / n / std::sqrt(n)) << "S = " << s;
    std::printf("S = %d: sample area error RMS %.4f px^2, expected about %.4f\n", s, std::sqrt(sum_error2 / n),
                sum_std / n);
  }
}

// Per-dot radii (a grid's larger origin dot): each disc has its own area, exactly.
TEST(ImageRenderer, PerDotRadiiScaleEachDiscsArea) {
  const CameraIntrinsics camera;
  DotScene scene;
  scene.centres_in_base = {Eigen::Vector3d(-0.05, 0, 0.6), Eigen::Vector3d(0.05, 0, 0.6)};
  scene.normals_in_base = {-Eigen::Vector3d::UnitZ(), -Eigen::Vector3d::UnitZ()};
  scene.radius_m = 0.004;
  scene.radii_m = {1.6 * 0.004, 0.004};
  const RenderedImage out = RenderDots(camera, Rigid3(), scene, Clean(), 1);
  for (int d = 0; d < 2; ++d) {
    const double radius_px = camera.fx_px * scene.radii_m[d] / 0.6;
    EXPECT_NEAR(out.dots[d].area_px2, kPi * radius_px * radius_px, 1e-9 * out.dots[d].area_px2) << d;
  }
  EXPECT_NEAR(out.dots[0].sample_area_px2 / out.dots[1].sample_area_px2, 1.6 * 1.6, 0.02);
  scene.radii_m = {0.004};
  EXPECT_THROW(RenderDots(camera, Rigid3(), scene, Clean(), 1), std::exception);
}

TEST(ImageRenderer, TiltedDiscShowsThePerspectiveBias) {
  const CameraIntrinsics camera;
  // On the optical axis at z = 0.5 m, tilted by alpha about x: the closed form of image_renderer.h gives
  // the bias f r^2 sin(a) cos(a) / (z^2 - r^2 sin^2(a)) along -v (towards the nearer, lower edge).
  const double z = 0.5, alpha = DegToRad(50);
  for (const double r : {0.004, 0.02}) {
    const Eigen::Vector3d centre(0, 0, z);
    // Normal of a disc rotated by alpha about x, facing the camera: its +b half (v > 0) is farther.
    const Eigen::Vector3d normal(0, std::sin(alpha), -std::cos(alpha));
    const RenderedImage out = RenderDots(camera, Rigid3(), OneDot(centre, normal, r), Clean(), 1);
    const RenderedDot& dot = out.dots[0];
    ASSERT_TRUE(dot.Clean());
    const double s = std::sin(alpha), c = std::cos(alpha);
    const double expected = camera.fx_px * r * r * s * c / (z * z - r * r * s * s);
    const Eigen::Vector2d bias = dot.bias_px();
    EXPECT_NEAR(bias.x(), 0.0, 1e-9);
    // The nearer edge is the one towards -v (the in-plane direction (0, -cos a, -sin a) brings the rim
    // closer to the camera), so the centroid moves to -v.
    EXPECT_NEAR(bias.y(), -expected, 1e-9 * expected) << "r = " << r;
    // Exact conic centre and Green's theorem agree.
    EXPECT_LT((EllipseCentrePx(camera, centre, normal, r) - dot.area_centroid_px).norm(), 1e-9);
    // The supersamples see the same offset; the image too.
    EXPECT_LT((dot.sample_centroid_px - dot.area_centroid_px).norm(), kSampleCentroidTolPx) << "r = " << r;
    std::printf("tilted 50 deg, r = %.3f m: bias %.5f px (closed form %.5f), supersample error %.5f px\n", r,
                bias.norm(), expected, (dot.sample_centroid_px - dot.area_centroid_px).norm());
  }
  // Large enough to see in the image itself: the intensity centroid of the rendered disc moves too.
  const RenderedImage big = RenderDots(
      camera, Rigid3(), OneDot(Eigen::Vector3d(0, 0, z), Eigen::Vector3d(0, std::sin(alpha), -std::cos(alpha)), 0.02),
      Clean(), 1);
  const Eigen::Vector2d measured = ImageCentroid(big.image, big.dots[0].projected_centre_px, 50, 200);
  EXPECT_LT((measured - big.dots[0].area_centroid_px).norm(), 0.01);
  EXPECT_LT(measured.y() - big.dots[0].projected_centre_px.y(), -0.5);

  // Off axis, tilted about a skew axis: the exact conic centre against Green's theorem and the samples.
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> uniform(-1, 1);
  for (int trial = 0; trial < 10; ++trial) {
    const Eigen::Vector3d centre(0.08 * uniform(rng), 0.05 * uniform(rng), 0.45 + 0.1 * uniform(rng));
    const Eigen::Vector3d n =
        (-centre.normalized() + 0.8 * Eigen::Vector3d(uniform(rng), uniform(rng), 0)).normalized();
    const RenderedImage out = RenderDots(camera, Rigid3(), OneDot(centre, n, 0.01), Clean(), 1);
    const RenderedDot& dot = out.dots[0];
    ASSERT_TRUE(dot.Clean());
    EXPECT_LT((EllipseCentrePx(camera, centre, n, 0.01) - dot.area_centroid_px).norm(), 1e-9) << trial;
    EXPECT_LT((dot.sample_centroid_px - dot.area_centroid_px).norm(), kSampleCentroidTolPx) << trial;
    EXPECT_GT(dot.bias_px().norm(), 5 * kSampleCentroidTolPx) << trial;  // the test resolves the bias
  }
}

TEST(ImageRenderer, DistortionBendsTheRimConsistently) {
  CameraIntrinsics camera;
  camera.k1 = -0.25;
  const Eigen::Vector3d centre(0.12, -0.08, 0.5);  // far off axis: strong distortion
  const Eigen::Vector3d n = -centre.normalized();
  const RenderedImage out = RenderDots(camera, Rigid3(), OneDot(centre, n, 0.01), Clean(), 1);
  const RenderedDot& dot = out.dots[0];
  ASSERT_TRUE(dot.Clean());
  // Green's theorem on the distorted rim and the back-projected samples describe the same region.
  EXPECT_LT((dot.sample_centroid_px - dot.area_centroid_px).norm(), kSampleCentroidTolPx);
  EXPECT_NEAR(dot.sample_area_px2, dot.area_px2, 0.01 * dot.area_px2);
  // The projected centre goes through the distortion as well.
  EXPECT_LT((dot.projected_centre_px - *Project(camera, centre)).norm(), 1e-12);
  // Undistorted, the same disc projects elsewhere: the test is sensitive to k1.
  const RenderedImage pinhole = RenderDots(CameraIntrinsics(), Rigid3(), OneDot(centre, n, 0.01), Clean(), 1);
  EXPECT_GT((pinhole.dots[0].area_centroid_px - dot.area_centroid_px).norm(), 5.0);
}

TEST(ImageRenderer, BlurKeepsTheIntensityCentroid) {
  const CameraIntrinsics camera;
  RenderOptions blurred = Clean();
  blurred.blur_sigma_px = 1.2;
  const DotScene scene = OneDot(Eigen::Vector3d(0.031, -0.017, 0.55), -Eigen::Vector3d::UnitZ(), 0.004);
  const RenderedImage sharp = RenderDots(camera, Rigid3(), scene, Clean(), 1);
  const RenderedImage soft = RenderDots(camera, Rigid3(), scene, blurred, 1);
  const Eigen::Vector2d truth = sharp.dots[0].area_centroid_px;
  EXPECT_LT((ImageCentroid(soft.image, truth, 14, 200) - truth).norm(), 0.02);
  // Blur removes edge energy (what the V9 blur check measures).
  EXPECT_LT(capture::LaplacianVariance(soft.image), 0.2 * capture::LaplacianVariance(sharp.image));
}

TEST(ImageRenderer, NoiseIsSeededAndOfTheRequestedLevel) {
  const CameraIntrinsics camera;
  RenderOptions noisy = Clean();
  noisy.noise_std_grey = 3.0;
  const DotScene scene = OneDot(Eigen::Vector3d(0, 0, 0.6), -Eigen::Vector3d::UnitZ(), 0.004);
  const RenderedImage a = RenderDots(camera, Rigid3(), scene, noisy, 42);
  const RenderedImage b = RenderDots(camera, Rigid3(), scene, noisy, 42);
  const RenderedImage c = RenderDots(camera, Rigid3(), scene, noisy, 43);
  EXPECT_TRUE(capture::testing::SameImage(a.image, b.image));
  EXPECT_FALSE(capture::testing::SameImage(a.image, c.image));
  // Background statistics over the top 200 rows (the dot spans rows 233-246): mean 200, std
  // sqrt(3^2 + 1/12) after rounding. Standard errors over n = 128000 pixels: 3 / sqrt(n) = 0.008 (mean)
  // and 3 / sqrt(2 n) = 0.006 (std); tolerances are 5 of them.
  double sum = 0, sum2 = 0;
  const int n = 640 * 200;
  for (int k = 0; k < n; ++k) {
    sum += a.image.bitmap[k];
    sum2 += static_cast<double>(a.image.bitmap[k]) * a.image.bitmap[k];
  }
  const double mean = sum / n, std_dev = std::sqrt(sum2 / n - mean * mean);
  EXPECT_NEAR(mean, 200.0, 5 * 3.0 / std::sqrt(n));
  EXPECT_NEAR(std_dev, std::sqrt(9.0 + 1.0 / 12), 5 * 3.0 / std::sqrt(2.0 * n));
}

TEST(ImageRenderer, FlagsClippedOverlappingBehindAndOutside) {
  const CameraIntrinsics camera;
  DotScene scene;
  scene.radius_m = 0.004;
  const Eigen::Vector3d facing = -Eigen::Vector3d::UnitZ();
  scene.centres_in_base = {
      {0.0, 0.0, 0.6},   // 0: alone in the middle
      {0.1, 0.05, 0.6},  // 1 and 2 overlap (centres 4 mm apart, radius 4 mm)
      {0.104, 0.05, 0.6},
      {0.1, -0.05, 0.6},  // 3 and 4: 9.6 mm apart, rims 1.6 mm = 2.7 px apart: only near with gap 3 px
      {0.1096, -0.05, 0.6},
      {-0.1915, 0.0, 0.6},  // 5: its centre projects to u = 0.33: clipped by the left border
      {0.0, 0.0, -0.5},     // 6: behind the camera
      {0.5, 0.0, 0.6},      // 7: in front, but far outside the image
  };
  scene.normals_in_base.assign(scene.centres_in_base.size(), facing);
  RenderOptions options = Clean();
  options.merge_gap_px = 3.0;
  const RenderedImage out = RenderDots(camera, Rigid3(), scene, options, 1);
  const auto& d = out.dots;
  EXPECT_TRUE(d[0].Clean());
  EXPECT_TRUE(d[1].overlapping && d[2].overlapping);
  EXPECT_EQ(d[1].neighbours, std::vector<int>{2});
  EXPECT_FALSE(d[3].overlapping || d[4].overlapping);
  EXPECT_TRUE(d[3].near_other && d[4].near_other);
  EXPECT_FALSE(d[3].Clean());
  EXPECT_TRUE(d[5].visible && d[5].clipped && !d[5].fully_inside);
  EXPECT_FALSE(d[6].in_front || d[6].visible);
  EXPECT_TRUE(d[7].in_front && !d[7].visible && !d[7].clipped);
  options.merge_gap_px = 2.0;  // 2.7 px apart: no longer near
  const RenderedImage apart = RenderDots(camera, Rigid3(), scene, options, 1);
  EXPECT_TRUE(apart.dots[3].Clean() && apart.dots[4].Clean());
}

// The default world (test_worlds: PUMA 560 on the shipped arc): dot sizes, the perspective bias, and how
// many dots overlap or touch the border, with the flags checked against the geometry. Prints the
// figures and the rendering time (not asserted).
TEST(ImageRenderer, DefaultWorldStatistics) {
  const SimResult world = testing::PumaArcWorld(0.0);
  ASSERT_TRUE(world.ok);
  const DotScene scene = MakeDotScene(world.truth);
  const RenderOptions options = Clean();
  double sum_bias2 = 0, max_bias = 0, seconds = 0;
  std::vector<double> diameters;
  int max_overlapping = 0, max_near = 0, max_clipped = 0, total_overlapping = 0, total_near = 0, total_clipped = 0;
  std::vector<bool> clean_everywhere(scene.centres_in_base.size(), true);
  const int poses = static_cast<int>(world.truth.base_from_cam.size());
  for (int i = 0; i < poses; ++i) {
    const auto start = std::chrono::steady_clock::now();
    const RenderedImage out = RenderDots(world.truth.camera_true, world.truth.base_from_cam[i], scene, options, 1);
    seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    const Rigid3 cam_from_base = world.truth.base_from_cam[i].Inverse();
    int overlapping = 0, near = 0, clipped = 0;
    for (const RenderedDot& d : out.dots) {
      ASSERT_TRUE(d.in_front && d.visible);  // the world puts every dot in every view
      overlapping += d.overlapping;
      near += d.near_other && !d.overlapping;
      clipped += d.clipped;
      if (!d.Clean()) clean_everywhere[d.id] = false;
      diameters.push_back(2 * std::sqrt(d.area_px2 / kPi));
      const double bias = d.bias_px().norm();
      sum_bias2 += bias * bias;
      max_bias = std::max(max_bias, bias);
      // k1 = 0 in the default world: the area centroid is the exact ellipse centre.
      ASSERT_EQ(world.truth.camera_true.k1, 0.0);
      EXPECT_LT((EllipseCentrePx(world.truth.camera_true, cam_from_base * scene.centres_in_base[d.id],
                                 cam_from_base.rotation * scene.normals_in_base[d.id], scene.radius_m) -
                 d.area_centroid_px)
                    .norm(),
                1e-8);
    }
    // Flags against the geometry: discs of min_radius_px about the centroids lie inside the dots, discs
    // of max_radius_px contain them. Closer than the inner radii: must overlap; farther than the outer
    // radii plus the gap: neither overlapping nor near.
    for (const RenderedDot& a : out.dots) {
      for (const RenderedDot& b : out.dots) {
        if (a.id >= b.id) continue;
        const double distance = (a.area_centroid_px - b.area_centroid_px).norm();
        const bool listed = std::count(a.neighbours.begin(), a.neighbours.end(), b.id) > 0;
        if (distance < a.min_radius_px + b.min_radius_px - 0.5) {
          EXPECT_TRUE(a.overlapping && b.overlapping && listed) << "pose " << i << " dots " << a.id << ", " << b.id;
        }
        if (distance > a.max_radius_px + b.max_radius_px + options.merge_gap_px) {
          EXPECT_FALSE(listed) << "pose " << i << " dots " << a.id << ", " << b.id;
        }
      }
      if (a.overlapping || a.near_other) {
        EXPECT_FALSE(a.neighbours.empty());
      }
    }
    max_overlapping = std::max(max_overlapping, overlapping);
    max_near = std::max(max_near, near);
    max_clipped = std::max(max_clipped, clipped);
    total_overlapping += overlapping;
    total_near += near;
    total_clipped += clipped;
  }
  std::sort(diameters.begin(), diameters.end());
  const double rms_bias = std::sqrt(sum_bias2 / diameters.size());
  std::printf(
      "default world, %d poses x %zu dots of r = %.1f mm: diameter min %.1f, median %.1f, max %.1f px; "
      "ellipse-centre bias RMS %.4f px, max %.4f px; dots per frame: overlapping mean %.1f max %d, near but not "
      "overlapping mean %.1f max %d, clipped mean %.1f max %d; clean in every view: %d dots; render %.1f ms/frame\n",
      poses, scene.centres_in_base.size(), 1000 * scene.radius_m, diameters.front(), diameters[diameters.size() / 2],
      diameters.back(), rms_bias, max_bias, double(total_overlapping) / poses, max_overlapping,
      double(total_near) / poses, max_near, double(total_clipped) / poses, max_clipped,
      static_cast<int>(std::count(clean_everywhere.begin(), clean_everywhere.end(), true)), 1000 * seconds / poses);
  // The default radius gives 10-14 px dots at the arc's distances (median), wider at the scene's extremes.
  EXPECT_GT(diameters[diameters.size() / 2], 10.0);
  EXPECT_LT(diameters[diameters.size() / 2], 14.0);
  // Bias: second order, below f r^2 / (2 z^2) at the minimum depth the world allows (0.3 m): 0.089 px.
  EXPECT_LT(max_bias, 1000 * 0.004 * 0.004 / (2 * 0.3 * 0.3));
  EXPECT_GT(rms_bias, 0.0);
  // The world keeps every dot image_margin_px = 10 px inside every view: only dots wider than 20 px can
  // reach the border.
  EXPECT_EQ(total_clipped, 0);
}

}  // namespace
}  // namespace selfcal::sim

namespace selfcal::sim {
namespace {

// The spacing rule of SimOptions: with it, no rendered dot of the standard world overlaps or comes near
// another in any of the 25 views (without it, 13 of 80 per frame do), so every dot is trackable.
TEST(ImageRenderer, SpacedSceneRendersEveryDotCleanInEveryView) {
  const RobotModel puma = testing::Puma560();
  const GeneratedTrajectory trajectory = MakeArcTrajectory(puma, ArcTrajectoryOptions());
  ASSERT_TRUE(trajectory.ok);
  SimOptions options;
  options.separation_dot_radius_m = kDefaultDotRadiusM;
  const SimResult world = Simulate(puma, trajectory.joints, options);
  ASSERT_TRUE(world.ok) << world.message;
  ASSERT_EQ(world.truth.dots_in_base.size(), 80u);
  const DotScene scene = MakeDotScene(world.truth);
  RenderOptions render;
  render.supersampling = 2;  // flags only; the exact geometry does not depend on it
  for (size_t v = 0; v < world.truth.base_from_cam.size(); ++v) {
    const RenderedImage image =
        RenderDots(world.truth.camera_true, world.truth.base_from_cam[v], scene, render, /*noise_seed=*/1);
    int clean = 0;
    for (const RenderedDot& dot : image.dots) clean += dot.Clean() ? 1 : 0;
    EXPECT_EQ(clean, 80) << "view " << v;
  }
}

}  // namespace
}  // namespace selfcal::sim
