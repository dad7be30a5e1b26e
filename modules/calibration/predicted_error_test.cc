#include "calibration/predicted_error.h"

#include <cmath>
#include <iostream>
#include <vector>

#include <gtest/gtest.h>

#include "bundle/bundle_adjustment.h"
#include "calibration/paper_pipeline.h"
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

// The central differences do not depend on the step: a step 4 times larger gives the same gradients to
// 1e-4, far below the precision the prediction needs (truncation O(h^2); the triangulation's convergence
// error divided by h).
TEST(PredictedError, GradientIsStepConsistent) {
  const sim::SimResult world = World(0.2, 3);
  const ObservationSet& obs = world.observations;
  const bundle::BundleReport b = Solve(obs);
  ASSERT_EQ(b.outcome, bundle::Outcome::kConverged) << b.message;
  ASSERT_TRUE(b.covariance_available) << b.covariance_message;
  const std::vector<int> verification = obs.PosesWithRole(PoseRole::kVerification);
  const PredictedDistanceErrors p1 = PredictDistanceErrors(obs, verification, obs.robot, b.rho, b.fx_px, b.free_indices,
                                                           b.covariance_free, 0.2, obs.check_distances, 1.0);
  const PredictedDistanceErrors p4 = PredictDistanceErrors(obs, verification, obs.robot, b.rho, b.fx_px, b.free_indices,
                                                           b.covariance_free, 0.2, obs.check_distances, 4.0);
  ASSERT_TRUE(p1.ok) << p1.message;
  ASSERT_EQ(p1.num_ok, static_cast<int>(obs.check_distances.size()));
  ASSERT_EQ(p4.num_ok, p1.num_ok);
  for (size_t d = 0; d < p1.distances.size(); ++d) {
    const auto& a = p1.distances[d];
    const auto& c = p4.distances[d];
    EXPECT_LE((a.gradient_theta - c.gradient_theta).norm(), 1e-4 * a.gradient_theta.norm()) << d;
    EXPECT_LE((a.gradient_px - c.gradient_px).norm(), 1e-4 * a.gradient_px.norm()) << d;
    EXPECT_NEAR(a.std_m, c.std_m, 1e-4 * a.std_m);
    EXPECT_GT(a.parameters_std_m, 0);
    EXPECT_GT(a.pixels_std_m, 0);
  }
  // The distance at the point is the one VerifyDistances measures.
  const VerificationSummary v = VerifyDistances(obs, verification, obs.robot, b.rho, b.fx_px, obs.check_distances);
  for (size_t d = 0; d < p1.distances.size(); ++d) EXPECT_NEAR(p1.distances[d].measured_m, v.checks[d].measured_m, 1e-12);
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
