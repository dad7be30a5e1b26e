// Two-view estimator on exact and noisy data: the building blocks, the Cramer-Rao bound, the OpenCV
// reference and determinism. Refusals are in two_view_degenerate_test.cc, G10 and G2 in
// two_view_diagnostics_test.cc.
#include <chrono>
#include <cmath>
#include <cstring>
#include <iostream>
#include <random>

#include <gtest/gtest.h>

#include "twoview/two_view.h"
#include "twoview/two_view_internal.h"
#include "twoview/two_view_test_util.h"

namespace selfcal::twoview {
namespace {

using namespace test_scene;  // NOLINT(build/namespaces): the shared scene vocabulary of these tests

// ---- Building blocks, exact data --------------------------------------------------------------------

TEST(TwoViewMath, EightPointFocalFactorisationAndTriangulationAreExact) {
  std::mt19937_64 rng(11);
  const Scene scene = MakeScene(SceneSpec{}, &rng);
  std::vector<Eigen::Vector2d> c1, c2;
  for (size_t i = 0; i < scene.points.size(); ++i) {
    c1.push_back(CenteredPixel(scene.camera, scene.pixels1[i]));
    c2.push_back(CenteredPixel(scene.camera, scene.pixels2[i]));
  }
  const Eigen::Matrix3d q = EightPointFundamental(c1, c2);
  // The true Q = A^-T [t]x R A^-1, compared up to scale and sign.
  const Eigen::Matrix3d a_inv = Eigen::Vector3d(1e-3, 1e-3, 1).asDiagonal();
  Eigen::Matrix3d q_true =
      a_inv * Skew<double>(scene.cam2_from_cam1.translation) * scene.cam2_from_cam1.rotation * a_inv;
  q_true /= q_true.norm();
  EXPECT_LT(std::min((q - q_true).norm(), (q + q_true).norm()), 1e-12);

  double fx = 0, observability = 0;
  ASSERT_TRUE(FocalFromFundamental(q_true, 0.05, &fx, &observability));
  EXPECT_NEAR(fx, 1000.0, 1e-7);
  EXPECT_GT(observability, 0.05);
  std::cout << "[ figures  ] axis coplanarity sine of the test scene " << observability << "\n";

  // Theorem 1: exactly one of the four candidates is the truth (t up to scale).
  const Eigen::Matrix3d e =
      Eigen::Vector3d(1000, 1000, 1).asDiagonal() * q_true * Eigen::Vector3d(1000, 1000, 1).asDiagonal();
  const std::vector<Rigid3> candidates = FactorEssential(e);
  ASSERT_EQ(candidates.size(), 4u);
  int matches = 0;
  for (const Rigid3& c : candidates) {
    EXPECT_NEAR(c.rotation.determinant(), 1.0, 1e-12);
    EXPECT_NEAR(c.translation.norm(), 1.0, 1e-12);
    if (RotationError(scene.cam2_from_cam1.rotation, c.rotation) < 1e-12 &&
        DirectionError(scene.cam2_from_cam1.translation, c.translation) < 1e-12) {
      ++matches;
    }
  }
  EXPECT_EQ(matches, 1);

  const Eigen::Vector2d n1 = c1[0] / 1000.0, n2 = c2[0] / 1000.0;
  EXPECT_LT((TriangulateTwoView(scene.cam2_from_cam1, n1, n2) - scene.points[0]).norm(), 1e-12);
}

TEST(TwoViewMath, SymmetricEpipolarDistanceIsPointToLineDistance) {
  // F = [e]x with e = (0, 0, 1) maps x1 to the line through the origin and x1; x2 = (0, 3) lies 3 from
  // the line y = 0 through x1 = (4, 0), and x1 lies 4 from the line x = 0 through x2.
  Eigen::Matrix3d f = Skew<double>(Eigen::Vector3d(0, 0, 1));
  EXPECT_NEAR(SymmetricEpipolarDistance(f, Eigen::Vector2d(4, 0), Eigen::Vector2d(0, 3)), 5.0, 1e-12);
  EXPECT_NEAR(SymmetricEpipolarDistance(f, Eigen::Vector2d(4, 0), Eigen::Vector2d(8, 0)), 0.0, 1e-12);
}

TEST(TwoViewMath, FocalUnobservableWhenOpticalAxesIntersect) {
  std::mt19937_64 rng(12);
  SceneSpec spec;
  spec.target2 = Eigen::Vector3d(0, 0, 0.75);  // on cam1's optical axis
  const Scene scene = MakeScene(spec, &rng);
  const Eigen::Matrix3d a_inv = Eigen::Vector3d(1e-3, 1e-3, 1).asDiagonal();
  const Eigen::Matrix3d q =
      a_inv * Skew<double>(scene.cam2_from_cam1.translation) * scene.cam2_from_cam1.rotation * a_inv;
  double fx = -1, observability = 1;
  EXPECT_FALSE(FocalFromFundamental(q, 0.05, &fx, &observability));
  EXPECT_EQ(fx, -1);  // untouched
  EXPECT_LT(observability, 1e-9);
}

// ---- Exact data ---------------------------------------------------------------------------------------

TEST(TwoView, NoiseFreeRecoversPoseAndFocalExactly) {
  std::mt19937_64 rng(1);
  const Scene scene = MakeScene(SceneSpec{}, &rng);
  CameraIntrinsics prior = scene.camera;
  prior.fx_px = 900;  // the prior must not matter when f_x is observable
  const TwoViewReport report = EstimateTwoView(Options(), prior, scene.pixels1, scene.pixels2);
  ASSERT_EQ(report.outcome, Outcome::kSuccess) << report.message;
  EXPECT_TRUE(report.fx_observable);
  EXPECT_TRUE(report.translation_observable);
  EXPECT_FALSE(report.planar);
  EXPECT_EQ(report.num_inliers, 80);
  const double rotation_error = RotationError(scene.cam2_from_cam1.rotation, report.rotation);
  const double direction_error = DirectionError(scene.cam2_from_cam1.translation, report.translation_direction);
  EXPECT_LT(rotation_error, 1e-9);
  EXPECT_LT(direction_error, 1e-9);
  EXPECT_LT(std::abs(report.fx_px - 1000.0), 1e-9 * 1000.0);
  EXPECT_NEAR(report.fx_linear_px, 1000.0, 1e-6);  // Bougnoux alone, before refinement
  EXPECT_LT(report.rms_epipolar_px, 1e-9);
  EXPECT_NEAR(report.translation_direction.norm(), 1.0, 1e-12);
  EXPECT_EQ(report.far_point_fraction, 0);
  EXPECT_TRUE(report.warnings.empty());
  std::cout << "[ figures  ] noise-free: rotation error " << rotation_error << " rad, direction error "
            << direction_error << " rad, fx error " << report.fx_px - 1000.0 << " px (linear "
            << report.fx_linear_px - 1000.0 << " px)\n";
}

TEST(TwoView, NoiseFreeKnownFocalAndAnisotropicPixels) {
  std::mt19937_64 rng(2);
  SceneSpec spec;
  spec.camera.mu = 1.08;  // f_y = 1080: CenteredPixel divides it out, distances stay in raw pixels
  const Scene scene = MakeScene(spec, &rng);
  for (bool estimate_focal : {false, true}) {
    const TwoViewReport report = EstimateTwoView(Options(estimate_focal), scene.camera, scene.pixels1, scene.pixels2);
    ASSERT_EQ(report.outcome, Outcome::kSuccess) << report.message;
    EXPECT_EQ(report.fx_observable, estimate_focal);
    EXPECT_LT(RotationError(scene.cam2_from_cam1.rotation, report.rotation), 1e-9);
    EXPECT_LT(DirectionError(scene.cam2_from_cam1.translation, report.translation_direction), 1e-9);
    EXPECT_LT(std::abs(report.fx_px - 1000.0), 1e-6);
  }
}

// ---- Noise and the Cramer-Rao bound -------------------------------------------------------------------

TEST(TwoViewCramerRaoBound, BehavesLikeABound) {
  std::mt19937_64 rng(3);
  const Scene scene = MakeScene(SceneSpec{}, &rng);
  const TwoViewBound known = TwoViewCramerRao(scene.camera, scene.cam2_from_cam1, scene.points, 0.5, false);
  const TwoViewBound unknown = TwoViewCramerRao(scene.camera, scene.cam2_from_cam1, scene.points, 0.5, true);
  const TwoViewBound half = TwoViewCramerRao(scene.camera, scene.cam2_from_cam1, scene.points, 0.25, true);
  ASSERT_TRUE(known.ok && unknown.ok && half.ok) << known.message << unknown.message << half.message;
  // An extra unknown cannot make the others better determined.
  EXPECT_GE(unknown.rotation_rms_rad(), known.rotation_rms_rad() * (1 - 1e-12));
  EXPECT_GE(unknown.translation_dir_rms_rad(), known.translation_dir_rms_rad() * (1 - 1e-12));
  EXPECT_EQ(known.fx_variance, 0);
  EXPECT_GT(unknown.fx_variance, 0);
  // Linear in sigma.
  EXPECT_NEAR(half.rotation_rms_rad() / unknown.rotation_rms_rad(), 0.5, 1e-9);
  // The direction covariance lives in the plane orthogonal to t.
  EXPECT_LT((unknown.translation_dir_covariance * scene.cam2_from_cam1.translation).norm(),
            1e-12 * unknown.translation_dir_covariance.norm());
  std::cout << "[ figures  ] CRB at 0.5 px: rotation " << known.rotation_rms_rad() << " / "
            << unknown.rotation_rms_rad() << " rad, direction " << known.translation_dir_rms_rad() << " / "
            << unknown.translation_dir_rms_rad() << " rad (f known / unknown), fx sigma "
            << std::sqrt(unknown.fx_variance) << " px\n";

  // Refusals: a point behind a camera, zero translation.
  std::vector<Eigen::Vector3d> behind = scene.points;
  behind[3].z() = -1;
  EXPECT_FALSE(TwoViewCramerRao(scene.camera, scene.cam2_from_cam1, behind, 0.5, true).ok);
  EXPECT_FALSE(
      TwoViewCramerRao(scene.camera, Rigid3::FromRotation(scene.cam2_from_cam1.rotation), scene.points, 0.5, true).ok);
}

// Single noisy trials: every error within 4 RMS of the bound (a 3-DOF Gaussian exceeds 4 RMS with
// probability ~1e-9 per trial).
TEST(TwoView, NoisyErrorsWithinFewCramerRaoRms) {
  std::mt19937_64 rng(4);
  for (double sigma : {0.2, 0.5}) {
    for (int trial = 0; trial < 10; ++trial) {
      Scene scene = MakeScene(SceneSpec{}, &rng);
      const TwoViewBound bound = TwoViewCramerRao(scene.camera, scene.cam2_from_cam1, scene.points, sigma, true);
      ASSERT_TRUE(bound.ok) << bound.message;
      AddNoise(sigma, &rng, &scene.pixels1);
      AddNoise(sigma, &rng, &scene.pixels2);
      TwoViewOptions options = Options();
      options.ransac_threshold_px = 4 * sigma;
      const TwoViewReport report = EstimateTwoView(options, scene.camera, scene.pixels1, scene.pixels2);
      ASSERT_EQ(report.outcome, Outcome::kSuccess) << report.message;
      EXPECT_TRUE(report.refinement_accepted);
      EXPECT_EQ(report.refinement_termination, "convergence");
      EXPECT_GT(report.refinement_iterations, 0);
      EXPECT_LT(RotationError(scene.cam2_from_cam1.rotation, report.rotation), 4 * bound.rotation_rms_rad());
      EXPECT_LT(DirectionError(scene.cam2_from_cam1.translation, report.translation_direction),
                4 * bound.translation_dir_rms_rad());
      EXPECT_LT(std::abs(report.fx_px - 1000.0), 4 * std::sqrt(bound.fx_variance));
      // Each of the two epipolar distances carries ~2 sigma^2 of variance, so sqrt(d1^2 + d2^2) ~ 2 sigma.
      EXPECT_GT(report.rms_epipolar_px, 1.0 * sigma);
      EXPECT_LT(report.rms_epipolar_px, 3.0 * sigma);
    }
  }
}

struct MonteCarloFigures {
  double rotation_ratio = 0, direction_ratio = 0, fx_ratio = 0, seconds_per_call = 0;
};

// Empirical RMS over seeded trials (fixed scene, fresh noise) divided by the bound's RMS.
MonteCarloFigures MonteCarlo(bool estimate_focal, int trials, uint64_t seed) {
  std::mt19937_64 rng(seed);
  const double sigma = 0.5;
  const Scene scene = MakeScene(SceneSpec{}, &rng);
  const TwoViewBound bound = TwoViewCramerRao(scene.camera, scene.cam2_from_cam1, scene.points, sigma, estimate_focal);
  EXPECT_TRUE(bound.ok) << bound.message;
  TwoViewOptions options = Options(estimate_focal);
  options.ransac_threshold_px = 4 * sigma;  // every point stays an inlier: the bound assumes all 80
  double sum_rotation = 0, sum_direction = 0, sum_fx = 0, seconds = 0;
  for (int trial = 0; trial < trials; ++trial) {
    std::vector<Eigen::Vector2d> pixels1 = scene.pixels1, pixels2 = scene.pixels2;
    AddNoise(sigma, &rng, &pixels1);
    AddNoise(sigma, &rng, &pixels2);
    const auto start = std::chrono::steady_clock::now();
    const TwoViewReport report = EstimateTwoView(options, scene.camera, pixels1, pixels2);
    seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    EXPECT_EQ(report.outcome, Outcome::kSuccess) << report.message;
    sum_rotation += std::pow(RotationError(scene.cam2_from_cam1.rotation, report.rotation), 2);
    sum_direction += std::pow(DirectionError(scene.cam2_from_cam1.translation, report.translation_direction), 2);
    sum_fx += std::pow(report.fx_px - scene.camera.fx_px, 2);
  }
  MonteCarloFigures figures;
  figures.rotation_ratio = std::sqrt(sum_rotation / trials) / bound.rotation_rms_rad();
  figures.direction_ratio = std::sqrt(sum_direction / trials) / bound.translation_dir_rms_rad();
  figures.fx_ratio = estimate_focal ? std::sqrt(sum_fx / trials / bound.fx_variance) : 0;
  figures.seconds_per_call = seconds / trials;
  return figures;
}

// With 400 trials the empirical RMS has a relative standard error of ~1/sqrt(4 * 400) = 2.5 % (2 DOF),
// so 0.9 is four standard errors below an efficient estimator; eq. (13) weighs the two epipolar
// distances unlike the maximum-likelihood (reprojection) cost, hence the upper margin 1.5.
TEST(TwoView, MonteCarloMatchesCramerRaoBound) {
  for (bool estimate_focal : {false, true}) {
    const MonteCarloFigures figures = MonteCarlo(estimate_focal, 400, estimate_focal ? 51 : 52);
    std::cout << "[ figures  ] Monte Carlo / CRB (f " << (estimate_focal ? "unknown" : "known") << "): rotation "
              << figures.rotation_ratio << ", direction " << figures.direction_ratio << ", fx " << figures.fx_ratio
              << "; " << 1e3 * figures.seconds_per_call << " ms per EstimateTwoView\n";
    EXPECT_GT(figures.rotation_ratio, 0.9);
    EXPECT_LT(figures.rotation_ratio, 1.5);
    EXPECT_GT(figures.direction_ratio, 0.9);
    EXPECT_LT(figures.direction_ratio, 1.5);
    if (estimate_focal) {
      EXPECT_GT(figures.fx_ratio, 0.9);
      EXPECT_LT(figures.fx_ratio, 1.5);
    }
  }
}


// ---- OpenCV reference and determinism ---------------------------------------------------------------

TEST(TwoViewOpenCv, NoiseFreeRecoversPose) {
  std::mt19937_64 rng(18);
  for (double mu : {1.0, 1.08}) {
    SceneSpec spec;
    spec.camera.mu = mu;
    const Scene scene = MakeScene(spec, &rng);
    const TwoViewReport report = EstimateTwoViewOpenCv(Options(), scene.camera, scene.pixels1, scene.pixels2);
    ASSERT_EQ(report.outcome, Outcome::kSuccess) << report.message;
    EXPECT_EQ(report.num_inliers, 80);
    const double rotation_error = RotationError(scene.cam2_from_cam1.rotation, report.rotation);
    const double direction_error = DirectionError(scene.cam2_from_cam1.translation, report.translation_direction);
    EXPECT_LT(rotation_error, 1e-6);
    EXPECT_LT(direction_error, 1e-6);
    std::cout << "[ figures  ] OpenCV noise-free (mu " << mu << "): rotation error " << rotation_error
              << " rad, direction error " << direction_error << " rad\n";
  }
}

TEST(TwoView, SameSeedGivesBitwiseIdenticalResults) {
  std::mt19937_64 rng(19);
  std::uniform_real_distribution<double> u(0, 639), v(0, 479);
  Scene scene = MakeScene(SceneSpec{}, &rng);
  AddNoise(0.5, &rng, &scene.pixels1);
  AddNoise(0.5, &rng, &scene.pixels2);
  for (int i = 0; i < 20; ++i) scene.pixels2[i] = Eigen::Vector2d(u(rng), v(rng));  // so that sampling matters
  TwoViewOptions options = Options();
  options.seed = 1234;
  const TwoViewReport a = EstimateTwoView(options, scene.camera, scene.pixels1, scene.pixels2);
  const TwoViewReport b = EstimateTwoView(options, scene.camera, scene.pixels1, scene.pixels2);
  ASSERT_EQ(a.outcome, Outcome::kSuccess) << a.message;
  EXPECT_EQ(a.outcome, b.outcome);
  EXPECT_EQ(std::memcmp(a.rotation.data(), b.rotation.data(), sizeof(double) * 9), 0);
  EXPECT_EQ(std::memcmp(a.translation_direction.data(), b.translation_direction.data(), sizeof(double) * 3), 0);
  EXPECT_EQ(std::memcmp(&a.fx_px, &b.fx_px, sizeof(double)), 0);
  EXPECT_EQ(std::memcmp(&a.rms_epipolar_px, &b.rms_epipolar_px, sizeof(double)), 0);
  EXPECT_EQ(a.inliers, b.inliers);
  EXPECT_EQ(a.message, b.message);
}

}  // namespace
}  // namespace selfcal::twoview
