// Two-view estimator: refusals and degenerate data (G1, D7, G3-G7, G9) and far points (G6).
#include <cmath>
#include <iostream>
#include <limits>
#include <random>

#include <gtest/gtest.h>

#include "twoview/two_view.h"
#include "twoview/two_view_internal.h"
#include "twoview/two_view_test_util.h"

namespace selfcal::twoview {
namespace {

using namespace test_scene;  // NOLINT(build/namespaces): the shared scene vocabulary of these tests

// ---- Refusals and degenerate data ---------------------------------------------------------------------

TEST(TwoViewDegenerate, G1TooFewPoints) {
  std::mt19937_64 rng(5);
  SceneSpec spec;
  spec.num_points = 7;
  const Scene scene = MakeScene(spec, &rng);
  const TwoViewReport report = EstimateTwoView(Options(), scene.camera, scene.pixels1, scene.pixels2);
  EXPECT_EQ(report.outcome, Outcome::kTooFewPoints);
  EXPECT_STREQ(OutcomeName(report.outcome), "insufficient_points");
  EXPECT_EQ(EstimateTwoViewOpenCv(Options(), scene.camera, scene.pixels1, scene.pixels2).outcome,
            Outcome::kTooFewPoints);
}

TEST(TwoViewDegenerate, D7InvalidInput) {
  std::mt19937_64 rng(6);
  const Scene scene = MakeScene(SceneSpec{}, &rng);
  std::vector<Eigen::Vector2d> nan_pixels = scene.pixels2;
  nan_pixels[17].x() = std::numeric_limits<double>::quiet_NaN();
  TwoViewReport report = EstimateTwoView(Options(), scene.camera, scene.pixels1, nan_pixels);
  EXPECT_EQ(report.outcome, Outcome::kInvalidInput);
  EXPECT_NE(report.message.find("17"), std::string::npos) << report.message;
  std::vector<Eigen::Vector2d> inf_pixels = scene.pixels1;
  inf_pixels[3].y() = std::numeric_limits<double>::infinity();
  EXPECT_EQ(EstimateTwoView(Options(), scene.camera, inf_pixels, scene.pixels2).outcome, Outcome::kInvalidInput);
  EXPECT_EQ(EstimateTwoViewOpenCv(Options(), scene.camera, scene.pixels1, nan_pixels).outcome, Outcome::kInvalidInput);

  std::vector<Eigen::Vector2d> shorter = scene.pixels2;
  shorter.pop_back();
  EXPECT_EQ(EstimateTwoView(Options(), scene.camera, scene.pixels1, shorter).outcome, Outcome::kInvalidInput);
  EXPECT_EQ(EstimateTwoViewOpenCv(Options(), scene.camera, scene.pixels1, shorter).outcome, Outcome::kInvalidInput);

  TwoViewOptions bad = Options();
  bad.ransac_threshold_px = 0;
  bad.ransac_confidence = 1.5;
  EXPECT_EQ(bad.Validate(),
            "ransac_threshold_px = 0 must be finite and > 0\nransac_confidence = 1.5 must lie in (0, 1)\n");
  EXPECT_EQ(EstimateTwoView(bad, scene.camera, scene.pixels1, scene.pixels2).outcome, Outcome::kInvalidInput);
  EXPECT_TRUE(Options().Validate().empty());
}

// RMS bound of a rotation-only fit: pixel 2 = pi(K Exp(w) R K^-1 pixel 1), both pixels noisy, so
// sqrt(2) sigma on the transferred pixel (the transfer is close to an isometry for small fields of view).
double RotationOnlyBoundRad(const CameraIntrinsics& camera, const Eigen::Matrix3d& rotation,
                            const std::vector<Eigen::Vector3d>& points, double sigma_px) {
  Eigen::Matrix3d information = Eigen::Matrix3d::Zero();
  for (const Eigen::Vector3d& p : points) {
    Eigen::Matrix<double, 2, 3> jacobian;
    for (int k = 0; k < 3; ++k) {
      Eigen::Vector3d w = Eigen::Vector3d::Zero();
      w(k) = 1e-6;
      const Eigen::Vector2d plus = *Project(camera, ExpSO3<double>(w) * rotation * p);
      const Eigen::Vector2d minus = *Project(camera, ExpSO3<double>(-w) * rotation * p);
      jacobian.col(k) = (plus - minus) / 2e-6;
    }
    information += jacobian.transpose() * jacobian / (2 * sigma_px * sigma_px);
  }
  return std::sqrt(information.inverse().trace());
}

TEST(TwoViewDegenerate, G3PureRotationGivesRotationOnly) {
  std::mt19937_64 rng(7);
  SceneSpec spec;
  spec.pure_rotation = true;
  spec.target2 = Eigen::Vector3d(-0.16, 0.1, 0.75);
  for (double sigma : {0.0, 0.5}) {
    Scene scene = MakeScene(spec, &rng);
    ASSERT_GT(RotationAngle(scene.cam2_from_cam1.rotation), DegToRad(10));  // a real rotation
    const double bound = RotationOnlyBoundRad(scene.camera, scene.cam2_from_cam1.rotation, scene.points, 0.5);
    AddNoise(sigma, &rng, &scene.pixels1);
    AddNoise(sigma, &rng, &scene.pixels2);
    const TwoViewReport report = EstimateTwoView(Options(), scene.camera, scene.pixels1, scene.pixels2);
    ASSERT_EQ(report.outcome, Outcome::kPureRotation) << report.message;
    EXPECT_FALSE(report.translation_observable);
    EXPECT_EQ(report.translation_direction, Eigen::Vector3d::Zero());
    const double error = RotationError(scene.cam2_from_cam1.rotation, report.rotation);
    EXPECT_LT(error, sigma == 0 ? 1e-12 : 4 * bound) << "sigma " << sigma;
    std::cout << "[ figures  ] pure rotation, sigma " << sigma << ": rotation error " << error
              << " rad (rotation-only bound " << bound << " at 0.5 px)\n";
  }
  // Tiny baseline: 1 mm at 0.75 m is 0.08 deg of parallax, drowned by 0.2 px of noise.
  spec.pure_rotation = false;
  spec.centre2 = Eigen::Vector3d(0.001, 0, 0);
  Scene scene = MakeScene(spec, &rng);
  AddNoise(0.2, &rng, &scene.pixels1);
  AddNoise(0.2, &rng, &scene.pixels2);
  const TwoViewReport report = EstimateTwoView(Options(), scene.camera, scene.pixels1, scene.pixels2);
  EXPECT_EQ(report.outcome, Outcome::kPureRotation) << report.message;
  // The fitted rotation absorbs part of the 0.08 deg of translation flow.
  EXPECT_LT(RotationError(scene.cam2_from_cam1.rotation, report.rotation), DegToRad(0.1));

  // Small but real baseline, 18 mm at 0.75 m, noise-free: no rotation explains the rays (1.5 px left,
  // above the 1.25 px gate), cheirality decides, but the triangulation angle (1.3 deg) is below a
  // min_parallax_deg of 2.
  spec.centre2 = Eigen::Vector3d(0.018, 0, 0);
  const Scene small = MakeScene(spec, &rng);
  TwoViewOptions strict = Options();
  strict.min_parallax_deg = 2;
  const TwoViewReport small_report = EstimateTwoView(strict, small.camera, small.pixels1, small.pixels2);
  EXPECT_EQ(small_report.outcome, Outcome::kPureRotation) << small_report.message;
  EXPECT_NE(small_report.message.find("median parallax below"), std::string::npos) << small_report.message;
  // The rotation of the full model, not a best-fit rotation (which would be off by ~the parallax).
  EXPECT_LT(RotationError(small.cam2_from_cam1.rotation, small_report.rotation), 1e-9);
  EXPECT_FALSE(small_report.translation_observable);
  EXPECT_EQ(small_report.translation_direction, Eigen::Vector3d::Zero());
  // With the threshold lowered the same pair is a full success.
  TwoViewOptions permissive = Options();
  permissive.min_parallax_deg = 0.5;
  const TwoViewReport full = EstimateTwoView(permissive, small.camera, small.pixels1, small.pixels2);
  ASSERT_EQ(full.outcome, Outcome::kSuccess) << full.message;
  EXPECT_LT(RotationError(small.cam2_from_cam1.rotation, full.rotation), 1e-9);
  EXPECT_LT(DirectionError(small.cam2_from_cam1.translation, full.translation_direction), 1e-9);
}

TEST(TwoViewDegenerate, IdenticalImagesAreNotSuccess) {
  std::mt19937_64 rng(8);
  const Scene scene = MakeScene(SceneSpec{}, &rng);
  const TwoViewReport report = EstimateTwoView(Options(), scene.camera, scene.pixels1, scene.pixels1);
  EXPECT_NE(report.outcome, Outcome::kSuccess);
  EXPECT_EQ(report.outcome, Outcome::kPureRotation) << report.message;  // zero motion is a (null) rotation
  EXPECT_LT(RotationAngle(report.rotation), 1e-12);
  EXPECT_FALSE(report.translation_observable);
}

TEST(TwoViewDegenerate, CollinearPointsAreDegenerate) {
  std::mt19937_64 rng(9);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  const CameraIntrinsics camera = TestCamera();
  const Rigid3 cam2_from_cam1 = LookAt(Eigen::Vector3d(0.2, 0.03, 0.05), Eigen::Vector3d(-0.02, 0.1, 0.75), 0.1);
  std::vector<Eigen::Vector2d> pixels1, pixels2;
  for (int i = 0; i < 40; ++i) {
    const Eigen::Vector3d p = Eigen::Vector3d(0, 0, 0.75) + 0.2 * unit(rng) * Eigen::Vector3d(1, 0.3, 0.2).normalized();
    pixels1.push_back(*Project(camera, p));
    pixels2.push_back(*Project(camera, cam2_from_cam1 * p));
  }
  TwoViewOptions options = Options();
  options.ransac_max_iterations = 300;
  const TwoViewReport report = EstimateTwoView(options, camera, pixels1, pixels2);
  EXPECT_EQ(report.outcome, Outcome::kDegenerate) << report.message;
}

TEST(TwoViewDegenerate, OpticalAxesIntersectingUsesThePrior) {
  std::mt19937_64 rng(10);
  SceneSpec spec;
  spec.target2 = Eigen::Vector3d(0, 0, 0.75);  // both cameras aim at the same point
  for (double sigma : {0.0, 0.3}) {
    Scene scene = MakeScene(spec, &rng);
    AddNoise(sigma, &rng, &scene.pixels1);
    AddNoise(sigma, &rng, &scene.pixels2);
    const TwoViewReport report = EstimateTwoView(Options(), scene.camera, scene.pixels1, scene.pixels2);
    ASSERT_EQ(report.outcome, Outcome::kSuccess) << report.message;
    EXPECT_FALSE(report.fx_observable) << report.message;
    EXPECT_EQ(report.fx_px, scene.camera.fx_px);
    EXPECT_EQ(report.fx_linear_px, 0);
    // With the (here correct) prior the pose is still found.
    EXPECT_LT(RotationError(scene.cam2_from_cam1.rotation, report.rotation), sigma == 0 ? 1e-9 : 5e-3);
  }
  // A wrong prior is reported as is, not silently re-estimated from an unobservable pair.
  Scene scene = MakeScene(spec, &rng);
  CameraIntrinsics prior = scene.camera;
  prior.fx_px = 1050;
  const TwoViewReport report = EstimateTwoView(Options(), prior, scene.pixels1, scene.pixels2);
  EXPECT_EQ(report.fx_px, 1050);
  EXPECT_FALSE(report.fx_observable);
}

TEST(TwoViewDegenerate, G4PlanarSceneTakesHomographyPath) {
  std::mt19937_64 rng(13);
  SceneSpec spec;
  spec.planar = true;
  for (double sigma : {0.0, 0.2, 0.5}) {
    Scene scene = MakeScene(spec, &rng);
    const TwoViewBound bound =
        TwoViewCramerRao(scene.camera, scene.cam2_from_cam1, scene.points, std::max(sigma, 1e-9), false);
    ASSERT_TRUE(bound.ok) << bound.message;
    AddNoise(sigma, &rng, &scene.pixels1);
    AddNoise(sigma, &rng, &scene.pixels2);
    const TwoViewReport report = EstimateTwoView(Options(), scene.camera, scene.pixels1, scene.pixels2);
    ASSERT_EQ(report.outcome, Outcome::kSuccess) << report.message;
    EXPECT_TRUE(report.planar);
    EXPECT_GT(report.homography_ratio, 0.45);
    EXPECT_FALSE(report.fx_observable);
    EXPECT_EQ(report.fx_px, 1000.0);
    const double rotation_error = RotationError(scene.cam2_from_cam1.rotation, report.rotation);
    const double direction_error = DirectionError(scene.cam2_from_cam1.translation, report.translation_direction);
    std::cout << "[ figures  ] planar, sigma " << sigma << ": R_H " << report.homography_ratio << ", rotation error "
              << rotation_error << " rad (CRB " << bound.rotation_rms_rad() << "), direction error " << direction_error
              << " rad (CRB " << bound.translation_dir_rms_rad() << ")\n";
    // The bound of the unconstrained model, not using planarity: an estimator that uses it may do better.
    EXPECT_LT(rotation_error, sigma == 0 ? 1e-9 : 4 * bound.rotation_rms_rad());
    EXPECT_LT(direction_error, sigma == 0 ? 1e-9 : 4 * bound.translation_dir_rms_rad());
  }
}

TEST(TwoViewDegenerate, GeneralSceneDoesNotLookPlanar) {
  std::mt19937_64 rng(14);
  Scene scene = MakeScene(SceneSpec{}, &rng);
  AddNoise(0.5, &rng, &scene.pixels1);
  AddNoise(0.5, &rng, &scene.pixels2);
  const TwoViewReport report = EstimateTwoView(Options(), scene.camera, scene.pixels1, scene.pixels2);
  ASSERT_EQ(report.outcome, Outcome::kSuccess) << report.message;
  EXPECT_FALSE(report.planar);
  EXPECT_LT(report.homography_ratio, 0.2);
}

TEST(TwoViewDegenerate, G5PlanarForwardMotionIsAmbiguous) {
  // Moving straight at a fronto-parallel-ish plane: both physically valid homography decompositions put
  // every point in front of both cameras, so cheirality cannot decide (the 2-fold planar ambiguity).
  std::mt19937_64 rng(15);
  SceneSpec spec;
  spec.planar = true;
  spec.plane_normal = Eigen::Vector3d(0.3, 0.2, -1.0);
  spec.centre2 = Eigen::Vector3d(0.0, 0.0, 0.2);
  spec.target2 = Eigen::Vector3d(0.03, 0.02, 0.75);
  spec.roll2_rad = 0.05;
  const Scene scene = MakeScene(spec, &rng);
  const TwoViewReport report = EstimateTwoView(Options(), scene.camera, scene.pixels1, scene.pixels2);
  EXPECT_EQ(report.outcome, Outcome::kAmbiguousPose) << report.message;
  // The rival is reported, and one of the two is the truth (noise-free: to round-off).
  ASSERT_TRUE(report.has_rival);
  const Eigen::Matrix3d& truth = scene.cam2_from_cam1.rotation;
  const double best_error = LogSO3(report.rotation.transpose() * truth).norm();
  const double rival_error = LogSO3(report.rival_rotation.transpose() * truth).norm();
  EXPECT_LT(std::min(best_error, rival_error), 1e-6) << best_error << " " << rival_error;
  EXPECT_GT(std::max(best_error, rival_error), 1e-3) << "the two solutions should differ";
}

TEST(TwoViewDegenerate, G7Outliers) {
  std::mt19937_64 rng(16);
  std::uniform_real_distribution<double> u(0, 639), v(0, 479);
  for (double outlier_fraction : {0.4, 0.8}) {
    Scene scene = MakeScene(SceneSpec{}, &rng);
    AddNoise(0.2, &rng, &scene.pixels1);
    AddNoise(0.2, &rng, &scene.pixels2);
    const int num_outliers = static_cast<int>(outlier_fraction * scene.points.size());
    for (int i = 0; i < num_outliers; ++i) scene.pixels2[i] = Eigen::Vector2d(u(rng), v(rng));
    const TwoViewReport report = EstimateTwoView(Options(), scene.camera, scene.pixels1, scene.pixels2);
    if (outlier_fraction > 0.5) {
      EXPECT_EQ(report.outcome, Outcome::kTooManyOutliers) << report.message;
      continue;
    }
    ASSERT_EQ(report.outcome, Outcome::kSuccess) << report.message;
    // Every true inlier kept; a random pixel lands within 1 px of its epipolar line with probability
    // ~2/500, so at most a couple of the 32 outliers slip through.
    int kept_outliers = 0, lost_inliers = 0;
    for (int i = 0; i < static_cast<int>(scene.points.size()); ++i) {
      if (i < num_outliers && report.inliers[i]) ++kept_outliers;
      if (i >= num_outliers && !report.inliers[i]) ++lost_inliers;
    }
    EXPECT_LE(kept_outliers, 2);
    EXPECT_LE(lost_inliers, 2);  // 0.2 px noise against a 1 px gate: 5 sigma
    std::vector<Eigen::Vector3d> clean(scene.points.begin() + num_outliers, scene.points.end());
    const TwoViewBound bound = TwoViewCramerRao(scene.camera, scene.cam2_from_cam1, clean, 0.2, true);
    EXPECT_LT(RotationError(scene.cam2_from_cam1.rotation, report.rotation), 4 * bound.rotation_rms_rad());
    EXPECT_LT(DirectionError(scene.cam2_from_cam1.translation, report.translation_direction),
              4 * bound.translation_dir_rms_rad());
  }
}

TEST(TwoViewDegenerate, G9RefinementThatCannotRunKeepsTheLinearEstimate) {
  std::mt19937_64 rng(17);
  Scene scene = MakeScene(SceneSpec{}, &rng);
  AddNoise(0.5, &rng, &scene.pixels1);
  AddNoise(0.5, &rng, &scene.pixels2);
  TwoViewOptions options = Options();
  options.max_refine_iterations = 0;
  const TwoViewReport linear = EstimateTwoView(options, scene.camera, scene.pixels1, scene.pixels2);
  ASSERT_EQ(linear.outcome, Outcome::kSuccess) << linear.message;
  EXPECT_FALSE(linear.refinement_accepted);
  EXPECT_EQ(linear.refinement_termination, "no_convergence");
  EXPECT_EQ(linear.fx_px, linear.fx_linear_px);  // the linear estimate, untouched
  const TwoViewReport refined = EstimateTwoView(Options(), scene.camera, scene.pixels1, scene.pixels2);
  ASSERT_EQ(refined.outcome, Outcome::kSuccess);
  EXPECT_TRUE(refined.refinement_accepted);
  EXPECT_LT(refined.rms_epipolar_px, linear.rms_epipolar_px);  // what the refinement minimises went down
}


// ---- G6: far points -----------------------------------------------------------------------------------

// The far-scene geometry: 0.5 m of mostly lateral baseline, cam2 aimed 50 m ahead.
SceneSpec FarSpec() {
  SceneSpec spec;
  spec.box_centre = Eigen::Vector3d(0, 0, 50);
  spec.box_half = Eigen::Vector3d(14, 10, 10);  // 40-60 m deep, filling the view
  spec.centre2 = 0.5 * Eigen::Vector3d(0.45, 0.1, 0.19).normalized();
  spec.target2 = Eigen::Vector3d(-1.5, 2, 50);
  return spec;
}

// 40-60 m away with a 0.5 m baseline, every point 80-120 baselines deep. The decision (G3 has priority):
// such a pair is a pure rotation, because a rotation absorbs the translation's 8-12 px of flow up to a
// median of about 1 px, inside the 1.25 px rotation-only gate, whatever min_parallax_deg says. The
// translation is indeed not observable from it.
TEST(TwoViewDegenerate, G6FarSceneIsCaughtAsPureRotationFirst) {
  std::mt19937_64 rng(30);
  for (double sigma : {0.0, 0.2, 0.5}) {
    Scene scene = MakeScene(FarSpec(), &rng);
    AddNoise(sigma, &rng, &scene.pixels1);
    AddNoise(sigma, &rng, &scene.pixels2);
    for (double min_parallax_deg : {1.0, 0.0}) {
      TwoViewOptions options = Options();
      options.min_parallax_deg = min_parallax_deg;
      const TwoViewReport report = EstimateTwoView(options, scene.camera, scene.pixels1, scene.pixels2);
      EXPECT_EQ(report.outcome, Outcome::kPureRotation) << report.message;
      EXPECT_NE(report.message.find("a rotation alone explains the inliers"), std::string::npos) << report.message;
      // The rotation-only fit absorbs the translation's flow, b / D <= 0.5 / 40 rad.
      EXPECT_LT(RotationError(scene.cam2_from_cam1.rotation, report.rotation), 0.5 / 40);
      EXPECT_FALSE(report.translation_observable);
    }
  }
}

// 56 points 40-60 m away and 24 at 2-5 m: the near ones rule out a rotation-only model and make the
// pose well determined, but 70 % of the points are far. With the default min_parallax_deg the median
// parallax (0.5 deg, a far point's) reports it as a pure rotation first (G3 b), with the far fraction
// filled; with min_parallax_deg lowered, G6 decides, and max_far_point_fraction is the switch.
Scene MostlyFarScene(double sigma_px, std::mt19937_64* rng) {
  SceneSpec far_spec = FarSpec();
  far_spec.num_points = 56;
  SceneSpec near_spec = FarSpec();
  near_spec.box_centre = Eigen::Vector3d(0, 0, 3.5);
  near_spec.box_half = Eigen::Vector3d(1.0, 0.8, 1.5);
  near_spec.num_points = 24;
  Scene scene = MakeScene(far_spec, rng);
  const Scene near = MakeScene(near_spec, rng);
  scene.points.insert(scene.points.end(), near.points.begin(), near.points.end());
  scene.pixels1.insert(scene.pixels1.end(), near.pixels1.begin(), near.pixels1.end());
  scene.pixels2.insert(scene.pixels2.end(), near.pixels2.begin(), near.pixels2.end());
  AddNoise(sigma_px, rng, &scene.pixels1);
  AddNoise(sigma_px, rng, &scene.pixels2);
  return scene;
}

TEST(TwoViewDegenerate, G6MostlyFarPointsGiveLowDepthVariation) {
  std::mt19937_64 rng(31);
  for (double sigma : {0.0, 0.2, 0.5}) {
    const Scene scene = MostlyFarScene(sigma, &rng);
    const TwoViewReport by_parallax = EstimateTwoView(Options(), scene.camera, scene.pixels1, scene.pixels2);
    EXPECT_EQ(by_parallax.outcome, Outcome::kPureRotation) << by_parallax.message;
    EXPECT_NE(by_parallax.message.find("median parallax below"), std::string::npos) << by_parallax.message;

    TwoViewOptions options = Options();
    options.min_parallax_deg = 0.25;
    const TwoViewReport report = EstimateTwoView(options, scene.camera, scene.pixels1, scene.pixels2);
    ASSERT_EQ(report.outcome, Outcome::kLowDepthVariation) << report.message;
    EXPECT_STREQ(OutcomeName(report.outcome), "low_depth_variation");
    EXPECT_NE(report.message.find("translation direction unreliable"), std::string::npos) << report.message;
    EXPECT_FALSE(report.translation_observable);
    EXPECT_EQ(report.translation_direction, Eigen::Vector3d::Zero());
    EXPECT_LT(RotationError(scene.cam2_from_cam1.rotation, report.rotation), sigma == 0 ? 1e-9 : 5e-3);
    // Exactly the 56 far points without noise; noise moves a few across the gate or out of the inliers.
    if (sigma == 0) {
      EXPECT_EQ(report.num_inliers, 80);
      EXPECT_DOUBLE_EQ(report.far_point_fraction, 0.7);
    } else {
      EXPECT_NEAR(report.far_point_fraction, 0.7, 0.05);
    }
    EXPECT_DOUBLE_EQ(by_parallax.far_point_fraction, report.far_point_fraction);  // same estimate
    std::cout << "[ figures  ] mostly far, sigma " << sigma << ": far fraction " << report.far_point_fraction
              << ", rotation error " << RotationError(scene.cam2_from_cam1.rotation, report.rotation) << " rad\n";

    options.max_far_point_fraction = 0.8;
    const TwoViewReport tolerant = EstimateTwoView(options, scene.camera, scene.pixels1, scene.pixels2);
    EXPECT_EQ(tolerant.outcome, Outcome::kSuccess) << tolerant.message;
  }
  TwoViewOptions bad = Options();
  bad.max_far_point_fraction = 1.5;
  EXPECT_EQ(bad.Validate(), "max_far_point_fraction = 1.5 must lie in [0, 1]\n");
}

// The simulator's regime, dots 0.5-1 m away, baselines 5 and 30 cm, and the test scene (20 cm at
// 0.65-0.85 m): no point is anywhere near 50 baselines deep. (At 2 cm a dot 1 m away is exactly 50
// baselines deep, so there a part of the farthest dots counts as far.)
TEST(TwoView, G6NormalScenesHaveNoFarPoints) {
  std::mt19937_64 rng(32);
  Scene scene = MakeScene(SceneSpec{}, &rng);
  AddNoise(0.5, &rng, &scene.pixels1);
  AddNoise(0.5, &rng, &scene.pixels2);
  const TwoViewReport report = EstimateTwoView(Options(), scene.camera, scene.pixels1, scene.pixels2);
  ASSERT_EQ(report.outcome, Outcome::kSuccess) << report.message;
  EXPECT_EQ(report.far_point_fraction, 0);
  for (double baseline_m : {0.05, 0.3}) {
    for (int trial = 0; trial < 5; ++trial) {
      SceneSpec spec;
      spec.box_half = Eigen::Vector3d(0.2, 0.15, 0.25);  // 0.5-1 m deep
      spec.centre2 = baseline_m * Eigen::Vector3d(1, 0.2, 0.1).normalized();
      Scene near = MakeScene(spec, &rng);
      AddNoise(0.5, &rng, &near.pixels1);
      AddNoise(0.5, &rng, &near.pixels2);
      const TwoViewReport r = EstimateTwoView(Options(), near.camera, near.pixels1, near.pixels2);
      ASSERT_EQ(r.outcome, Outcome::kSuccess) << "baseline " << baseline_m << ": " << r.message;
      EXPECT_EQ(r.far_point_fraction, 0) << "baseline " << baseline_m;
    }
  }
}

}  // namespace
}  // namespace selfcal::twoview
