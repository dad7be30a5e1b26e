#include "simulation/rendered_observations.h"

#include <cstdio>

#include <gtest/gtest.h>

#include "calibration/bundle_stage.h"
#include "calibration/paper_pipeline.h"
#include "support/sim_worlds.h"

namespace selfcal::simulation {
namespace {

sim::SimResult SpacedWorld() {
  sim::SimOptions options;
  options.separation_dot_radius_m = sim::kDefaultDotRadiusM;
  return testing::PumaArcWorld(options);
}

// Noise-free rendering: every one of the 2000 dot images is found and named, the detector's centroid
// sits on the exact area centroid to a few thousandths of a pixel, and what is left against the projected
// centre is the ellipse-centre bias of perspective (measured by the renderer, RMS ~0.01 px).
TEST(RenderedObservations, NoiseFreeCentroidsSitOnTheTruth) {
  const sim::SimResult world = SpacedWorld();
  ASSERT_TRUE(world.ok);
  RenderedObservationOptions options;
  CentroidErrors errors;
  const ObservationSet obs = ObserveRendered(world, options, /*noise_seed=*/1, &errors);
  EXPECT_EQ(errors.expected, 80 * 25);
  EXPECT_EQ(errors.matched, 80 * 25);
  EXPECT_EQ(errors.missed, 0);
  EXPECT_EQ(errors.spurious, 0);
  const double vs_area = CentroidErrors::Rms(errors.vs_area_centroid_px);
  const double vs_projected = CentroidErrors::Rms(errors.vs_projected_px);
  const double bias = CentroidErrors::Rms(errors.ellipse_bias_px);
  std::printf("noise-free: vs area centroid %.4f px, vs projected %.4f px, ellipse bias %.4f px\n", vs_area,
              vs_projected, bias);
  EXPECT_LT(vs_area, 0.01);
  EXPECT_LT(vs_projected, 0.05);
  EXPECT_EQ(obs.Validate(), "");
}

// Grey-level noise and blur degrade the centroids gracefully; identities never swap (a swap would be an
// error of about one dot spacing, > 30 px here).
TEST(RenderedObservations, NoiseAndBlurKeepCentroidsWellUnderATenthOfAPixel) {
  const sim::SimResult world = SpacedWorld();
  ASSERT_TRUE(world.ok);
  RenderedObservationOptions options;
  options.render.noise_std_grey = 5;
  options.render.blur_sigma_px = 1.0;
  CentroidErrors errors;
  ObserveRendered(world, options, /*noise_seed=*/7, &errors);
  EXPECT_EQ(errors.missed, 0);
  EXPECT_EQ(errors.spurious, 0);
  double worst = 0;
  for (double e : errors.vs_area_centroid_px) worst = std::max(worst, std::abs(e));
  const double vs_area = CentroidErrors::Rms(errors.vs_area_centroid_px);
  std::printf("grey noise 5, blur 1 px: vs area centroid RMS %.4f px, max %.4f px\n", vs_area, worst);
  EXPECT_LT(vs_area, 0.05);
  EXPECT_LT(worst, 0.5);
}

// The kinematic bundle adjustment on noise-free rendered images is limited by the centroids only, so its
// 3-D verification error is far below the one it reaches from points with the paper's noise I (0.2 px).
TEST(RenderedObservations, BundleOnRenderedImagesBeatsNoiseIPoints) {
  const sim::SimResult world = SpacedWorld();
  ASSERT_TRUE(world.ok);
  RenderedObservationOptions options;
  const ObservationSet rendered = ObserveRendered(world, options, 1);
  const ObservationSet points = sim::Reobserve(world, 0.2, 1);
  calibration::BundleStageOptions bundle_options;
  const calibration::BundleStageReport on_images = calibration::RunBundleStage(rendered, calibration::RunPaperPipeline(rendered, {}), bundle_options);
  const calibration::BundleStageReport on_points = calibration::RunBundleStage(points, calibration::RunPaperPipeline(points, {}), bundle_options);
  ASSERT_GT(on_images.verification.num_ok, 0);
  ASSERT_GT(on_points.verification.num_ok, 0);
  std::printf("bundle 3-D RMS: rendered %.3f mm, points at 0.2 px %.3f mm\n",
              on_images.verification.rms_error_m * 1e3, on_points.verification.rms_error_m * 1e3);
  EXPECT_LT(on_images.verification.rms_error_m, 0.5 * on_points.verification.rms_error_m);
}

}  // namespace
}  // namespace selfcal::simulation
