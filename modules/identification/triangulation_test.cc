#include "identification/triangulation.h"

#include <cmath>
#include <random>

#include <Eigen/Dense>
#include <gtest/gtest.h>

namespace selfcal::identification {
namespace {

CameraIntrinsics TestCamera() {
  CameraIntrinsics camera;
  camera.fx_px = 800;
  camera.mu = 1.02;
  camera.cx_px = 322;
  camera.cy_px = 236;
  camera.k1 = -0.08;
  return camera;
}

// A camera at `center` whose optical axis (z) points at `target`.
Rigid3 LookAt(const Eigen::Vector3d& center, const Eigen::Vector3d& target) {
  const Eigen::Vector3d z = (target - center).normalized();
  Eigen::Vector3d x = z.cross(Eigen::Vector3d::UnitZ());
  if (x.norm() < 1e-6) x = Eigen::Vector3d::UnitX();
  x.normalize();
  Eigen::Matrix3d r;
  r << x, z.cross(x), z;
  return Rigid3(r, center);
}

// Views of `point` from cameras spread on a sphere around `look_at`, pixels exact for focal fx_px.
PointTrack MakeTrack(const CameraIntrinsics& camera, double fx_px, const Eigen::Vector3d& point,
                     const std::vector<Eigen::Vector3d>& centers, const Eigen::Vector3d& look_at) {
  PointTrack track;
  for (const Eigen::Vector3d& c : centers) {
    const Rigid3 base_from_cam = LookAt(c, look_at);
    double u = 0, v = 0;
    EXPECT_TRUE(ProjectPoint<double>(camera, fx_px, camera.k1, base_from_cam.Inverse() * point, &u, &v));
    track.base_from_cam.push_back(base_from_cam);
    track.pixels.emplace_back(u, v);
  }
  return track;
}

std::vector<Eigen::Vector3d> Centers() {
  return {{0.0, 0.0, 0.0}, {0.25, 0.05, 0.02}, {-0.1, 0.2, -0.05}, {0.05, -0.15, 0.1}};
}

TEST(ScaleByNominalRatios, IsEquation21) {
  const std::vector<Eigen::Vector3d> directions = {Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(0, 0.6, 0.8),
                                                   Eigen::Vector3d(0, 0, -1)};
  const std::vector<Eigen::Vector3d> nominal = {Eigen::Vector3d(0.3, 0.4, 0), Eigen::Vector3d(0, 1, 0),
                                                Eigen::Vector3d(0.1, 0, 0)};
  const auto t = ScaleByNominalRatios(directions, nominal, 2.0);
  ASSERT_EQ(t.size(), 3u);
  EXPECT_LT((t[0] - Eigen::Vector3d(2.0, 0, 0)).norm(), 1e-15);
  EXPECT_LT((t[1] - 4.0 * Eigen::Vector3d(0, 0.6, 0.8)).norm(), 1e-15);  // (1 / 0.5) * 2
  EXPECT_LT((t[2] - Eigen::Vector3d(0, 0, -0.4)).norm(), 1e-15);         // (0.1 / 0.5) * 2
}

TEST(Triangulation, ExactWithoutNoise) {
  const CameraIntrinsics camera = TestCamera();
  const double fx = 812.5;  // differs from camera.fx_px: the estimate is what is used
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-0.05, 0.05);
  for (int trial = 0; trial < 20; ++trial) {
    const Eigen::Vector3d point(0.1 + u(rng), 0.05 + u(rng), 0.8 + u(rng));
    const PointTrack track = MakeTrack(camera, fx, point, Centers(), Eigen::Vector3d(0.1, 0.05, 0.8));
    const TriangulationResult result = TriangulatePoint(camera, fx, track, 0.5);
    ASSERT_TRUE(result.ok) << result.message;
    EXPECT_LT((result.point - point).norm(), 1e-9);
    EXPECT_LT(result.rms_reprojection_px, 1e-6);
    // Two views are enough.
    PointTrack two = track;
    two.base_from_cam.resize(2);
    two.pixels.resize(2);
    const TriangulationResult pair = TriangulatePoint(camera, fx, two, 0.5);
    ASSERT_TRUE(pair.ok) << pair.message;
    EXPECT_LT((pair.point - point).norm(), 1e-9);
  }
}

TEST(Triangulation, CovarianceMatchesMonteCarlo) {
  const CameraIntrinsics camera = TestCamera();
  const double sigma_px = 0.5;
  const Eigen::Vector3d point(0.05, 0.02, 0.9);
  const PointTrack exact = MakeTrack(camera, camera.fx_px, point, Centers(), point);
  const TriangulationResult reference = TriangulatePoint(camera, camera.fx_px, exact, sigma_px);
  ASSERT_TRUE(reference.ok);
  std::mt19937 rng(4);
  std::normal_distribution<double> g(0.0, sigma_px);
  const int kTrials = 2000;
  Eigen::Matrix3d sample = Eigen::Matrix3d::Zero();
  for (int trial = 0; trial < kTrials; ++trial) {
    PointTrack noisy = exact;
    for (Eigen::Vector2d& px : noisy.pixels) px += Eigen::Vector2d(g(rng), g(rng));
    const TriangulationResult r = TriangulatePoint(camera, camera.fx_px, noisy, sigma_px);
    ASSERT_TRUE(r.ok) << r.message;
    const Eigen::Vector3d e = r.point - point;
    sample += e * e.transpose() / kTrials;
  }
  // Compare along the principal directions of the predicted covariance (depth is the weak one).
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(reference.covariance);
  for (int k = 0; k < 3; ++k) {
    const Eigen::Vector3d d = eig.eigenvectors().col(k);
    const double ratio = d.dot(sample * d) / eig.eigenvalues()[k];
    EXPECT_GT(ratio, 0.85) << "direction " << k;
    EXPECT_LT(ratio, 1.15) << "direction " << k;
  }
}

TEST(Triangulation, RefusesSingleView) {
  const CameraIntrinsics camera = TestCamera();
  const Eigen::Vector3d point(0, 0, 1);
  PointTrack track = MakeTrack(camera, camera.fx_px, point, {Eigen::Vector3d::Zero()}, point);
  const TriangulationResult result = TriangulatePoint(camera, camera.fx_px, track, 0.5);
  EXPECT_FALSE(result.ok);
  EXPECT_NE(result.message.find("1 view"), std::string::npos) << result.message;
}

TEST(Triangulation, RefusesPointBehindACamera) {
  // Camera 0 at the origin looks along +z; camera 1 at (2, 0, -2) looks along -x. The viewing lines
  // meet at (0, 0, -2), behind camera 0.
  CameraIntrinsics camera = TestCamera();
  camera.k1 = 0;
  PointTrack track;
  track.base_from_cam.push_back(LookAt(Eigen::Vector3d::Zero(), Eigen::Vector3d(0, 0, 1)));
  track.base_from_cam.push_back(LookAt(Eigen::Vector3d(2, 0, -2), Eigen::Vector3d(0, 0, -2)));
  track.pixels = {Eigen::Vector2d(camera.cx_px, camera.cy_px), Eigen::Vector2d(camera.cx_px, camera.cy_px)};
  const TriangulationResult result = TriangulatePoint(camera, camera.fx_px, track, 0.5);
  EXPECT_FALSE(result.ok);
  EXPECT_NE(result.message.find("behind camera 0"), std::string::npos) << result.message;
}

TEST(Triangulation, RefusesParallelRays) {
  // The second camera moved straight along the line of sight: depth is unobservable.
  const CameraIntrinsics camera = TestCamera();
  const Eigen::Vector3d point(0, 0, 1);
  const PointTrack track =
      MakeTrack(camera, camera.fx_px, point, {Eigen::Vector3d::Zero(), Eigen::Vector3d(0, 0, 0.3)}, point);
  const TriangulationResult result = TriangulatePoint(camera, camera.fx_px, track, 0.5);
  EXPECT_FALSE(result.ok);
  EXPECT_NE(result.message.find("ill-conditioned"), std::string::npos) << result.message;
}

// A yardstick of true length `length` between two points, seen from `centers`, in a world whose
// lengths are all divided by `true_scale` (what the unscaled identification delivers).
YardstickView MakeYardstick(const CameraIntrinsics& camera, const Eigen::Vector3d& mid, const Eigen::Vector3d& dir,
                            double length, double true_scale, const std::vector<Eigen::Vector3d>& centers) {
  YardstickView y;
  y.length_m = length;
  std::vector<Eigen::Vector3d> scaled_centers;
  for (const Eigen::Vector3d& c : centers) scaled_centers.push_back(c / true_scale);
  const Eigen::Vector3d a = (mid + 0.5 * length * dir.normalized()) / true_scale;
  const Eigen::Vector3d b = (mid - 0.5 * length * dir.normalized()) / true_scale;
  y.end_a = MakeTrack(camera, camera.fx_px, a, scaled_centers, mid / true_scale);
  y.end_b = MakeTrack(camera, camera.fx_px, b, scaled_centers, mid / true_scale);
  return y;
}

TEST(Yardstick, ExactScaleWithoutNoise) {
  const CameraIntrinsics camera = TestCamera();
  const double true_scale = 1.37;
  std::vector<YardstickView> sticks = {
      MakeYardstick(camera, Eigen::Vector3d(0.05, 0.0, 0.9), Eigen::Vector3d(1, 0.2, 0), 0.2, true_scale, Centers()),
      MakeYardstick(camera, Eigen::Vector3d(-0.05, 0.1, 1.0), Eigen::Vector3d(0.1, 1, 0.3), 0.15, true_scale,
                    Centers())};
  const ScaleEstimate estimate = EstimateYardstickScale(camera, camera.fx_px, sticks, 0.5);
  ASSERT_TRUE(estimate.ok) << estimate.message;
  EXPECT_NEAR(estimate.scale, true_scale, 1e-9);
  ASSERT_EQ(estimate.per_yardstick_scale.size(), 2u);
  EXPECT_NEAR(estimate.per_yardstick_scale[0], true_scale, 1e-9);
  EXPECT_NEAR(estimate.per_yardstick_scale[1], true_scale, 1e-9);
  EXPECT_NEAR(estimate.measured_lengths_m[0], 0.2 / true_scale, 1e-9);
  EXPECT_GT(estimate.scale_sigma, 0);
  EXPECT_LT(estimate.scale_sigma / estimate.scale, 0.05);
}

TEST(Yardstick, WeightedLeastSquaresAndSigma) {
  const CameraIntrinsics camera = TestCamera();
  const double true_scale = 0.8, sigma_px = 0.3;
  // A well-seen stick and one far away (larger length variance, smaller weight).
  const std::vector<YardstickView> exact = {
      MakeYardstick(camera, Eigen::Vector3d(0.05, 0.0, 0.7), Eigen::Vector3d(1, 0.2, 0), 0.2, true_scale, Centers()),
      MakeYardstick(camera, Eigen::Vector3d(0.0, 0.1, 2.5), Eigen::Vector3d(0.3, 1, 0.6), 0.25, true_scale, Centers()),
      MakeYardstick(camera, Eigen::Vector3d(-0.1, -0.1, 1.2), Eigen::Vector3d(0, 0.3, 1), 0.3, true_scale, Centers())};
  std::mt19937 rng(8);
  std::normal_distribution<double> g(0.0, sigma_px);
  const int kTrials = 1000;
  double sum = 0, sum_sq = 0, reported_sigma = 0;
  for (int trial = 0; trial < kTrials; ++trial) {
    std::vector<YardstickView> noisy = exact;
    for (YardstickView& y : noisy) {
      for (Eigen::Vector2d& px : y.end_a.pixels) px += Eigen::Vector2d(g(rng), g(rng));
      for (Eigen::Vector2d& px : y.end_b.pixels) px += Eigen::Vector2d(g(rng), g(rng));
    }
    const ScaleEstimate estimate = EstimateYardstickScale(camera, camera.fx_px, noisy, sigma_px);
    ASSERT_TRUE(estimate.ok) << estimate.message;
    if (trial == 0) {
      // The weighted least squares by hand: w = 1 / var(l), var from the endpoint covariances.
      double swll = 0, swLl = 0;
      for (const YardstickView& y : noisy) {
        const TriangulationResult a = TriangulatePoint(camera, camera.fx_px, y.end_a, sigma_px);
        const TriangulationResult b = TriangulatePoint(camera, camera.fx_px, y.end_b, sigma_px);
        const Eigen::Vector3d u = (a.point - b.point).normalized();
        const double l = (a.point - b.point).norm();
        const double w = 1.0 / u.dot((a.covariance + b.covariance) * u);
        swll += w * l * l;
        swLl += w * y.length_m * l;
      }
      EXPECT_NEAR(estimate.scale, swLl / swll, 1e-12);
      // The far stick is the worst one on its own.
      EXPECT_GT(std::abs(estimate.per_yardstick_scale[1] - true_scale), 0.0);
    }
    sum += estimate.scale;
    sum_sq += estimate.scale * estimate.scale;
    reported_sigma += estimate.scale_sigma / kTrials;
  }
  const double mean = sum / kTrials;
  const double sd = std::sqrt(sum_sq / kTrials - mean * mean);
  EXPECT_NEAR(mean, true_scale, 4 * sd / std::sqrt(kTrials));
  EXPECT_GT(sd / reported_sigma, 0.85);
  EXPECT_LT(sd / reported_sigma, 1.15);
}

TEST(Yardstick, RefusesAnEndSeenOnce) {  // S1
  const CameraIntrinsics camera = TestCamera();
  std::vector<YardstickView> sticks = {
      MakeYardstick(camera, Eigen::Vector3d(0.05, 0.0, 0.9), Eigen::Vector3d(1, 0.2, 0), 0.2, 1.0, Centers())};
  sticks[0].end_b.base_from_cam.resize(1);
  sticks[0].end_b.pixels.resize(1);
  const ScaleEstimate estimate = EstimateYardstickScale(camera, camera.fx_px, sticks, 0.5);
  EXPECT_FALSE(estimate.ok);
  EXPECT_NE(estimate.message.find("need 2"), std::string::npos) << estimate.message;
  EXPECT_NE(estimate.message.find("end b"), std::string::npos) << estimate.message;
}

TEST(Yardstick, RefusesIllConditionedScale) {  // S3
  // A short stick far away seen from a 2 cm baseline: the length is poorly determined.
  const CameraIntrinsics camera = TestCamera();
  const std::vector<Eigen::Vector3d> narrow = {{0, 0, 0}, {0.02, 0, 0}};
  const std::vector<YardstickView> sticks = {
      MakeYardstick(camera, Eigen::Vector3d(0.0, 0.0, 3.0), Eigen::Vector3d(0.2, 0.1, 1), 0.1, 1.0, narrow)};
  const ScaleEstimate estimate = EstimateYardstickScale(camera, camera.fx_px, sticks, 0.5);
  EXPECT_FALSE(estimate.ok);
  EXPECT_NE(estimate.message.find("scale ill-conditioned"), std::string::npos) << estimate.message;
  EXPECT_GT(estimate.scale_sigma / estimate.scale, 0.05);
  // The same stick seen from a wide baseline is accepted.
  const ScaleEstimate wide =
      EstimateYardstickScale(camera, camera.fx_px,
                             {MakeYardstick(camera, Eigen::Vector3d(0.0, 0.0, 3.0), Eigen::Vector3d(0.2, 0.1, 1), 0.1,
                                            1.0, {{0, 0, 0}, {1.5, 0, 0}, {0, 1.5, 0.2}})},
                             0.5);
  EXPECT_TRUE(wide.ok) << wide.message;
}

}  // namespace
}  // namespace selfcal::identification
