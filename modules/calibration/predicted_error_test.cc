#include "calibration/predicted_error.h"

#include <cmath>
#include <iostream>
#include <vector>

#include <gtest/gtest.h>

#include "bundle/bundle_adjustment.h"
#include "calibration/paper_pipeline.h"
#include "identification/triangulation.h"
#include "sim/sim_world.h"
#include "sim/trajectory_generator.h"
#include "support/sim_worlds.h"
#include "support/test_robots.h"

namespace selfcal::calibration {
namespace {

sim::SimResult World(double noise_px, uint64_t seed) { return testing::PumaArcWorld(noise_px, seed, seed + 7); }

bundle::BundleReport Solve(const ObservationSet& obs) {
  return bundle::RunBundleAdjustment(obs, KinematicParameters::Nominal(obs.robot), obs.camera.fx_px, {});
}

// The distance between the triangulations of two dots from the verification views at a model, with the
// pixel `perturbed` (index into the views of dot a, then of dot b; coordinate c) moved by h: what the
// analytic gradients differentiate.
double TriangulatedDistance(const ObservationSet& obs, const std::vector<int>& poses, const Eigen::VectorXd& rho,
                            double fx, const KnownDistance& known, int perturbed, int c, double h) {
  Eigen::Vector3d ends[2];
  int row = 0;
  for (int end = 0; end < 2; ++end) {
    identification::PointTrack track;
    for (int p : poses) {
      auto it = obs.poses[p].dots_px.find(end == 0 ? known.dot_a : known.dot_b);
      if (it == obs.poses[p].dots_px.end()) continue;
      track.base_from_cam.push_back(BaseFromCamAt(obs.robot, rho, obs.poses[p]));
      track.pixels.push_back(it->second);
      if (row++ == perturbed) track.pixels.back()[c] += h;
    }
    const identification::TriangulationResult r = identification::TriangulatePoint(obs.camera, fx, track, 1.0);
    EXPECT_TRUE(r.ok) << r.message;
    ends[end] = r.point;
  }
  return (ends[0] - ends[1]).norm();
}

// The analytic gradients (implicit function theorem at the triangulated point, residual curvature
// included) against central differences of the full triangulation (Gauss-Newton to convergence, steps
// 1e-4 m / rad, 0.1 px for f_x, 0.05 px for the pixels), every 7th distance: measured agreement 1e-7 to
// 8e-7 relative on the gradients and below 6e-7 on the stds (the differences' truncation and the
// triangulation's convergence); leaving out the curvature terms gives 3e-3, a wrong sign or frame order 1.
TEST(PredictedError, AnalyticGradientsMatchDifferencesOfTheTriangulation) {
  const sim::SimResult world = World(0.2, 3);
  const ObservationSet& obs = world.observations;
  const bundle::BundleReport b = Solve(obs);
  ASSERT_EQ(b.outcome, bundle::Outcome::kConverged) << b.message;
  ASSERT_TRUE(b.covariance_available) << b.covariance_message;
  const std::vector<int> verification = obs.PosesWithRole(PoseRole::kVerification);
  const PredictedDistanceErrors p = PredictDistanceErrors(obs, verification, obs.robot, b.rho, b.fx_px, b.free_indices,
                                                          b.covariance_free, 0.2, obs.check_distances);
  ASSERT_TRUE(p.ok) << p.message;
  ASSERT_EQ(p.num_ok, static_cast<int>(obs.check_distances.size()));
  const int nf = static_cast<int>(b.free_indices.size());
  for (size_t d = 0; d < p.distances.size(); d += 7) {
    const PredictedDistanceError& e = p.distances[d];
    Eigen::VectorXd g_theta(nf + 1), g_px(e.gradient_px.size());
    for (int t = 0; t <= nf; ++t) {
      const double h = t == nf ? 0.1 : 1e-4;
      Eigen::VectorXd plus = b.rho, minus = b.rho;
      double fx_plus = b.fx_px, fx_minus = b.fx_px;
      if (t == nf) {
        fx_plus += h;
        fx_minus -= h;
      } else {
        plus[b.free_indices[t]] += h;
        minus[b.free_indices[t]] -= h;
      }
      g_theta[t] = (TriangulatedDistance(obs, verification, plus, fx_plus, e.known, -1, 0, 0) -
                    TriangulatedDistance(obs, verification, minus, fx_minus, e.known, -1, 0, 0)) / (2 * h);
    }
    for (int i = 0; i < g_px.size(); ++i) {
      g_px[i] = (TriangulatedDistance(obs, verification, b.rho, b.fx_px, e.known, i / 2, i % 2, 0.05) -
                 TriangulatedDistance(obs, verification, b.rho, b.fx_px, e.known, i / 2, i % 2, -0.05)) / 0.1;
    }
    EXPECT_NEAR(e.measured_m, TriangulatedDistance(obs, verification, b.rho, b.fx_px, e.known, -1, 0, 0), 1e-15);
    EXPECT_LE((e.gradient_theta - g_theta).norm(), 5e-6 * g_theta.norm()) << d;
    EXPECT_LE((e.gradient_px - g_px).norm(), 5e-6 * g_px.norm()) << d;
    const double std_a = std::sqrt(g_theta.dot(b.covariance_free.topLeftCorner(nf + 1, nf + 1) * g_theta));
    EXPECT_NEAR(e.parameters_std_m, std_a, 2e-6 * std_a) << d;
    EXPECT_NEAR(e.pixels_std_m, 0.2 * g_px.norm(), 2e-6 * 0.2 * g_px.norm()) << d;
    EXPECT_GT(e.parameters_std_m, 0);
    EXPECT_GT(e.pixels_std_m, 0);
  }
  // The distance at the point is the one VerifyDistances measures.
  const VerificationSummary v = VerifyDistances(obs, verification, obs.robot, b.rho, b.fx_px, obs.check_distances);
  for (size_t d = 0; d < p.distances.size(); ++d) EXPECT_EQ(p.distances[d].measured_m, v.checks[d].measured_m);
}

TEST(PredictedError, NoUncertaintyGivesZero) {
  const sim::SimResult world = World(0.0, 2);
  const ObservationSet& obs = world.observations;
  const std::vector<int> verification = obs.PosesWithRole(PoseRole::kVerification);
  std::vector<int> free;
  for (int i : world.truth.perturbed_indices) free.push_back(i);
  const Eigen::MatrixXd zero = Eigen::MatrixXd::Zero(free.size() + 1, free.size() + 1);
  const PredictedDistanceErrors p = PredictDistanceErrors(obs, verification, obs.robot, world.truth.rho_true,
                                                          world.truth.camera_true.fx_px, free, zero, 0.0, obs.check_distances);
  ASSERT_TRUE(p.ok) << p.message;
  EXPECT_EQ(p.num_ok, static_cast<int>(obs.check_distances.size()));
  EXPECT_EQ(p.rms_std_m, 0.0);
  for (const auto& e : p.distances) {
    EXPECT_EQ(e.std_m, 0.0);
    EXPECT_GT(e.gradient_theta.norm(), 0);  // the gradients themselves are not zero
  }
  // Bad input is refused, not crashed on.
  EXPECT_FALSE(PredictDistanceErrors(obs, verification, obs.robot, world.truth.rho_true, world.truth.camera_true.fx_px, free,
                                     Eigen::MatrixXd::Zero(2, 2), 0.0, obs.check_distances).ok);
}

// Monte Carlo: the actual RMS 3-D error of the bundle adjustment's check distances against the RMS of the
// predicted std (each run's own covariance, sigma_px = 0.2), 30 seeded worlds. Interval: the errors are
// pooled over runs x distances, but the distances of one run share one parameter error (part (a), ~85 %
// of the variance here), so the effective number of independent samples is of the order of the number
// of runs; with ~30 chi-square samples the relative sd of an RMS is ~1/sqrt(2 * 30) = 13 %, and
// [0.7, 1.4] is ~2.5 sd either way (deterministic seeds: the ratio is 1.07 here).
TEST(PredictedError, MonteCarloMatchesBundleAdjustment) {
  constexpr int kRuns = 30;
  double actual_sq = 0, predicted_sq = 0, predicted_a_sq = 0, predicted_b_sq = 0;
  int count = 0;
  for (int run = 0; run < kRuns; ++run) {
    const sim::SimResult world = World(0.2, 100 + run);
    const ObservationSet& obs = world.observations;
    const bundle::BundleReport b = Solve(obs);
    ASSERT_EQ(b.outcome, bundle::Outcome::kConverged) << b.message;
    ASSERT_TRUE(b.covariance_available) << b.covariance_message;
    const std::vector<int> verification = obs.PosesWithRole(PoseRole::kVerification);
    const VerificationSummary v = VerifyDistances(obs, verification, obs.robot, b.rho, b.fx_px, obs.check_distances);
    const PredictedDistanceErrors p = PredictDistanceErrors(obs, verification, obs.robot, b.rho, b.fx_px, b.free_indices,
                                                            b.covariance_free, obs.pixel_noise_px, obs.check_distances);
    ASSERT_TRUE(p.ok) << p.message;
    for (size_t d = 0; d < v.checks.size(); ++d) {
      if (!v.checks[d].ok || !p.distances[d].ok) continue;
      actual_sq += v.checks[d].error_m * v.checks[d].error_m;
      predicted_sq += p.distances[d].std_m * p.distances[d].std_m;
      predicted_a_sq += p.distances[d].parameters_std_m * p.distances[d].parameters_std_m;
      predicted_b_sq += p.distances[d].pixels_std_m * p.distances[d].pixels_std_m;
      ++count;
    }
  }
  ASSERT_GT(count, 0);
  const double actual = std::sqrt(actual_sq / count), predicted = std::sqrt(predicted_sq / count);
  std::cout << "3-D error over " << kRuns << " runs at 0.2 px: actual RMS " << actual * 1e3 << " mm, predicted "
            << predicted * 1e3 << " mm (parameters " << std::sqrt(predicted_a_sq / count) * 1e3 << ", pixels "
            << std::sqrt(predicted_b_sq / count) * 1e3 << "), ratio " << actual / predicted << "\n";
  EXPECT_GT(actual / predicted, 0.7);
  EXPECT_LT(actual / predicted, 1.4);
}

}  // namespace
}  // namespace selfcal::calibration
