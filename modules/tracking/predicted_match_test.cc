// Gated naming by prediction (predicted_match.h) on synthetic point sets with a known truth: every name
// right or absent, ambiguities refused, the model offset found from anchors or by votes.
#include "tracking/predicted_match.h"

#include <random>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "tracking/planar_fit.h"

namespace selfcal::tracking {
namespace {

// An irregular scene: n dots at least 15 px apart in a 640 x 480 image.
std::vector<Eigen::Vector2d> Scene(int n, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(20, 620), v(20, 460);
  std::vector<Eigen::Vector2d> pts;
  while (static_cast<int>(pts.size()) < n) {
    const Eigen::Vector2d p(u(rng), v(rng));
    bool spaced = true;
    for (const auto& q : pts) spaced = spaced && (p - q).norm() >= 15;
    if (spaced) pts.push_back(p);
  }
  return pts;
}

std::vector<PredictedDot> Predictions(const std::vector<Eigen::Vector2d>& uv, double sigma_px) {
  std::vector<PredictedDot> out;
  for (size_t k = 0; k < uv.size(); ++k) {
    out.push_back({static_cast<int>(k), uv[k], sigma_px * sigma_px * Eigen::Matrix2d::Identity()});
  }
  return out;
}

TEST(PredictedMatch, NamesEveryDetectionOfAnAccuratePredictionRight) {
  const std::vector<Eigen::Vector2d> truth = Scene(60, 3);
  std::mt19937_64 rng(5);
  std::normal_distribution<double> noise(0, 0.5);
  std::vector<Eigen::Vector2d> detections;
  for (size_t k = truth.size(); k-- > 0;) detections.push_back(truth[k] + Eigen::Vector2d(noise(rng), noise(rng)));
  const PredictedMatch m = MatchPredictions(Predictions(truth, 0.5), detections, PredictedMatchOptions());
  EXPECT_EQ(m.ambiguous, 0);
  int right = 0;
  for (size_t k = 0; k < detections.size(); ++k) {
    ASSERT_TRUE(m.id_of_detection[k] == -1 || m.id_of_detection[k] == static_cast<int>(truth.size() - 1 - k));
    right += m.id_of_detection[k] >= 0 ? 1 : 0;
  }
  EXPECT_GE(right, 58);  // the 99.9 % gate: at most a few outside by chance
  EXPECT_EQ(m.named, right);
}

TEST(PredictedMatch, TwoPredictionsInOneGateOrTwoDetectionsInOneGateNameNothing) {
  // Two predictions 3 px apart with sigma 2 px: the detection between them is in both gates.
  std::vector<PredictedDot> p = {{7, {100, 100}, 4 * Eigen::Matrix2d::Identity()},
                                 {8, {103, 100}, 4 * Eigen::Matrix2d::Identity()},
                                 {9, {300, 300}, 4 * Eigen::Matrix2d::Identity()}};
  // Two detections inside the gate of dot 9; one isolated far from everything.
  const std::vector<Eigen::Vector2d> d = {{101.5, 100}, {299, 300}, {302, 301}, {500, 50}};
  const PredictedMatch m = MatchPredictions(p, d, PredictedMatchOptions());
  EXPECT_EQ(m.id_of_detection, (std::vector<int>{-1, -1, -1, -1}));
  EXPECT_EQ(m.ambiguous, 3);
  EXPECT_EQ(m.outside_gates, 1);
  EXPECT_EQ(m.named, 0);
}

TEST(PredictedMatch, AnElongatedGateFollowsItsCovariance) {
  // Long along u (an epipolar direction), narrow along v.
  const PredictedDot p{3, {200, 200}, (Eigen::Matrix2d() << 100, 0, 0, 0.25).finished()};
  EXPECT_LT(Mahalanobis2(p, {230, 200}), 13.8);
  EXPECT_GT(Mahalanobis2(p, {200, 203}), 13.8);
}

TEST(PredictedMatch, CorrectionFromAnchorsRemovesAnAffineOffsetAndIgnoresSwaps) {
  const std::vector<Eigen::Vector2d> predicted = Scene(30, 11);
  Eigen::Matrix3d truth_map = Eigen::Matrix3d::Identity();
  truth_map.topLeftCorner<2, 2>() << 1.01, 0.004, -0.003, 0.995;
  truth_map.topRightCorner<2, 1>() << 6.0, -4.0;
  std::mt19937_64 rng(2);
  std::normal_distribution<double> noise(0, 0.3);
  std::vector<Eigen::Vector2d> observed;
  for (const auto& p : predicted) {
    observed.push_back((truth_map * p.homogeneous()).hnormalized() + Eigen::Vector2d(noise(rng), noise(rng)));
  }
  std::swap(observed[4], observed[9]);  // two anchors with swapped identities
  const PredictionCorrection c = FitPredictionCorrection(predicted, observed, PredictionCorrectionOptions());
  ASSERT_TRUE(c.ok) << c.message;
  EXPECT_EQ(c.inliers, 28) << c.message;
  const double sigma = std::sqrt(c.model_cov_px2(0, 0));
  EXPECT_GT(sigma, 0.3 * 0.6);
  EXPECT_LT(sigma, 0.3 * 1.6);
  const Eigen::Vector2d probe(320, 240);
  const PredictedDot corrected = c.Apply({0, probe, 0.01 * Eigen::Matrix2d::Identity()});
  EXPECT_LT((corrected.uv_px - (truth_map * probe.homogeneous()).hnormalized()).norm(), 0.3);
}

TEST(PredictedMatch, VotesFindAnOffsetWithoutAnchors) {
  const std::vector<Eigen::Vector2d> truth = Scene(50, 17);
  std::vector<Eigen::Vector2d> detections;
  for (size_t k = 0; k < 45; ++k) detections.push_back(truth[k] + Eigen::Vector2d(9.0, 5.5));  // 5 not detected
  detections.push_back({600, 30});  // a spurious blob
  const PredictionCorrection c = VotePredictionCorrection(Predictions(truth, 0.5), detections, PredictionCorrectionOptions());
  ASSERT_TRUE(c.ok) << c.message;
  EXPECT_TRUE(c.from_votes);
  EXPECT_LT((MapPoint(c.observed_from_predicted, truth[0]) - detections[0]).norm(), 0.1);
}

TEST(PredictedMatch, VotesRefuseARegularGridWhoseShiftsAllFit) {
  std::vector<Eigen::Vector2d> grid;
  for (int i = 0; i < 8; ++i) {
    for (int j = 0; j < 6; ++j) grid.push_back({100.0 + 20 * i, 100.0 + 20 * j});
  }
  std::vector<Eigen::Vector2d> detections;
  for (const auto& g : grid) detections.push_back(g + Eigen::Vector2d(3, 0));
  const PredictionCorrection c = VotePredictionCorrection(Predictions(grid, 0.5), detections, PredictionCorrectionOptions());
  EXPECT_FALSE(c.ok) << c.message;  // a shift by one spacing fits 7 of 8 columns: no identity is safe
}

}  // namespace
}  // namespace selfcal::tracking
