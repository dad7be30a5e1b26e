// A flange-pose set with noisy recorded flange poses: the pose-noise solve is the result, and its held-out test
// (verification poses, or cross-validation folds) models the flange pose noise. Against the simulator's hidden
// truth: the simulated PUMA arc recorded as flange poses of the true arm, each pose then moved by a random
// flange pose error of known size.
#include "calibration/pose_noise_result.h"

#include <cmath>
#include <cstdint>
#include <random>

#include <gtest/gtest.h>

#include "calibration/calibrate.h"
#include "support/eye_to_hand_world.h"
#include "support/sim_worlds.h"
#include "support/test_robots.h"

namespace selfcal::calibration {
namespace {

constexpr double kPixelNoisePx = 0.2;
constexpr double kTranslationSigmaM = 1e-3;   // 1 mm per axis
constexpr double kRotationSigmaRad = 8.7e-4;  // 0.05 deg per axis

struct NoisyFlangeWorld {
  ObservationSet observations;
  Rigid3 flange_from_cam_true;
  double fx_true = 0;
  std::map<int, Eigen::Vector3d> dots_true;  // by dot id
};

// The arc's poses recorded as flange poses, each moved by base_from_flange * Exp(delta), delta ~ N(0, diag(s_t, s_r))
// (seeded), the noise stated in the set.
NoisyFlangeWorld MakeNoisyFlangeWorld(std::uint64_t seed) {
  const sim::SimResult world = testing::PumaArcWorld(kPixelNoisePx, 3, seed);
  NoisyFlangeWorld out;
  out.observations = testing::AsFlangePoseSet(world);
  out.fx_true = world.truth.camera_true.fx_px;
  out.flange_from_cam_true = out.observations.poses[0].base_from_flange->Inverse() * world.truth.base_from_cam[0];
  for (size_t k = 0; k < world.truth.dots_in_base.size(); ++k) out.dots_true[static_cast<int>(k)] = world.truth.dots_in_base[k];
  std::mt19937_64 rng(1000 + seed);
  std::normal_distribution<double> gauss(0.0, 1.0);
  for (PoseObservation& pose : out.observations.poses) {
    const double v[6] = {kTranslationSigmaM * gauss(rng), kTranslationSigmaM * gauss(rng), kTranslationSigmaM * gauss(rng),
                         kRotationSigmaRad * gauss(rng),  kRotationSigmaRad * gauss(rng),  kRotationSigmaRad * gauss(rng)};
    *pose.base_from_flange = *pose.base_from_flange * RigidFromTranslationRotvec(v);
  }
  out.observations.flange_translation_sigma_m = kTranslationSigmaM;
  out.observations.flange_rotation_sigma_rad = kRotationSigmaRad;
  return out;
}

bundle::PoseNoiseOptions StatedNoise() {
  bundle::PoseNoiseOptions noise;
  noise.translation_sigma_m = kTranslationSigmaM;
  noise.rotation_sigma_rad = kRotationSigmaRad;
  return noise;
}

// Seeds 1..num_seeds, each solved from the truth (the pose-noise solve alone) and its 10 verification poses
// predicted from their recorded (noisy) flange poses: the mean of chi-square / dof and how many pass.
void HeldOutStatistics(int num_seeds, double* mean_ratio, int* passed) {
  double sum_ratio = 0;
  *passed = 0;
  for (int seed = 1; seed <= num_seeds; ++seed) {
    const NoisyFlangeWorld w = MakeNoisyFlangeWorld(seed);
    ObservationSet obs = w.observations;
    obs.camera.fx_px = w.fx_true;
    const bundle::PoseNoiseReport solve = bundle::RunPoseNoiseBundle(obs, w.flange_from_cam_true, w.dots_true, StatedNoise());
    ASSERT_TRUE(solve.ok) << seed << ": " << solve.message;
    ASSERT_EQ(solve.covariance.rows(), 7) << seed;  // the camera correction and f_x
    const HeldOutReprojection h = PoseNoiseHeldOut(obs, solve, StatedNoise());
    ASSERT_TRUE(h.ok) << seed << ": " << h.message;
    EXPECT_TRUE(h.prediction_uncertainty) << seed;
    sum_ratio += h.overall.chi_square / h.overall.dof;
    *passed += h.overall.test_passed ? 1 : 0;
  }
  *mean_ratio = sum_ratio / num_seeds;
  std::printf("pose-noise held-out test over %d seeds: mean chi-square / dof %.3f, passed %d\n", num_seeds, *mean_ratio,
              *passed);
}

// With the right noise the held-out chi-square follows its distribution: chi-square / dof averages 1 and the 95 %
// test passes about 95 % of the time. 8 seeds here (at least 6 pass: P(fewer) = 0.6 % for a correct 95 % test;
// the mean within 0.15 of 1); the 40-seed run below measured a mean of 1.005 and 39 of 40 passed (about 40 s:
// --gtest_also_run_disabled_tests --gtest_filter='PoseNoiseResult.DISABLED_*'; at least 34 of 40, P(fewer) = 0.3 %).
void ExpectHeldOutStatistics(int num_seeds, double mean_tolerance, int min_passed) {
  double mean_ratio = 0;
  int passed = 0;
  HeldOutStatistics(num_seeds, &mean_ratio, &passed);
  EXPECT_NEAR(mean_ratio, 1.0, mean_tolerance);
  EXPECT_GE(passed, min_passed);
}

TEST(PoseNoiseResult, HeldOutChiSquareMatchesItsDistributionWithTheRightNoise) { ExpectHeldOutStatistics(8, 0.15, 6); }

TEST(PoseNoiseResult, DISABLED_HeldOutChiSquareOverFortySeeds) { ExpectHeldOutStatistics(40, 0.1, 34); }

// The whole calibration with a stated flange pose noise and the arc's verification poses: the verdict's held-out
// test is the pose-noise model's (accepted, not untested), and the report's f_x, hand-eye transform and dots are
// that solve's, within its sigmas of the truth.
TEST(PoseNoiseResult, AStatedNoiseGivesATestedVerdictFromTheSolveWritten) {
  const NoisyFlangeWorld w = MakeNoisyFlangeWorld(7);
  const CalibrationReport report = Calibrate(w.observations, CalibrateOptions());
  ASSERT_TRUE(report.PoseNoiseIsTheResult()) << report.message;
  ASSERT_EQ(report.verdict, Verdict::kAccepted) << report.message;
  ASSERT_TRUE(report.pose_noise_heldout.has_value());
  EXPECT_TRUE(report.acceptance.HeldOutTested());
  const bundle::PoseNoiseReport& n = *report.pose_noise;
  ASSERT_TRUE(report.model.has_value());
  EXPECT_EQ(report.model->camera.fx_px, n.intrinsics[kFx]);
  EXPECT_EQ(report.model->robot.flange_from_cam.translation, n.flange_from_cam.translation);
  EXPECT_NEAR(n.intrinsics[kFx], w.fx_true, 4 * n.intrinsics_stddev[kFx]);
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(n.flange_from_cam.translation[k], w.flange_from_cam_true.translation[k], 4 * n.stddev[k]) << k;
  }
  // The plots' dots and residuals are the pose-noise solve's: its residuals at the corrected flange poses have
  // its RMS.
  EXPECT_EQ(report.pose_noise_fit_geometry.identification_residuals.size(), static_cast<size_t>(n.num_observations));
  double sum2 = 0;
  for (const ObservedResidual& r : report.pose_noise_fit_geometry.identification_residuals) sum2 += r.residual_px.squaredNorm();
  EXPECT_NEAR(std::sqrt(sum2 / n.num_observations), n.rms_reprojection_px, 1e-6 * n.rms_reprojection_px);
  EXPECT_EQ(report.model->parameters.size(), KinematicParameters::Nominal(w.observations.robot).size());
}

// f_x held 2 % wrong: the pose-noise solve absorbs what it can into the flange corrections, and the held-out
// test refuses the model.
TEST(PoseNoiseResult, AFocalLengthHeldTwoPercentWrongIsRefused) {
  NoisyFlangeWorld w = MakeNoisyFlangeWorld(7);
  w.observations.camera.fx_px = 1.02 * w.fx_true;
  CalibrateOptions options;
  options.bundle.bundle.held_parameters = {"fx"};
  const CalibrationReport report = Calibrate(w.observations, options);
  ASSERT_TRUE(report.PoseNoiseIsTheResult()) << report.message;
  EXPECT_EQ(report.pose_noise->intrinsics[kFx], w.observations.camera.fx_px);
  EXPECT_EQ(report.verdict, Verdict::kRejected) << report.message;
}

// No verification pose: the cross-validation's folds each run the pose-noise solve on the other poses and predict
// theirs with the flange pose noise; the pooled test passes and accepts the model.
TEST(PoseNoiseResult, CrossValidationFoldsRefitThePoseNoiseSolve) {
  NoisyFlangeWorld w = MakeNoisyFlangeWorld(7);
  for (PoseObservation& pose : w.observations.poses) pose.role = PoseRole::kIdentification;
  const CalibrationReport report = Calibrate(w.observations, CalibrateOptions());
  ASSERT_TRUE(report.PoseNoiseIsTheResult()) << report.message;
  ASSERT_TRUE(report.cross_validation.has_value() && report.cross_validation->ran) << report.message;
  const CrossValidationReport& cv = *report.cross_validation;
  EXPECT_EQ(cv.folds_tested, 4);
  EXPECT_NE(cv.message.find("pose-noise"), std::string::npos) << cv.message;
  EXPECT_TRUE(cv.pooled.test_passed) << cv.pooled.chi_square << " > " << cv.pooled.chi_square_limit;
  EXPECT_GT(cv.mm_per_px, 0);
  EXPECT_EQ(report.verdict, Verdict::kAccepted) << report.message;
  // The verdict's sentence names the pose error the folds carried: the flange pose noise, not the camera's.
  bool named = false;
  for (const AcceptanceCheck& c : report.acceptance.checks) {
    named = named || (c.name == "cross_validation_test" && c.sentence.find("and the flange pose noise of ") != std::string::npos);
  }
  EXPECT_TRUE(named) << cv.pose_error;
}

// Eye-to-hand (the camera fixed, the dots on the flange: the flange pose noise reaches the camera through
// points_from_cam = (base_from_flange Exp(delta))^-1 base_from_cam): the same statistics over 12 seeds of a UR5e
// cell, 25 identification and 10 verification flange poses, 0.3 px, 1 mm / 0.05 deg of flange pose noise,
// solved from the truth (measured: mean chi-square / dof 1.003, 12 of 12 pass; at least 9: P(fewer) = 0.2 %).
TEST(PoseNoiseResult, EyeToHandHeldOutChiSquareMatchesItsDistribution) {
  double sum_ratio = 0;
  int passed = 0;
  constexpr int kSeeds = 12;
  for (int seed = 1; seed <= kSeeds; ++seed) {
    testing::EyeToHandOptions options;
    options.noise_px = 0.3;
    options.flange_poses = true;
    options.num_verification = 10;
    options.seed = seed;
    const testing::EyeToHandWorld world = testing::MakeEyeToHandWorld(testing::Ur5e(), options);
    ObservationSet obs = world.observations;
    obs.camera = world.camera_true;
    std::mt19937_64 rng(2000 + seed);
    std::normal_distribution<double> gauss(0.0, 1.0);
    for (PoseObservation& pose : obs.poses) {
      const double v[6] = {kTranslationSigmaM * gauss(rng), kTranslationSigmaM * gauss(rng), kTranslationSigmaM * gauss(rng),
                           kRotationSigmaRad * gauss(rng),  kRotationSigmaRad * gauss(rng),  kRotationSigmaRad * gauss(rng)};
      *pose.base_from_flange = *pose.base_from_flange * RigidFromTranslationRotvec(v);
    }
    std::map<int, Eigen::Vector3d> dots;
    for (size_t k = 0; k < world.dots_in_flange.size(); ++k) dots[static_cast<int>(k)] = world.dots_in_flange[k];
    const bundle::PoseNoiseReport solve = bundle::RunPoseNoiseBundle(obs, world.base_from_cam_true, dots, StatedNoise());
    ASSERT_TRUE(solve.ok) << seed << ": " << solve.message;
    const HeldOutReprojection h = PoseNoiseHeldOut(obs, solve, StatedNoise());
    ASSERT_TRUE(h.ok) << seed << ": " << h.message;
    sum_ratio += h.overall.chi_square / h.overall.dof;
    passed += h.overall.test_passed ? 1 : 0;
  }
  std::printf("eye-to-hand pose-noise held-out test over %d seeds: mean chi-square / dof %.3f, passed %d\n", kSeeds,
              sum_ratio / kSeeds, passed);
  EXPECT_NEAR(sum_ratio / kSeeds, 1.0, 0.15);
  EXPECT_GE(passed, 9);
}

// The flange pose noise not stated (estimated from the residuals): which solve is the result is decided by
// cross-validating both on the identification poses, and everything written comes from the one with the lower
// held-out RMS (model_choice.h). Without verification poses its cross-validation is the report's. (The arc's
// yardstick left out: a yardstick that scales the pose-noise solve keeps it the result.)
TEST(ModelChoice, AnEstimatedNoiseIsDecidedByCrossValidationAndTheWinnerIsWritten) {
  for (const std::uint64_t seed : {7u, 8u}) {
    NoisyFlangeWorld w = MakeNoisyFlangeWorld(seed);
    w.observations.yardsticks.clear();
    w.observations.flange_translation_sigma_m = 0;
    w.observations.flange_rotation_sigma_rad = 0;
    for (PoseObservation& pose : w.observations.poses) pose.role = PoseRole::kIdentification;
    const CalibrationReport report = Calibrate(w.observations, CalibrateOptions());
    ASSERT_TRUE(report.pose_noise.has_value() && report.pose_noise->ok)
        << seed << ": " << report.message << " / " << report.bundle->bundle.error_model.message << " "
        << report.bundle->bundle.error_model.pose_translation_m << " " << report.bundle->bundle.error_model.pose_rotation_rad;
    ASSERT_TRUE(report.model_choice.has_value() && report.model_choice->made) << seed;
    const ModelChoice& c = *report.model_choice;
    EXPECT_EQ(c.pose_noise_chosen, c.pose_noise_rms_px <= c.exact_pose_rms_px) << seed;
    EXPECT_EQ(report.PoseNoiseIsTheResult(), c.pose_noise_chosen) << seed;
    ASSERT_TRUE(report.cross_validation.has_value()) << seed;
    EXPECT_EQ(report.cross_validation->pooled.rms_px, std::min(c.pose_noise_rms_px, c.exact_pose_rms_px)) << seed;
    ASSERT_TRUE(report.model.has_value()) << seed << ": " << report.message;
    const Rigid3& written = report.model->robot.flange_from_cam;
    const Rigid3& winner = c.pose_noise_chosen ? report.pose_noise->flange_from_cam
                                               : report.bundle->calibrated_robot.flange_from_cam;
    EXPECT_EQ(written.translation, winner.translation) << seed;
    EXPECT_EQ(report.model->camera.fx_px, c.pose_noise_chosen ? report.pose_noise->intrinsics[kFx]
                                                              : report.bundle->calibrated_camera.fx_px)
        << seed;
    EXPECT_EQ(report.pose_noise_fit_geometry.camera_poses.empty(), !c.pose_noise_chosen) << seed;
    std::printf("seed %d: exact-pose %.3f px, pose-noise %.3f px cross-validated\n", static_cast<int>(seed),
                c.exact_pose_rms_px, c.pose_noise_rms_px);
  }
}

// With verification poses the choice still cross-validates the identification poses only: the verification
// images stay the verdict's test, and the pose-noise solve's held-out figure exists exactly when it is the result.
TEST(ModelChoice, VerificationPosesStayTheTestTheChoiceNeverSaw) {
  NoisyFlangeWorld w = MakeNoisyFlangeWorld(7);
  w.observations.yardsticks.clear();
  w.observations.flange_translation_sigma_m = 0;
  w.observations.flange_rotation_sigma_rad = 0;
  ASSERT_FALSE(w.observations.PosesWithRole(PoseRole::kVerification).empty());
  const CalibrationReport report = Calibrate(w.observations, CalibrateOptions());
  ASSERT_TRUE(report.model_choice.has_value() && report.model_choice->made) << report.message;
  EXPECT_FALSE(report.cross_validation.has_value());
  EXPECT_EQ(report.pose_noise_heldout.has_value(), report.model_choice->pose_noise_chosen);
  EXPECT_TRUE(report.acceptance.HeldOutTested()) << report.message;
}

// A stated noise is the user's model, and a yardstick that scales the pose-noise solve is a model the
// exact-pose solve lacks: no choice, the pose-noise solve is the result.
TEST(ModelChoice, AStatedNoiseOrAYardstickScaleIsNotSecondGuessed) {
  const NoisyFlangeWorld stated = MakeNoisyFlangeWorld(7);
  const CalibrationReport report = Calibrate(stated.observations, CalibrateOptions());
  EXPECT_FALSE(report.model_choice.has_value());
  EXPECT_TRUE(report.PoseNoiseIsTheResult()) << report.message;
  NoisyFlangeWorld scaled = MakeNoisyFlangeWorld(7);
  ASSERT_FALSE(scaled.observations.yardsticks.empty());
  scaled.observations.flange_translation_sigma_m = 0;
  scaled.observations.flange_rotation_sigma_rad = 0;
  const CalibrationReport by_yardstick = Calibrate(scaled.observations, CalibrateOptions());
  ASSERT_TRUE(by_yardstick.pose_noise.has_value() && by_yardstick.pose_noise->ok) << by_yardstick.message;
  EXPECT_GT(by_yardstick.flange_scale_yardsticks, 0);
  EXPECT_FALSE(by_yardstick.model_choice.has_value());
  EXPECT_TRUE(by_yardstick.PoseNoiseIsTheResult());
}

}  // namespace
}  // namespace selfcal::calibration
