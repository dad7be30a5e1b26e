#include "tracking/planar_fit.h"

#include <random>

#include <gtest/gtest.h>

namespace selfcal::tracking {
namespace {

Eigen::Matrix3d SomeHomography() {
  Eigen::Matrix3d h;
  h << 1.1, 0.2, 30.0, -0.15, 0.95, 12.0, 2e-4, -1e-4, 1.0;
  return h;
}

std::vector<Eigen::Vector2d> Points(int n, std::mt19937_64* rng) {
  std::uniform_real_distribution<double> u(0, 600), v(0, 400);
  std::vector<Eigen::Vector2d> pts;
  for (int k = 0; k < n; ++k) pts.emplace_back(u(*rng), v(*rng));
  return pts;
}

TEST(PlanarFit, ExactHomographyFromFourAndManyPoints) {
  std::mt19937_64 rng(1);
  const Eigen::Matrix3d h = SomeHomography();
  for (const int n : {4, 50}) {
    const std::vector<Eigen::Vector2d> from = Points(n, &rng);
    std::vector<Eigen::Vector2d> to;
    for (const auto& p : from) to.push_back(MapPoint(h, p));
    const auto fit = FitHomography(from, to);
    ASSERT_TRUE(fit.has_value());
    EXPECT_LT((*fit - h).norm() / h.norm(), 1e-9) << "n = " << n;
  }
}

TEST(PlanarFit, ExactAffine) {
  std::mt19937_64 rng(2);
  Eigen::Matrix3d a;
  a << 0.9, -0.3, 5.0, 0.25, 1.05, -7.0, 0, 0, 1;
  const std::vector<Eigen::Vector2d> from = Points(10, &rng);
  std::vector<Eigen::Vector2d> to;
  for (const auto& p : from) to.push_back(MapPoint(a, p));
  const auto fit = FitAffine(from, to);
  ASSERT_TRUE(fit.has_value());
  EXPECT_LT((*fit - a).norm(), 1e-9);
}

TEST(PlanarFit, DegenerateInputsGiveNoModel) {
  const std::vector<Eigen::Vector2d> line = {{0, 0}, {1, 1}, {2, 2}, {3, 3}, {4, 4}};
  EXPECT_FALSE(FitHomography(line, line).has_value());
  EXPECT_FALSE(FitAffine(line, line).has_value());
  EXPECT_FALSE(FitHomography({{0, 0}, {1, 0}, {0, 1}}, {{0, 0}, {1, 0}, {0, 1}}).has_value());
  EXPECT_FALSE(FitHomography({{0, 0}, {1, 0}, {0, 1}, {std::nan(""), 1}}, {{0, 0}, {1, 0}, {0, 1}, {1, 1}}).has_value());
}

// Seeded noise of 0.3 px plus 20 % gross outliers: RANSAC flags exactly the outliers (they are moved by
// 10-40 px, far above the 1.5 px threshold = 5 sigma) and the refit is within the noise of the truth.
TEST(PlanarFit, RansacFindsTheOutliers) {
  std::mt19937_64 rng(3);
  const Eigen::Matrix3d h = SomeHomography();
  const std::vector<Eigen::Vector2d> from = Points(100, &rng);
  std::normal_distribution<double> noise(0, 0.3);
  std::uniform_real_distribution<double> jump(10, 40), angle(0, 2 * M_PI);
  std::vector<Eigen::Vector2d> to;
  std::vector<bool> outlier(from.size(), false);
  for (size_t k = 0; k < from.size(); ++k) {
    Eigen::Vector2d p = MapPoint(h, from[k]) + Eigen::Vector2d(noise(rng), noise(rng));
    if (k % 5 == 0) {
      const double a = angle(rng);
      p += jump(rng) * Eigen::Vector2d(std::cos(a), std::sin(a));
      outlier[k] = true;
    }
    to.push_back(p);
  }
  RobustPlanarFitOptions o;
  o.inlier_threshold = 1.5;
  const RobustPlanarFit fit = FitPlanarRobust(o, from, to);
  ASSERT_TRUE(fit.ok) << fit.message;
  EXPECT_EQ(fit.inlier_count, 80);
  for (size_t k = 0; k < from.size(); ++k) EXPECT_EQ(fit.inliers[k], !outlier[k]) << k;
  for (const auto& p : from) EXPECT_LT((MapPoint(fit.to_from_from, p) - MapPoint(h, p)).norm(), 0.3);

  // Same seed, same answer.
  const RobustPlanarFit again = FitPlanarRobust(o, from, to);
  EXPECT_EQ(again.to_from_from, fit.to_from_from);

  // Too many outliers for the minimum inlier fraction: refused with a reason.
  o.min_inlier_fraction = 0.9;
  const RobustPlanarFit refused = FitPlanarRobust(o, from, to);
  EXPECT_FALSE(refused.ok);
  EXPECT_NE(refused.message.find("80 of 100"), std::string::npos) << refused.message;
}

}  // namespace
}  // namespace selfcal::tracking
