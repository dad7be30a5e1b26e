// PredictDots (dot_prediction.h) on a synthetic cell with a known truth: a PUMA 560 looking at 60 dots
// 0.4-0.8 m away from five nearby poses. With the true model the predictions' errors follow their
// covariances; with hidden kinematic errors the raw predictions are off by pixels, and the correction on
// anchors (tracking/predicted_match.h) brings them back so that gated naming names the other dots right.
#include "acquisition/dot_prediction.h"

#include <random>

#include <Eigen/Eigenvalues>
#include <gtest/gtest.h>

#include "acquisition/prediction_test_cell.h"

namespace selfcal::acquisition {
namespace {

TEST(DotPrediction, ErrorsFollowTheCovarianceWithTheTrueModel) {
  const Cell c = MakeCell(0, 0, 4);
  std::mt19937_64 rng(9);
  std::vector<ViewedSample> samples;
  for (int k = 0; k < 4; ++k) samples.push_back({c.joints[k], Observe(c, c.joints[k], &rng), {}, {}});
  PredictionModel truth = c.nominal;
  truth.robot = ApplyParameters(c.nominal.robot, c.rho_true);
  const std::map<int, Eigen::Vector2d> next = Observe(c, c.joints[5], &rng);
  DotPredictionOptions exact;
  exact.ray_model_sigma_px = 0;  // the true model: the rays err by the pixel noise alone
  const DotPredictionReport r = PredictDots(truth, samples, c.joints[5], {}, exact);
  EXPECT_EQ(r.triangulated, 60);
  double sum_m2 = 0;
  int n = 0;
  for (const tracking::PredictedDot& p : r.dots) {
    if (!next.count(p.id)) continue;
    sum_m2 += tracking::Mahalanobis2(p, next.at(p.id));
    ++n;
  }
  ASSERT_GE(n, 40);
  // E[m2] = 2 for a consistent covariance; the mean over n dots has std 2 / sqrt(n).
  EXPECT_NEAR(sum_m2 / n, 2.0, 5 * 2.0 / std::sqrt(n));
}

TEST(DotPrediction, ASingleRayDotIsPredictedAlongItsEpipolarLine) {
  const Cell c = MakeCell(0, 0, 6);
  std::mt19937_64 rng(3);
  std::vector<ViewedSample> samples;
  for (int k = 0; k < 3; ++k) samples.push_back({c.joints[k], Observe(c, c.joints[k], &rng), {}, {}});
  const std::map<int, Eigen::Vector2d> next = Observe(c, c.joints[5], &rng);
  int lost = -1;  // a dot seen everywhere, then lost after the first sample
  for (const auto& [id, px] : samples[0].dots_px) {
    if (lost < 0 && samples[1].dots_px.count(id) && samples[2].dots_px.count(id) && next.count(id)) lost = id;
  }
  ASSERT_GE(lost, 0);
  PredictionModel truth = c.nominal;
  truth.robot = ApplyParameters(c.nominal.robot, c.rho_true);
  const DotPredictionReport before = PredictDots(truth, samples, c.joints[5], {}, DotPredictionOptions());
  for (int k = 1; k < 3; ++k) samples[k].dots_px.erase(lost);
  const DotPredictionReport r = PredictDots(truth, samples, c.joints[5], {}, DotPredictionOptions());
  EXPECT_EQ(r.single_ray, before.single_ray + 1);
  const auto it = std::find_if(r.dots.begin(), r.dots.end(), [&](const auto& p) { return p.id == lost; });
  ASSERT_NE(it, r.dots.end());
  const Eigen::Vector2d seen = next.at(lost);
  EXPECT_LT(tracking::Mahalanobis2(*it, seen), 13.8);
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(it->cov_px2);
  EXPECT_GT(eig.eigenvalues()(1), 10 * eig.eigenvalues()(0));  // long along the epipolar line
}

TEST(DotPrediction, CorrectedOnAnchorsANominalModelNamesTheOtherDotsRight) {
  const Cell c = MakeCell(1e-3, 0.2 * 3.14159265358979 / 180, 8);  // the simulator's hidden error levels
  std::mt19937_64 rng(5);
  std::vector<ViewedSample> samples;
  for (int k = 0; k < 4; ++k) samples.push_back({c.joints[k], Observe(c, c.joints[k], &rng), {}, {}});
  const std::map<int, Eigen::Vector2d> next = Observe(c, c.joints[5], &rng);
  const DotPredictionReport r = PredictDots(c.nominal, samples, c.joints[5], {}, DotPredictionOptions());
  double raw_worst = 0;
  std::vector<Eigen::Vector2d> pred, obs, detections;
  std::vector<int> truth_id;
  std::vector<tracking::PredictedDot> others;
  for (const tracking::PredictedDot& p : r.dots) {
    if (!next.count(p.id)) continue;
    raw_worst = std::max(raw_worst, (p.uv_px - next.at(p.id)).norm());
    if (p.id % 3 == 0) {  // a third of the dots are anchors (tracked into the frame)
      pred.push_back(p.uv_px);
      obs.push_back(next.at(p.id));
    } else {
      others.push_back(p);
      detections.push_back(next.at(p.id));
      truth_id.push_back(p.id);
    }
  }
  std::printf("raw nominal predictions off by up to %.2f px\n", raw_worst);
  EXPECT_GT(raw_worst, 0.5);  // the hidden errors show (pixel noise 0.2 px)
  const tracking::PredictionCorrection fix = tracking::FitPredictionCorrection(pred, obs, tracking::PredictionCorrectionOptions());
  ASSERT_TRUE(fix.ok) << fix.message;
  for (tracking::PredictedDot& p : others) p = fix.Apply(p);
  const tracking::PredictedMatch m = tracking::MatchPredictions(others, detections, tracking::PredictedMatchOptions());
  int named = 0;
  for (size_t k = 0; k < detections.size(); ++k) {
    if (m.id_of_detection[k] < 0) continue;
    EXPECT_EQ(m.id_of_detection[k], truth_id[k]);
    ++named;
  }
  EXPECT_GE(named, static_cast<int>(detections.size()) * 95 / 100) << fix.message;
}

// A scene of scattered dots: a dot's image neighbours say nothing of its depth, so every dot seen once
// must lie inside its segment gate wherever it is in the scene's depth range (0.4-0.8 m here), the ends
// of the segment included.
TEST(DotPrediction, EveryDotSeenOnceLiesInItsSegmentGate) {
  const Cell c = MakeCell(0, 0, 11);
  std::mt19937_64 rng(12);
  PredictionModel truth = c.nominal;
  truth.robot = ApplyParameters(c.nominal.robot, c.rho_true);
  const std::vector<ViewedSample> samples = {{c.joints[0], Observe(c, c.joints[0], &rng), {}, {}}};
  const std::map<int, Eigen::Vector2d> next = Observe(c, c.joints[5], &rng);
  std::map<int, Eigen::Vector2d> tracked;  // half the dots carried into the new frame give the depths
  for (const auto& [id, px] : next) {
    if (id % 2 == 0) tracked[id] = px;
  }
  const DotPredictionReport r = PredictDots(truth, samples, c.joints[5], tracked, DotPredictionOptions());
  int checked = 0;
  for (const tracking::PredictedDot& p : r.dots) {
    if (tracked.count(p.id) || !next.count(p.id)) continue;
    EXPECT_LE(tracking::Mahalanobis2(p, next.at(p.id)), 13.8) << "dot " << p.id;
    ++checked;
  }
  EXPECT_GE(checked, 20);
  EXPECT_EQ(r.anchor_px.size(), tracked.size());
}

// A candidate (a detection alone in a dot's long gate) gives the dot a second ray: right, a short gate
// that holds the dot; wrong (another dot's pixel), a gate that the dot is not in.
TEST(DotPrediction, ACandidateGivesASecondRayThatConfirmsOrForgets) {
  const Cell c = MakeCell(0, 0, 6);
  std::mt19937_64 rng(3);
  PredictionModel truth = c.nominal;
  truth.robot = ApplyParameters(c.nominal.robot, c.rho_true);
  std::vector<ViewedSample> samples;
  for (int k = 0; k < 3; ++k) samples.push_back({c.joints[2 * k], Observe(c, c.joints[2 * k], &rng), {}, {}});
  const std::map<int, Eigen::Vector2d> next = Observe(c, c.joints[5], &rng);
  std::vector<int> everywhere;  // dots seen in the first and last sample and in the new frame
  for (const auto& [id, px] : samples[0].dots_px) {
    if (samples[2].dots_px.count(id) && next.count(id)) everywhere.push_back(id);
  }
  ASSERT_FALSE(everywhere.empty());
  const int lost = everywhere.front();
  // The wrong candidate lies on the dot's epipolar line, as every candidate does: the point of its first
  // ray 30 % farther away, seen from the last sample.
  const Rigid3 base_from_first = BaseFromCam(truth.robot, KinematicParameters::Nominal(truth.robot), c.joints[0]);
  const Eigen::Vector3d in_first = base_from_first.Inverse() * c.dots_in_base[static_cast<size_t>(lost)];
  const Rigid3 last_from_base = BaseFromCam(truth.robot, KinematicParameters::Nominal(truth.robot), c.joints[4]).Inverse();
  const std::optional<Eigen::Vector2d> farther = Project(truth.camera, last_from_base * (base_from_first * (1.3 * in_first)));
  ASSERT_TRUE(farther.has_value());
  const Eigen::Vector2d right = samples[2].dots_px.at(lost), wrong = *farther;
  for (int k = 1; k < 3; ++k) samples[k].dots_px.erase(lost);
  auto predicted = [&](const Eigen::Vector2d& candidate) {
    samples[2].candidates_px = {{lost, candidate}};
    DotPredictionOptions exact;
    exact.ray_model_sigma_px = 0;  // the true model
    const DotPredictionReport r = PredictDots(truth, samples, c.joints[5], {}, exact);
    // The point's gate names; the segment of its one sample ray stays beside it and only competes.
    const auto it = std::find_if(r.dots.begin(), r.dots.end(), [&](const auto& p) { return p.id == lost && p.names; });
    EXPECT_EQ(std::count_if(r.dots.begin(), r.dots.end(), [&](const auto& p) { return p.id == lost && !p.names; }), 1);
    EXPECT_EQ(r.on_candidates, 1);
    EXPECT_NE(it, r.dots.end());
    return it == r.dots.end() ? tracking::PredictedDot() : *it;
  };
  const tracking::PredictedDot confirmed = predicted(right);
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(confirmed.cov_px2);
  EXPECT_LE(std::sqrt(eig.eigenvalues()(1)), DotPredictionOptions().max_gate_sigma_px);
  EXPECT_LE(tracking::Mahalanobis2(confirmed, next.at(lost)), 13.8);
  EXPECT_GT(tracking::Mahalanobis2(predicted(wrong), next.at(lost)), 13.8);
}

// Hidden kinematic errors put each sample's nominal camera off differently at every pose, so a point
// triangulated from distant poses is off in a way the new frame's correction cannot remove. Mapping each
// sample's pixels onto its nominal camera first brings the predictions of the dots no anchor carries
// back into their gates.
TEST(DotPrediction, ResectedSampleCamerasBringPointsFromDistantPosesIntoTheirGates) {
  Cell c = MakeCell(0.002, 0.004, 21);
  const double kSwing = 0.08;  // rad: farther and the scene leaves the view of this synthetic cell
  for (size_t k = 1; k < c.joints.size(); ++k) {
    for (int j = 0; j < 6; ++j) c.joints[k][j] = c.joints[0][j] + kSwing * std::sin(2.3 * static_cast<double>(k) + j);
  }
  std::mt19937_64 rng(5);
  std::vector<ViewedSample> samples;
  for (int k = 0; k < 5; ++k) samples.push_back({c.joints[k], Observe(c, c.joints[k], &rng), {}, {}});
  const std::map<int, Eigen::Vector2d> next = Observe(c, c.joints[5], &rng);
  // Anchors: the even dots, as if tracked into the new frame; the odd ones are predicted and checked.
  auto worst = [&](int rounds, double* rms_px) {
    DotPredictionOptions options;
    options.sample_correction_rounds = rounds;
    const DotPredictionReport r = PredictDots(c.nominal, samples, c.joints[5], {}, options);
    std::vector<Eigen::Vector2d> from, to;
    for (const tracking::PredictedDot& p : r.dots) {
      if (p.id % 2 == 0 && next.count(p.id)) {
        from.push_back(p.uv_px);
        to.push_back(next.at(p.id));
      }
    }
    const tracking::PredictionCorrection fit =
        tracking::FitPredictionCorrection(from, to, tracking::PredictionCorrectionOptions());
    EXPECT_TRUE(fit.ok) << fit.message;
    double worst_m2 = 0, sum2 = 0;
    int n = 0;
    for (const tracking::PredictedDot& p : r.dots) {
      if (p.id % 2 == 0 || !next.count(p.id)) continue;
      const tracking::PredictedDot g = fit.Apply(p);
      worst_m2 = std::max(worst_m2, tracking::Mahalanobis2(g, next.at(p.id)));
      sum2 += (g.uv_px - next.at(p.id)).squaredNorm();
      ++n;
    }
    EXPECT_GE(n, 15);
    *rms_px = std::sqrt(sum2 / std::max(n, 1));
    return worst_m2;
  };
  double raw_rms = 0, corrected_rms = 0;
  const double raw = worst(0, &raw_rms), corrected = worst(2, &corrected_rms);
  EXPECT_LT(corrected_rms, 0.8 * raw_rms) << "raw " << raw_rms << " px, corrected " << corrected_rms << " px";
  EXPECT_LE(corrected, 13.8) << "raw worst chi-square " << raw;
}

// The new frame's camera is resected on the dots known in it: with a few of them wrong it still lands
// where it lands with none wrong (the predictions of the other dots closer than the nominal camera's);
// with most of them wrong (a tracker that jumped onto other blobs) the pose is refused and the nominal
// camera stays, so that the robust correction downstream can find the wrong dots out.
TEST(DotPrediction, TheNewFrameIsResectedOnItsKnownDotsUnlessMostOfThemAreWrong) {
  const Cell c = MakeCell(1e-3, 0.2 * 3.14159265358979 / 180, 8);
  std::mt19937_64 rng(5);
  std::vector<ViewedSample> samples;
  for (int k = 0; k < 4; ++k) samples.push_back({c.joints[k], Observe(c, c.joints[k], &rng), {}, {}});
  const std::map<int, Eigen::Vector2d> next = Observe(c, c.joints[5], &rng);
  std::map<int, Eigen::Vector2d> known;  // two thirds of the dots, tracked into the frame
  for (const auto& [id, px] : next) {
    if (id % 3 != 0) known[id] = px;
  }
  auto rms_of_the_others = [&](const std::map<int, Eigen::Vector2d>& current, bool resect) {
    DotPredictionOptions options;
    options.resect_new_frame = resect;
    const DotPredictionReport r = PredictDots(c.nominal, samples, c.joints[5], current, options);
    double sum2 = 0;
    int n = 0;
    for (const tracking::PredictedDot& p : r.dots) {
      if (p.id % 3 != 0 || !next.count(p.id) || !p.names) continue;
      sum2 += (p.uv_px - next.at(p.id)).squaredNorm();
      ++n;
    }
    EXPECT_GE(n, 10);
    return std::sqrt(sum2 / std::max(n, 1));
  };
  const double nominal = rms_of_the_others(known, false);
  std::map<int, Eigen::Vector2d> few_wrong = known, most_wrong = known;
  int k = 0;
  for (auto& [id, px] : few_wrong) px += (k++ % 10 == 0) ? Eigen::Vector2d(25, -18) : Eigen::Vector2d::Zero();
  k = 0;
  for (auto& [id, px] : most_wrong) px += (k++ % 10 < 6) ? Eigen::Vector2d(25, -18) : Eigen::Vector2d::Zero();
  const double clean = rms_of_the_others(known, true);
  const double few = rms_of_the_others(few_wrong, true), most = rms_of_the_others(most_wrong, true);
  EXPECT_LT(clean, 0.8 * nominal) << "resected: " << clean << " px, nominal " << nominal << " px";
  EXPECT_LT(few, 1.05 * clean) << "resected on a tenth wrong: " << few << " px, on none " << clean << " px";
  EXPECT_NEAR(most, nominal, 1e-9) << "six tenths wrong: the nominal camera stays";
}

}  // namespace
}  // namespace selfcal::acquisition
