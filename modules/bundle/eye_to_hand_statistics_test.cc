// Seeded noise on the synthetic eye-to-hand cell (test/support/eye_to_hand_world.h) at 0.3 px: the
// bundle's errors against its Cramer-Rao bound, and the coverage of the reported +-2 sigma, for the PUMA
// 560, the UR5e and the Panda.
#include <cmath>
#include <iostream>

#include <gtest/gtest.h>

#include "bundle/bundle_adjustment.h"
#include "support/eye_to_hand_world.h"
#include "support/test_robots.h"

namespace selfcal::bundle {
namespace {

using selfcal::testing::EyeToHandOptions;
using selfcal::testing::EyeToHandWorld;
using selfcal::testing::MakeEyeToHandWorld;

constexpr double kNoisePx = 0.3;
constexpr int kRuns = 20;

BundleTruth TruthOf(const EyeToHandWorld& world) {
  BundleTruth truth;
  truth.rho = world.rho_true;
  truth.camera = world.camera_true;
  for (size_t d = 0; d < world.dots_in_flange.size(); ++d) truth.dots_in_base[static_cast<int>(d)] = world.dots_in_flange[d];
  return truth;
}

std::vector<RobotModel> Robots() { return {selfcal::testing::Puma560(), selfcal::testing::Ur5e(), selfcal::testing::Panda()}; }

// One world per robot, kRuns noise draws: the RMS error of each free parameter and f_x against the bound.
TEST(EyeToHandBundleStatistics, ErrorsMatchTheCramerRaoBound) {
  for (const RobotModel& robot : Robots()) {
    EyeToHandOptions options;
    options.noise_px = kNoisePx;
    const EyeToHandWorld world = MakeEyeToHandWorld(robot, options);
    const CramerRaoReport bound = BundleCramerRao(world.observations, TruthOf(world), kNoisePx, BundleOptions());
    ASSERT_TRUE(bound.ok) << bound.message;
    ASSERT_EQ(bound.free_indices, world.perturbed_indices);
    const int nf = static_cast<int>(bound.free_indices.size());
    std::vector<double> sum_sq(nf + 1, 0.0);
    for (int run = 0; run < kRuns; ++run) {
      const ObservationSet obs = selfcal::testing::ReobserveEyeToHand(world, kNoisePx, 700 + run);
      const BundleReport r = RunBundleAdjustment(obs, KinematicParameters::Nominal(obs.robot), obs.camera.fx_px, {});
      ASSERT_EQ(r.outcome, Outcome::kConverged) << r.message;
      ASSERT_EQ(r.free_indices, bound.free_indices);
      for (int k = 0; k < nf; ++k) sum_sq[k] += std::pow(r.rho[r.free_indices[k]] - world.rho_true[r.free_indices[k]], 2);
      sum_sq[nf] += std::pow(r.fx_px - world.camera_true.fx_px, 2);
    }
    double sum_ratio = 0, max_ratio = 0, min_ratio = 1e9;
    for (int k = 0; k <= nf; ++k) {
      const double crb = k < nf ? bound.stddev[bound.free_indices[k]] : bound.fx_stddev;
      const double ratio = std::sqrt(sum_sq[k] / kRuns) / crb;
      sum_ratio += ratio;
      max_ratio = std::max(max_ratio, ratio);
      min_ratio = std::min(min_ratio, ratio);
      // 20 runs: an RMS scatters by ~16 %; 2x either way is beyond four of those.
      EXPECT_GT(ratio, 0.5) << robot.name << " column " << k;
      EXPECT_LT(ratio, 1.6) << robot.name << " column " << k;
    }
    const double mean_ratio = sum_ratio / (nf + 1);
    std::cout << "[ figure ] " << robot.name << " eye-to-hand, " << kNoisePx << " px, " << kRuns
              << " draws: RMS error / Cramer-Rao bound over " << nf + 1 << " parameters: mean " << mean_ratio
              << ", min " << min_ratio << ", max " << max_ratio << "\n";
    // The mean of nf + 1 such ratios scatters by ~16 % / sqrt(nf + 1) (less independent in fact): 15 %.
    EXPECT_NEAR(mean_ratio, 1.0, 0.15) << robot.name;
  }
}

// kRuns worlds per robot (hidden errors, f_x, plate, poses, noise): the fraction of free parameters and
// f_x within +-2 reported sigma.
TEST(EyeToHandBundleStatistics, SigmasCoverTheErrors) {
  int all_intervals = 0, all_covered = 0;
  for (const RobotModel& robot : Robots()) {
    int intervals = 0, covered = 0;
    for (int run = 0; run < kRuns; ++run) {
      EyeToHandOptions options;
      options.noise_px = kNoisePx;
      options.seed = 100 + run;
      options.noise_seed = 200 + run;
      const EyeToHandWorld world = MakeEyeToHandWorld(robot, options);
      const ObservationSet& obs = world.observations;
      const BundleReport r = RunBundleAdjustment(obs, KinematicParameters::Nominal(obs.robot), obs.camera.fx_px, {});
      ASSERT_EQ(r.outcome, Outcome::kConverged) << r.message;
      ASSERT_TRUE(r.covariance_available) << r.covariance_message;
      ASSERT_EQ(r.free_indices, world.perturbed_indices) << robot.name << " world " << options.seed;
      const int nf = static_cast<int>(r.free_indices.size());
      for (int k = 0; k <= nf; ++k) {
        const double error = k < nf ? r.rho[r.free_indices[k]] - world.rho_true[r.free_indices[k]]
                                    : r.fx_px - world.camera_true.fx_px;
        const double sigma = k < nf ? r.stddev[r.free_indices[k]] : r.fx_stddev;
        ++intervals;
        covered += std::abs(error) <= 2 * sigma ? 1 : 0;
      }
    }
    const double coverage = static_cast<double>(covered) / intervals;
    std::cout << "[ figure ] " << robot.name << " eye-to-hand, " << kNoisePx << " px, " << kRuns
              << " worlds: coverage of +-2 sigma " << coverage << " (" << intervals << " intervals)\n";
    EXPECT_GE(coverage, 0.88) << robot.name;
    EXPECT_LE(coverage, 0.99) << robot.name;
    all_intervals += intervals;
    all_covered += covered;
  }
  const double coverage = static_cast<double>(all_covered) / all_intervals;
  std::cout << "[ figure ] eye-to-hand, three robots: coverage of +-2 sigma " << coverage << "\n";
  // 0.954 expected; the binomial spread of ~1500 intervals is 0.5 %, correlated parameters widen it.
  EXPECT_GE(coverage, 0.91);
  EXPECT_LE(coverage, 0.98);
}

}  // namespace
}  // namespace selfcal::bundle
