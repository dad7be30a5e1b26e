#include <random>

#include <gtest/gtest.h>

#include "geometry/rigid3.h"

namespace selfcal {
namespace {

TEST(Geometry, ExpLogRoundTrip) {
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int i = 0; i < 200; ++i) {
    Eigen::Vector3d axis(u(rng), u(rng), u(rng));
    axis.normalize();
    // angles from tiny to nearly pi, the hard ends of Log
    const double angle = (i < 50) ? 1e-9 * (i + 1) : (i < 100 ? kPi - 1e-7 * (i - 49) : 3.1 * std::abs(u(rng)));
    const Eigen::Vector3d w = angle * axis;
    const Eigen::Matrix3d r = ExpSO3<double>(w);
    EXPECT_NEAR((r.transpose() * r - Eigen::Matrix3d::Identity()).norm(), 0.0, 1e-14);
    EXPECT_NEAR(r.determinant(), 1.0, 1e-14);
    const Eigen::Vector3d w2 = LogSO3(r);
    EXPECT_LT((ExpSO3<double>(w2) - r).norm(), 1e-9) << "angle " << angle;
    EXPECT_NEAR(RotationAngle(r), angle, 1e-7) << "angle " << angle;
  }
}

TEST(Geometry, ExpMatchesEigenAngleAxis) {
  const Eigen::Vector3d w(0.3, -0.2, 0.7);
  const Eigen::Matrix3d expected = Eigen::AngleAxisd(w.norm(), w.normalized()).toRotationMatrix();
  EXPECT_LT((ExpSO3<double>(w) - expected).norm(), 1e-15);
  EXPECT_LT((RotZ(0.4) - Eigen::AngleAxisd(0.4, Eigen::Vector3d::UnitZ()).toRotationMatrix()).norm(), 1e-15);
  EXPECT_LT((RotY(0.4) - Eigen::AngleAxisd(0.4, Eigen::Vector3d::UnitY()).toRotationMatrix()).norm(), 1e-15);
  EXPECT_LT((RotX(0.4) - Eigen::AngleAxisd(0.4, Eigen::Vector3d::UnitX()).toRotationMatrix()).norm(), 1e-15);
}

TEST(Geometry, RigidComposeAndInverse) {
  const double v1[6] = {0.1, -0.2, 0.3, 0.4, 0.1, -0.3};
  const double v2[6] = {-0.5, 0.2, 0.05, -0.2, 0.6, 0.1};
  const Rigid3 b_from_a = RigidFromTranslationRotvec(v1);
  const Rigid3 c_from_b = RigidFromTranslationRotvec(v2);
  const Eigen::Vector3d p_in_a(0.3, 0.7, -1.1);
  const Eigen::Vector3d p_in_c = (c_from_b * b_from_a) * p_in_a;
  EXPECT_LT((p_in_c - c_from_b * (b_from_a * p_in_a)).norm(), 1e-15);
  EXPECT_LT(((b_from_a.Inverse() * b_from_a) * p_in_a - p_in_a).norm(), 1e-15);
  const PoseDifference d = ComparePoses(b_from_a, b_from_a);
  EXPECT_EQ(d.position_m, 0.0);
  EXPECT_NEAR(d.rotation_rad, 0.0, 1e-12);
}

TEST(Geometry, NearestRotationRestoresOrthogonality) {
  Eigen::Matrix3d r = ExpSO3<double>(Eigen::Vector3d(0.2, 0.3, -0.1));
  Eigen::Matrix3d noisy = r;
  noisy(0, 1) += 1e-3;
  const Eigen::Matrix3d fixed = NearestRotation(noisy);
  EXPECT_NEAR((fixed.transpose() * fixed - Eigen::Matrix3d::Identity()).norm(), 0, 1e-14);
  EXPECT_LT((fixed - r).norm(), 2e-3);
}

}  // namespace
}  // namespace selfcal
