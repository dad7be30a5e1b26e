// The estimated error model (error_model.h) on the simulated PUMA arc, where the truth is known: without
// pose error it vanishes and changes nothing; with a joint reading noise it is found and its sigmas cover
// the hidden parameters where the pixel-only ones do not.
#include "bundle/error_model.h"

#include <cmath>
#include <iostream>

#include <gtest/gtest.h>

#include "bundle/bundle_adjustment.h"
#include "support/sim_worlds.h"

namespace selfcal::bundle {
namespace {

sim::SimResult NoisyWorld(double joint_noise_deg, uint64_t seed) {
  sim::SimOptions options;
  options.pixel_noise_px = 0.2;
  options.world_seed = options.noise_seed = seed;
  options.joint_noise_rad = joint_noise_deg * M_PI / 180.0;
  return selfcal::testing::PumaArcWorld(options);
}

BundleReport Solve(const sim::SimResult& world, bool estimate_pose_error) {
  const ObservationSet& obs = world.observations;
  BundleOptions options;
  options.estimate_pose_error = estimate_pose_error;
  return RunBundleAdjustment(obs, KinematicParameters::Nominal(obs.robot), obs.camera.fx_px, options);
}

// Free parameters within 2 reported sigma of the truth, and their count.
std::pair<int, int> Covered(const BundleReport& r, const sim::SimResult& world) {
  int inside = 0;
  for (int i : r.free_indices) inside += std::abs(r.rho[i] - world.truth.rho_true[i]) <= 2 * r.stddev[i];
  return {inside, static_cast<int>(r.free_indices.size())};
}

TEST(ErrorModel, IsNegligibleWithoutPoseErrorAndKeepsThePixelOnlyEstimate) {
  const sim::SimResult world = NoisyWorld(0.0, 1);
  const BundleReport model = Solve(world, true), pixel = Solve(world, false);
  ASSERT_EQ(model.outcome, Outcome::kConverged) << model.message;
  ASSERT_TRUE(model.error_model.estimated) << model.error_model.message;
  EXPECT_FALSE(pixel.error_model.estimated);
  // 0.1 mm / 0.01 deg would move a dot by ~0.2 px at this camera: the components are far below.
  // What noise leaves of a zero variance component (its estimate is kept positive): 8 um here, 0.016 px.
  EXPECT_LT(model.error_model.pose_translation_m, 2e-5);
  EXPECT_LT(model.error_model.pose_rotation_rad, 3e-5);
  EXPECT_NEAR(model.error_model.pixel_px, 0.2, 0.02);
  EXPECT_EQ(model.rho, pixel.rho);  // the estimate is the pixel-only one
  // The pixel variance alone is estimated: its relative variance is 2 / redundancy (chi-square).
  EXPECT_NEAR(model.error_model.relative_covariance(0, 0) * model.error_model.pixel_redundancy / 2, 1.0, 0.05);
  EXPECT_EQ(model.error_model.relative_covariance(3, 3), 0.0);
  // The pixel variance over its redundancy is the pixel-only s^2 = 2 cost / dof; that remnant widens some
  // sigmas by up to 8 % (measured), never narrows one.
  for (int i : model.free_indices) {
    EXPECT_GE(model.stddev[i] / pixel.stddev[i], 0.995) << i;
    EXPECT_LE(model.stddev[i] / pixel.stddev[i], 1.10) << i;
  }
}

TEST(ErrorModel, FindsAJointReadingNoiseAndItsSigmasCoverTheTruth) {
  int model_inside = 0, pixel_inside = 0, total = 0;
  double standardized_sq = 0;  // the joint variance's error over its stated precision, squared, summed
  for (uint64_t seed = 1; seed <= 8; ++seed) {
    const sim::SimResult world = NoisyWorld(0.01, seed);
    const BundleReport model = Solve(world, true), pixel = Solve(world, false);
    ASSERT_EQ(model.outcome, Outcome::kConverged) << seed << ": " << model.message;
    ASSERT_TRUE(model.error_model.estimated) << model.error_model.message;
    // The joint component takes most of it (0.01 deg at the joints moves the camera by ~0.1 mm and ~0.015 deg,
    // lever ~0.6 m, but by each configuration's own lever arms). The isotropic components can take a share:
    // over 8 worlds the joint estimate was 0.0048-0.0117 deg (redundancy 15-38) and the isotropic ones up to
    // 0.065 mm / 0.009 deg, each smaller than the whole joint noise's camera motion.
    std::cout << "[ figure ] seed " << seed << ": joint readings " << model.error_model.joint_rad * 180 / M_PI
              << " deg (redundancy " << model.error_model.joint_redundancy << "), camera "
              << model.error_model.pose_translation_m * 1e3 << " mm / " << model.error_model.pose_rotation_rad * 180 / M_PI
              << " deg\n";
    EXPECT_GT(model.error_model.joint_rad * 180 / M_PI, 0.004) << seed;
    EXPECT_LT(model.error_model.joint_rad * 180 / M_PI, 0.016) << seed;
    EXPECT_LT(model.error_model.pose_translation_m, 1e-4) << seed;
    EXPECT_LT(model.error_model.pose_rotation_rad * 180 / M_PI, 0.015) << seed;
    const double ratio = std::pow(model.error_model.joint_rad / (0.01 * M_PI / 180.0), 2);
    const double sd = std::sqrt(model.error_model.relative_covariance(3, 3));
    std::cout << "[ figure ] seed " << seed << ": joint variance / truth " << ratio << " +- " << sd
              << " (its redundancy alone says +- " << std::sqrt(2 / model.error_model.joint_redundancy) << ")\n";
    standardized_sq += std::pow((ratio - 1) / sd, 2);
    model_inside += Covered(model, world).first;
    pixel_inside += Covered(pixel, world).first;
    total += Covered(model, world).second;
  }
  std::cout << "[ figure ] 0.01 deg joint noise, 8 worlds: within 2 sigma of the truth " << model_inside << "/" << total
            << " with the error model, " << pixel_inside << "/" << total << " with pixel noise only\n";
  // 95.4 % expected; 192 pairs give a binomial sd of 1.5 %, the parameters of one world are correlated:
  // 88 % is over 3 sd below. The pixel-only sigmas miss far more.
  EXPECT_GE(model_inside, 0.88 * total);
  // The joint variance's stated precision: the sum of 8 squared standardised errors is ~chi-square(8) when
  // it is right (99 % within 1.3-20); over 100 simulated worlds from the command line the standardised errors'
  // standard deviation was 1.04, where the redundancy alone understates the scatter by 1.4x.
  EXPECT_GT(standardized_sq, 1.3);
  EXPECT_LT(standardized_sq, 20.1);
  EXPECT_LT(pixel_inside, model_inside - 0.1 * total);
}

// The score test of a held parameter: j3.alpha held at its hidden true value passes in most worlds (95 % of
// them on average: at least 7 of 10 with probability 0.999); held 0.5 deg off it fails in every world without
// joint reading noise, though the pose error it leaves behind is estimated as noise. With a 0.01 deg joint
// noise the error is partly hidden by the real pose error (measured: 3 of 5 fail).
TEST(ErrorModel, AHeldValueIsTestedAgainstTheImages) {
  int passed_true = 0, failed_wrong[2] = {0, 0};
  for (uint64_t seed = 1; seed <= 10; ++seed) {
    const sim::SimResult world = NoisyWorld(seed % 2 == 0 ? 0.01 : 0.0, seed);
    const ObservationSet& obs = world.observations;
    const int index = KinematicParameters(obs.robot.num_joints()).IndexOf("j3.alpha");
    BundleOptions options;
    options.held_parameters = {"j3.alpha"};
    for (const double offset : {0.0, 0.5 * M_PI / 180.0}) {
      Eigen::VectorXd start = KinematicParameters::Nominal(obs.robot);
      start[index] = world.truth.rho_true[index] + offset;
      const BundleReport r = RunBundleAdjustment(obs, start, obs.camera.fx_px, options);
      ASSERT_EQ(r.outcome, Outcome::kConverged) << r.message;
      ASSERT_TRUE(r.held_values.tested);
      ASSERT_EQ(r.held_values.names, std::vector<std::string>{"j3.alpha"});
      EXPECT_TRUE(r.held_values.decisive);
      const bool within = r.held_values.chi_square <= 3.841;  // chi-square(1) at 95 %
      std::cout << "[ figure ] seed " << seed << ", j3.alpha held " << (offset > 0 ? "0.5 deg off" : "at the truth")
                << ": score chi-square " << r.held_values.chi_square << "\n";
      if (offset > 0) {
        failed_wrong[seed % 2] += !within;
      } else {
        passed_true += within;
      }
    }
  }
  EXPECT_GE(passed_true, 7);
  EXPECT_EQ(failed_wrong[1], 5);  // odd seeds: no joint noise
  EXPECT_GE(failed_wrong[0], 2);
}

}  // namespace
}  // namespace selfcal::bundle
