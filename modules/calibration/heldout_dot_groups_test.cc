#include "calibration/heldout_dot_groups.h"

#include <gtest/gtest.h>

namespace selfcal::calibration {
namespace {

// Two dots joined by a yardstick along x: the group's H is blockdiag(H_a, H_b) plus the length residual's
// w w^T, w = (e_x, -e_x) sigma_px / sigma_m, and its inverse is that matrix's (checked against a dense
// inverse written out here); the length's direction is the only one the yardstick constrains.
TEST(HeldOutDotGroups, TwoDotsJoinedByAYardstickAreSolvedAsOneBlock) {
  const std::map<int, Eigen::Vector3d> dots = {{4, {0.3, 0, 1}}, {9, {0.1, 0, 1}}, {5, {0, 0.2, 1}}};
  std::map<int, Eigen::Matrix3d> hdd;
  hdd[4] = Eigen::Vector3d(2, 3, 4).asDiagonal();
  hdd[9] = Eigen::Vector3d(5, 6, 7).asDiagonal();
  hdd[5] = Eigen::Matrix3d::Identity();
  const std::vector<DotGroup> groups = YardstickDotGroups({{4, 9, 0.2}}, 0.5, 1.0, hdd, dots);
  ASSERT_EQ(groups.size(), 1u);
  ASSERT_EQ(groups[0].ids, (std::vector<int>{4, 9}));
  Eigen::MatrixXd h = Eigen::MatrixXd::Zero(6, 6);
  h.topLeftCorner<3, 3>() = hdd[4];
  h.bottomRightCorner<3, 3>() = hdd[9];
  Eigen::VectorXd w = Eigen::VectorXd::Zero(6);
  w[0] = 2.0;  // 1 px / 0.5 m
  w[3] = -2.0;
  h += w * w.transpose();
  EXPECT_LT((groups[0].inverse - h.inverse()).norm(), 1e-12 * h.inverse().norm());
  // Only x couples: the y and z blocks stay each dot's own.
  EXPECT_NEAR(groups[0].inverse(1, 1), 1.0 / 3, 1e-12);
  EXPECT_NEAR(groups[0].inverse(5, 5), 1.0 / 7, 1e-12);
  EXPECT_NEAR(groups[0].inverse(1, 4), 0.0, 1e-12);
}

// A yardstick with an end the identification images do not place joins nothing; two yardsticks sharing a
// dot make one group of three; no sigma (the fit had no yardstick): no groups.
TEST(HeldOutDotGroups, UnplacedEndsChainsAndNoYardstick) {
  const std::map<int, Eigen::Vector3d> dots = {{1, {0, 0, 1}}, {2, {0.1, 0, 1}}, {3, {0.1, 0.1, 1}}, {7, {1, 1, 1}}};
  std::map<int, Eigen::Matrix3d> hdd;
  for (int id : {1, 2, 3}) hdd[id] = Eigen::Matrix3d::Identity();
  EXPECT_TRUE(YardstickDotGroups({{1, 7, 1.0}}, 1e-6, 0.2, hdd, dots).empty());
  EXPECT_TRUE(YardstickDotGroups({{1, 2, 0.1}}, 0.0, 0.2, hdd, dots).empty());
  const std::vector<DotGroup> chain = YardstickDotGroups({{1, 2, 0.1}, {2, 3, 0.1}}, 1e-6, 0.2, hdd, dots);
  ASSERT_EQ(chain.size(), 1u);
  EXPECT_EQ(chain[0].ids.size(), 3u);
  EXPECT_EQ(chain[0].inverse.rows(), 9);
  EXPECT_TRUE(chain[0].inverse.allFinite());
}

}  // namespace
}  // namespace selfcal::calibration
