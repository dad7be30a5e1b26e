#include "twoview/two_view.h"

#include <chrono>
#include <cmath>
#include <cstring>
#include <iostream>
#include <limits>
#include <random>
#include <sstream>

#include <gtest/gtest.h>

#include "twoview/two_view_internal.h"

namespace selfcal::twoview {
namespace {

// ---- Synthetic scene ------------------------------------------------------------------------------
//
//   cam1 at the origin looking along +z; 80 points in a 0.3 x 0.25 x 0.2 m box centred 0.75 m ahead;
//   cam2 displaced by `centre2` and aimed at `target2`, which is off cam1's optical axis so that the two
//   axes do not intersect (f_x observable), with an extra roll about its own axis.

CameraIntrinsics TestCamera() {
  CameraIntrinsics camera;
  camera.width_px = 640;
  camera.height_px = 480;
  camera.fx_px = 1000;
  camera.mu = 1;
  camera.cx_px = 319.5;
  camera.cy_px = 239.5;
  return camera;
}

struct SceneSpec {
  CameraIntrinsics camera = TestCamera();
  Eigen::Vector3d centre2{0.2, 0.03, 0.05};
  Eigen::Vector3d target2{-0.02, 0.1, 0.75};
  double roll2_rad = 0.1;
  int num_points = 80;
  bool planar = false;
  Eigen::Vector3d plane_normal{0.25, -0.15, -1.0};  // towards cam1, tilted
  bool pure_rotation = false;                       // centre2 ignored, cam2 at the origin
  Eigen::Vector3d box_centre{0, 0, 0.75};           // of the non-planar points, in cam1
  Eigen::Vector3d box_half{0.15, 0.125, 0.1};       // half extents of that box
};

struct Scene {
  CameraIntrinsics camera;
  Rigid3 cam2_from_cam1;
  std::vector<Eigen::Vector3d> points;  // in cam1
  std::vector<Eigen::Vector2d> pixels1, pixels2;
};

// cam_from_world of a camera at `centre` looking at `target` (image y roughly along world y).
Rigid3 LookAt(const Eigen::Vector3d& centre, const Eigen::Vector3d& target, double roll_rad) {
  const Eigen::Vector3d z = (target - centre).normalized();
  const Eigen::Vector3d x = Eigen::Vector3d::UnitY().cross(z).normalized();
  const Eigen::Vector3d y = z.cross(x);
  Eigen::Matrix3d world_from_cam;
  world_from_cam << x, y, z;
  world_from_cam = world_from_cam * RotZ(roll_rad);
  const Eigen::Matrix3d r = world_from_cam.transpose();
  return Rigid3(r, -(r * centre));
}

Scene MakeScene(const SceneSpec& spec, std::mt19937_64* rng) {
  Scene scene;
  scene.camera = spec.camera;
  const Eigen::Vector3d centre2 = spec.pure_rotation ? Eigen::Vector3d::Zero() : spec.centre2;
  scene.cam2_from_cam1 = LookAt(centre2, spec.target2, spec.roll2_rad);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  const Eigen::Vector3d centre(0, 0, 0.75);
  const Eigen::Vector3d n = spec.plane_normal.normalized();
  const Eigen::Vector3d e1 = n.cross(Eigen::Vector3d::UnitY()).normalized();
  const Eigen::Vector3d e2 = n.cross(e1);
  int attempts = 0;
  while (static_cast<int>(scene.points.size()) < spec.num_points) {
    EXPECT_LT(++attempts, 100 * spec.num_points) << "scene generator cannot fill the view";
    if (attempts >= 100 * spec.num_points) break;
    const Eigen::Vector3d p = spec.planar
                                  ? Eigen::Vector3d(centre + 0.15 * unit(*rng) * e1 + 0.12 * unit(*rng) * e2)
                                  : Eigen::Vector3d(spec.box_centre + Eigen::Vector3d(spec.box_half.x() * unit(*rng),
                                                                                      spec.box_half.y() * unit(*rng),
                                                                                      spec.box_half.z() * unit(*rng)));
    const auto uv1 = Project(scene.camera, p);
    const auto uv2 = Project(scene.camera, scene.cam2_from_cam1 * p);
    if (!uv1 || !uv2 || !InImage(scene.camera, *uv1, 5) || !InImage(scene.camera, *uv2, 5)) continue;
    scene.points.push_back(p);
    scene.pixels1.push_back(*uv1);
    scene.pixels2.push_back(*uv2);
  }
  return scene;
}

void AddNoise(double sigma_px, std::mt19937_64* rng, std::vector<Eigen::Vector2d>* pixels) {
  std::normal_distribution<double> noise(0.0, sigma_px);
  for (Eigen::Vector2d& uv : *pixels) uv += Eigen::Vector2d(noise(*rng), noise(*rng));
}

double RotationError(const Eigen::Matrix3d& truth, const Eigen::Matrix3d& estimate) {
  return RotationAngle(truth.transpose() * estimate);
}

double DirectionError(const Eigen::Vector3d& truth, const Eigen::Vector3d& estimate) {
  const Eigen::Vector3d a = truth.normalized(), b = estimate.normalized();
  return std::atan2(a.cross(b).norm(), a.dot(b));
}

TwoViewOptions Options(bool estimate_focal = true) {
  TwoViewOptions options;
  options.estimate_focal = estimate_focal;
  return options;
}

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
    EXPECT_NE(report.message.find("(G6)"), std::string::npos) << report.message;
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

// ---- G10: diagnostics -------------------------------------------------------------------------------

// Points filling the 640 x 480 image (r up to 400 px), where a lens distortion shows most.
SceneSpec WideSpec() {
  SceneSpec spec;
  spec.box_half = Eigen::Vector3d(0.25, 0.19, 0.1);
  return spec;
}

bool HasWarning(const TwoViewReport& report, const std::string& prefix) {
  for (const std::string& w : report.warnings) {
    if (w.rfind(prefix, 0) == 0) return true;
  }
  return false;
}
const char kRadialWarning[] = "intrinsics/distortion suspect: residuals grow with radius (";
const char kInlierWarning[] = "inlier ratio ";

// Clean data, fresh scene and noise per trial, two layouts: the requirement is no warning of any kind
// in at least 99 % of trials (two_view.cc quotes the rate over 1000 trials per layout).
TEST(TwoViewDiagnostics, G10CleanDataRaisesNoWarning) {
  constexpr int kTrials = 250;
  for (bool wide : {false, true}) {
    std::mt19937_64 rng(wide ? 41 : 40);
    int warned = 0;
    for (int trial = 0; trial < kTrials; ++trial) {
      Scene scene = MakeScene(wide ? WideSpec() : SceneSpec{}, &rng);
      AddNoise(0.5, &rng, &scene.pixels1);
      AddNoise(0.5, &rng, &scene.pixels2);
      const TwoViewReport report = EstimateTwoView(Options(), scene.camera, scene.pixels1, scene.pixels2);
      ASSERT_EQ(report.outcome, Outcome::kSuccess) << report.message;
      if (!report.warnings.empty()) {
        ++warned;
        std::cout << "[ figures  ] false alarm: " << report.warnings.front() << "\n";
      }
    }
    std::cout << "[ figures  ] G10 clean, 0.5 px, " << (wide ? "points filling the image" : "test scene") << ": "
              << warned << " of " << kTrials << " trials warned\n";
    EXPECT_LE(warned, kTrials / 100);
  }
  // Exact data: residuals are rounding errors and must not look like a trend.
  std::mt19937_64 rng(42);
  for (bool wide : {false, true}) {
    const Scene scene = MakeScene(wide ? WideSpec() : SceneSpec{}, &rng);
    const TwoViewReport report = EstimateTwoView(Options(), scene.camera, scene.pixels1, scene.pixels2);
    ASSERT_EQ(report.outcome, Outcome::kSuccess) << report.message;
    EXPECT_TRUE(report.warnings.empty()) << report.warnings.front();
  }
}

// Pixels of a lens with k1 = -0.15 (9.6 px of barrel distortion in the image corners) handed over as if
// undistorted. f_x and the pose absorb most of it (the focal came out 4-60 % too long in trials), the residual
// RMS barely changes, yet the signed residuals keep a radial signature.
TEST(TwoViewDiagnostics, G10UncorrectedRadialDistortionIsFlagged) {
  constexpr int kTrials = 60;
  std::mt19937_64 rng(43);
  const CameraIntrinsics assumed = TestCamera();  // k1 = 0
  for (double sigma : {0.0, 0.5}) {
    int flagged = 0;
    for (int trial = 0; trial < (sigma == 0 ? 3 : kTrials); ++trial) {
      SceneSpec spec = WideSpec();
      spec.camera.k1 = -0.15;
      Scene scene = MakeScene(spec, &rng);
      AddNoise(sigma, &rng, &scene.pixels1);
      AddNoise(sigma, &rng, &scene.pixels2);
      const TwoViewReport report = EstimateTwoView(Options(), assumed, scene.pixels1, scene.pixels2);
      ASSERT_EQ(report.outcome, Outcome::kSuccess) << report.message;
      if (HasWarning(report, kRadialWarning)) {
        ++flagged;
        // The estimated k1 has the right sign.
        EXPECT_NE(report.warnings.front().find("k1 = -0."), std::string::npos) << report.warnings.front();
      }
      if (trial == 0 && !report.warnings.empty()) std::cout << "[ figures  ] " << report.warnings.front() << "\n";
    }
    const int trials = sigma == 0 ? 3 : kTrials;
    std::cout << "[ figures  ] G10 k1 = -0.15 uncorrected, sigma " << sigma << ": " << flagged << " of " << trials
              << " flagged\n";
    // The study (DISABLED_G10RadialWarningStudy) measured 299 of 300 at 0.5 px; 95 % leaves room.
    EXPECT_GE(flagged, sigma == 0 ? trials : (95 * trials) / 100);
  }
}

// The study behind the figures quoted in two_view.cc (about 15 s; run with
// --gtest_also_run_disabled_tests): radial warnings per 1000 trials at 0.5 px for both layouts, clean,
// with 10 % and 40 % random mismatches, and with k1 = -0.15 left uncorrected.
TEST(TwoViewDiagnostics, DISABLED_G10RadialWarningStudy) {
  struct Case {
    double k1, outlier_fraction;
    int trials;
  };
  for (const Case& c : {Case{0, 0, 1000}, Case{0, 0.1, 1000}, Case{0, 0.4, 1000}, Case{-0.15, 0, 300}}) {
    for (bool wide : {false, true}) {
      std::mt19937_64 rng(wide ? 51 : 50);
      std::uniform_real_distribution<double> u(0, 639), v(0, 479);
      int runs = 0, flagged = 0;
      for (int trial = 0; trial < c.trials; ++trial) {
        SceneSpec spec = wide ? WideSpec() : SceneSpec{};
        spec.camera.k1 = c.k1;
        Scene scene = MakeScene(spec, &rng);
        AddNoise(0.5, &rng, &scene.pixels1);
        AddNoise(0.5, &rng, &scene.pixels2);
        const int num_outliers = static_cast<int>(c.outlier_fraction * scene.points.size());
        for (int i = 0; i < num_outliers; ++i) scene.pixels2[i] = Eigen::Vector2d(u(rng), v(rng));
        const TwoViewReport report = EstimateTwoView(Options(), TestCamera(), scene.pixels1, scene.pixels2);
        if (report.outcome != Outcome::kSuccess) continue;
        ++runs;
        flagged += HasWarning(report, kRadialWarning);
      }
      std::cout << "[ figures  ] k1 " << c.k1 << ", " << 100 * c.outlier_fraction << " % mismatches, "
                << (wide ? "points filling the image" : "test scene") << ": " << flagged << " of " << runs
                << " successful trials warned (" << c.trials - runs << " not successful)\n";
    }
  }
}

TEST(TwoViewDiagnostics, G10LowInlierRatioIsFlagged) {
  std::mt19937_64 rng(44);
  std::uniform_real_distribution<double> u(0, 639), v(0, 479);
  Scene scene = MakeScene(SceneSpec{}, &rng);
  AddNoise(0.2, &rng, &scene.pixels1);
  AddNoise(0.2, &rng, &scene.pixels2);
  const TwoViewReport clean = EstimateTwoView(Options(), scene.camera, scene.pixels1, scene.pixels2);
  ASSERT_EQ(clean.outcome, Outcome::kSuccess) << clean.message;
  EXPECT_FALSE(HasWarning(clean, kInlierWarning));
  for (int i = 0; i < 24; ++i) scene.pixels2[i] = Eigen::Vector2d(u(rng), v(rng));  // 30 % mismatches
  const TwoViewReport report = EstimateTwoView(Options(), scene.camera, scene.pixels1, scene.pixels2);
  ASSERT_EQ(report.outcome, Outcome::kSuccess) << report.message;
  ASSERT_TRUE(HasWarning(report, kInlierWarning));
  const double ratio = static_cast<double>(report.num_inliers) / 80;
  EXPECT_LT(ratio, 0.8);
  std::ostringstream expected;
  expected << "inlier ratio " << ratio << ": outliers or wrong intrinsics";
  EXPECT_EQ(report.warnings.front().rfind(expected.str(), 0), 0u) << report.warnings.front();
}

// ---- G2: stacked essential matrices -----------------------------------------------------------------

Eigen::Vector2d ProjectAnyDepth(const CameraIntrinsics& camera, const Eigen::Vector3d& p) {
  // Also for a point behind the camera, which images through the centre like any other.
  return Eigen::Vector2d(camera.fx_px * p.x() / p.z() + camera.cx_px,
                         camera.fx_px * camera.mu * p.y() / p.z() + camera.cy_px);
}

Eigen::Matrix3d EssentialOf(const Rigid3& cam2_from_cam1) {
  return Skew<double>(cam2_from_cam1.translation) * cam2_from_cam1.rotation;
}

// Three stacked candidates, as OpenCV's 5-point solver returns them. 40 correspondences come from the
// true pose (points in front), 50 from another pose B whose points lie in front of camera 1 but half of
// them behind camera 2: E_B has the most inliers (50 > 40), but no decomposition of it puts more than
// about half of them in front of both cameras. Candidate 0 is the truth with R off by 5 deg.
TEST(TwoViewOpenCv, G2StackedCandidatesChooseByInliersAndCheirality) {
  std::mt19937_64 rng(45);
  SceneSpec spec;
  spec.num_points = 40;
  const Scene scene = MakeScene(spec, &rng);
  std::vector<Eigen::Vector2d> pixels1 = scene.pixels1, pixels2 = scene.pixels2;
  const Rigid3 pose_b(RotY(0.1), Eigen::Vector3d(0.1, 0.02, -0.75));
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  int behind_cam2 = 0;
  for (int k = 0; k < 50; ++k) {
    const double depth = (k % 2 == 0 ? 0.525 : 0.975) + 0.075 * unit(rng);
    const Eigen::Vector3d p(0.15 * unit(rng), 0.12 * unit(rng), depth);
    const Eigen::Vector3d p2 = pose_b * p;
    if (p2.z() < 0) ++behind_cam2;
    pixels1.push_back(ProjectAnyDepth(scene.camera, p));
    pixels2.push_back(ProjectAnyDepth(scene.camera, p2));
  }
  ASSERT_EQ(behind_cam2, 25);

  Eigen::MatrixXd stacked(9, 3);
  stacked.middleRows<3>(0) =
      EssentialOf(Rigid3(ExpSO3<double>(Eigen::Vector3d(0, 0, DegToRad(5))) * scene.cam2_from_cam1.rotation,
                         scene.cam2_from_cam1.translation));
  stacked.middleRows<3>(3) = EssentialOf(pose_b);
  stacked.middleRows<3>(6) = -3.0 * EssentialOf(scene.cam2_from_cam1);  // scale and sign are free
  const internal::EssentialChoice choice =
      internal::ChooseEssentialCandidate(stacked, scene.camera, pixels1, pixels2, {}, 1.0);
  ASSERT_EQ(choice.index, 2) << choice.message;
  EXPECT_EQ(choice.num_candidates, 3);
  EXPECT_GT(choice.num_inliers[1], choice.num_inliers[2]);  // inliers alone would pick E_B
  EXPECT_GE(choice.num_inliers[1], 50);
  EXPECT_LE(choice.num_good[1], 30);
  EXPECT_LT(choice.num_inliers[0], 10);
  EXPECT_GE(choice.num_good[2], 40);
  for (int i = 0; i < 40; ++i) EXPECT_TRUE(choice.good[i]) << i;
  EXPECT_LT(RotationError(scene.cam2_from_cam1.rotation, choice.rotation), 1e-9);
  EXPECT_LT(DirectionError(scene.cam2_from_cam1.translation, choice.translation), 1e-9);
  std::cout << "[ figures  ] G2 candidates: inliers " << choice.num_inliers[0] << "/" << choice.num_inliers[1] << "/"
            << choice.num_inliers[2] << ", in front " << choice.num_good[0] << "/" << choice.num_good[1] << "/"
            << choice.num_good[2] << "; " << choice.message << "\n";

  // A RANSAC mask restricts the points each candidate may count.
  std::vector<bool> only_b(pixels1.size(), false);
  for (size_t i = 40; i < only_b.size(); ++i) only_b[i] = true;
  EXPECT_EQ(internal::ChooseEssentialCandidate(stacked, scene.camera, pixels1, pixels2, only_b, 1.0).index, 1);
}

TEST(TwoViewOpenCv, G2MalformedOrNonFiniteCandidatesAreNeverPassedOn) {
  std::mt19937_64 rng(46);
  const Scene scene = MakeScene(SceneSpec{}, &rng);
  const Eigen::Matrix3d e = EssentialOf(scene.cam2_from_cam1);
  for (const Eigen::MatrixXd& bad : {Eigen::MatrixXd(0, 3), Eigen::MatrixXd(Eigen::MatrixXd::Ones(4, 3)),
                                     Eigen::MatrixXd(Eigen::MatrixXd::Ones(3, 4))}) {
    const internal::EssentialChoice choice =
        internal::ChooseEssentialCandidate(bad, scene.camera, scene.pixels1, scene.pixels2, {}, 1.0);
    EXPECT_EQ(choice.index, -1);
    EXPECT_EQ(choice.num_candidates, 0);
    EXPECT_NE(choice.message.find("is not 3N x 3 (G2)"), std::string::npos) << choice.message;
  }
  Eigen::MatrixXd stacked(9, 3);
  stacked.middleRows<3>(0).setConstant(std::numeric_limits<double>::quiet_NaN());
  stacked.middleRows<3>(3).setZero();
  stacked.middleRows<3>(6) = e;
  const internal::EssentialChoice choice =
      internal::ChooseEssentialCandidate(stacked, scene.camera, scene.pixels1, scene.pixels2, {}, 1.0);
  ASSERT_EQ(choice.index, 2) << choice.message;
  EXPECT_EQ(choice.num_good[2], 80);
  EXPECT_NE(choice.message.find("(2 non-finite or rejected by recoverPose)"), std::string::npos) << choice.message;
  // Nothing usable at all.
  stacked.middleRows<3>(6).setZero();
  EXPECT_EQ(internal::ChooseEssentialCandidate(stacked, scene.camera, scene.pixels1, scene.pixels2, {}, 1.0).index, -1);
}

}  // namespace
}  // namespace selfcal::twoview
