// CountCheirality decides most depth signs without TriangulateTwoView's QR; the counts must be those of
// the QR everywhere, including where the signs are hard: tiny parallax, points near a camera centre or
// at infinity, pure rotation.
#include <cmath>
#include <random>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "twoview/two_view.h"
#include "twoview/two_view_internal.h"

namespace selfcal::twoview {
namespace {

// The definition: every point through TriangulateTwoView.
internal::CheiralityCount ReferenceCount(const Rigid3& pose, const std::vector<Eigen::Vector2d>& n1,
                                         const std::vector<Eigen::Vector2d>& n2, double min_parallax_rad) {
  internal::CheiralityCount count;
  const double cos_min = std::cos(min_parallax_rad);
  for (size_t i = 0; i < n1.size(); ++i) {
    const Eigen::Vector3d p1 = TriangulateTwoView(pose, n1[i], n2[i]);
    if (!p1.allFinite()) continue;
    const Eigen::Vector3d p2 = pose * p1;
    if (p1.z() > 0 && p2.z() > 0) {
      ++count.in_front;
      continue;
    }
    const Eigen::Vector3d ray1 = pose.rotation * Eigen::Vector3d(n1[i].x(), n1[i].y(), 1).normalized();
    const Eigen::Vector3d ray2 = Eigen::Vector3d(n2[i].x(), n2[i].y(), 1).normalized();
    if (ray1.dot(ray2) <= cos_min) ++count.behind;
  }
  return count;
}

TEST(CheiralityCountTest, SameCountsAsTriangulation) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> unit(-1, 1);
  std::normal_distribution<double> normal(0, 1);
  long points = 0;
  for (int trial = 0; trial < 400; ++trial) {
    const Eigen::Vector3d axis = Eigen::Vector3d(unit(rng), unit(rng), unit(rng)).normalized();
    const Eigen::Matrix3d r = Eigen::AngleAxisd(0.5 * unit(rng), axis).toRotationMatrix();
    // Baselines from 1e-12 (pure rotation to round-off) to 1, unit as in the candidates.
    const double baseline = std::pow(10.0, -12 * (unit(rng) + 1) / 2);
    const Eigen::Vector3d centre2 = baseline * Eigen::Vector3d(unit(rng), unit(rng), unit(rng));
    const Rigid3 truth(r, -(r * centre2));
    std::vector<Eigen::Vector2d> n1, n2;
    for (int i = 0; i < 200; ++i) {
      // Depths from 1e-9 to 1e9 and of either sign; pixel noise from none to 1e-2 (normalised).
      const double depth = (i % 7 == 0 ? -1 : 1) * std::pow(10.0, 9 * unit(rng));
      const Eigen::Vector3d p1 = depth * Eigen::Vector3d(0.5 * unit(rng), 0.5 * unit(rng), 1);
      const Eigen::Vector3d p2 = truth * p1;
      const double noise = i % 3 == 0 ? 0.0 : std::pow(10.0, -2 - 12 * (unit(rng) + 1) / 2);
      n1.push_back(p1.head<2>() / p1.z() + noise * Eigen::Vector2d(normal(rng), normal(rng)));
      n2.push_back(p2.head<2>() / p2.z() + noise * Eigen::Vector2d(normal(rng), normal(rng)));
    }
    std::vector<int> indices(n1.size());
    for (size_t i = 0; i < indices.size(); ++i) indices[i] = static_cast<int>(i);
    // All four factorisation candidates of the true essential matrix, with t of unit length.
    const Eigen::Vector3d t = truth.translation.norm() > 0 ? truth.translation.normalized() : Eigen::Vector3d::UnitX();
    const Eigen::Matrix3d flip = Eigen::AngleAxisd(M_PI, t).toRotationMatrix();
    for (const Rigid3& candidate : {Rigid3(r, t), Rigid3(r, -t), Rigid3(flip * r, t), Rigid3(flip * r, -t)}) {
      for (double parallax : {0.0, 1e-3}) {
        const internal::CheiralityCount fast = internal::CountCheirality(candidate, n1, n2, indices, parallax);
        const internal::CheiralityCount reference = ReferenceCount(candidate, n1, n2, parallax);
        ASSERT_EQ(fast.in_front, reference.in_front) << "trial " << trial;
        ASSERT_EQ(fast.behind, reference.behind) << "trial " << trial;
        points += static_cast<long>(n1.size());
      }
    }
  }
  EXPECT_EQ(points, 400L * 200 * 8);
}

}  // namespace
}  // namespace selfcal::twoview
