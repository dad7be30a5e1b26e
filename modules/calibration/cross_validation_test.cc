#include "calibration/cross_validation.h"

#include <cmath>
#include <set>

#include <gtest/gtest.h>

#include "calibration/calibrate.h"
#include "support/sim_worlds.h"

namespace selfcal::calibration {
namespace {

// A simulated PUMA arc with 0.2 px noise and every pose an identification pose: the k-fold held-out figure is
// the pixel noise plus the prediction's own small uncertainty, so its RMS lies near 0.2 px, and a correct
// model passes the held-out test in most folds (each at 95 %).
TEST(CrossValidation, ACorrectModelPredictsHeldOutFoldsAtThePixelNoise) {
  sim::SimResult world = testing::PumaArcWorld(0.2, 3, 3);
  ObservationSet obs = world.observations;
  for (PoseObservation& pose : obs.poses) pose.role = PoseRole::kIdentification;
  const CalibrationReport report = Calibrate(obs, CalibrateOptions());
  ASSERT_TRUE(report.bundle.has_value());
  ASSERT_TRUE(report.cross_validation.has_value()) << report.message;
  const CrossValidationReport& cv = *report.cross_validation;
  ASSERT_TRUE(cv.ran) << cv.message;
  ASSERT_EQ(cv.per_fold.size(), 4u);
  // Every pose held out exactly once.
  std::set<std::string> held;
  size_t count = 0;
  for (const CrossValidationFold& f : cv.per_fold) {
    EXPECT_EQ(f.outcome, bundle::Outcome::kConverged) << f.message;
    held.insert(f.held_out.begin(), f.held_out.end());
    count += f.held_out.size();
  }
  EXPECT_EQ(count, obs.poses.size());
  EXPECT_EQ(held.size(), obs.poses.size());
  EXPECT_GT(cv.pooled.rms_px, 0.2 * 0.8);
  EXPECT_LT(cv.pooled.rms_px, 0.2 * 1.3);
  EXPECT_GE(cv.folds_passed, 3);
  EXPECT_GT(cv.mm_per_px, 0);
  EXPECT_NEAR(cv.rms_mm, cv.pooled.rms_px * cv.mm_per_px, 1e-12);
  // The verdict's test: the folds' chi-squares summed over their degrees of freedom, passed, and the model
  // accepted on it (no verification pose to test with).
  int dof = 0;
  double chi_square = 0;
  for (const CrossValidationFold& f : cv.per_fold) {
    dof += f.figure.dof;
    chi_square += f.figure.chi_square;
  }
  EXPECT_EQ(cv.folds_tested, 4);
  EXPECT_EQ(cv.pooled.dof, dof);
  EXPECT_NEAR(cv.pooled.chi_square, chi_square, 1e-9 * chi_square);
  EXPECT_TRUE(cv.pooled.test_passed) << cv.pooled.chi_square << " > " << cv.pooled.chi_square_limit;
  EXPECT_EQ(report.verdict, Verdict::kAccepted) << report.message;
  EXPECT_TRUE(report.acceptance.HeldOutTested());

  // The same seed, the same folds; a set with verification poses is not cross-validated.
  const CrossValidationReport again = CrossValidate(obs, *report.bundle, BundleStageOptions(), 4, 1);
  ASSERT_EQ(again.per_fold.size(), 4u);
  EXPECT_EQ(again.per_fold[0].held_out, cv.per_fold[0].held_out);
  const CrossValidationReport verified = CrossValidate(world.observations, *report.bundle, BundleStageOptions(), 4, 1);
  EXPECT_FALSE(verified.ran);
}

// The same arc with every kinematic parameter held at the nominal description (the simulator's robot differs
// from it by millimetres and tenths of a degree): no verification pose, so the cross-validation's test is the
// one that refuses the model.
TEST(CrossValidation, AModelHeldAtAWrongDescriptionIsRefusedByTheFoldsItCannotPredict) {
  sim::SimResult world = testing::PumaArcWorld(0.2, 3, 3);
  ObservationSet obs = world.observations;
  for (PoseObservation& pose : obs.poses) pose.role = PoseRole::kIdentification;
  CalibrateOptions options;
  options.bundle.bundle.held_parameters = {"kinematics"};
  const CalibrationReport report = Calibrate(obs, options);
  ASSERT_TRUE(report.cross_validation.has_value()) << report.message;
  ASSERT_TRUE(report.cross_validation->ran) << report.cross_validation->message;
  EXPECT_FALSE(report.cross_validation->pooled.test_passed) << report.cross_validation->pooled.chi_square;
  EXPECT_EQ(report.verdict, Verdict::kRejected) << report.message;
  EXPECT_NE(report.message.find("does not predict poses it was not fitted to"), std::string::npos) << report.message;
  EXPECT_FALSE(report.model.has_value());
}

// Without verification poses and without cross-validation nothing held images out: the model is written
// and its verdict says it is untested.
TEST(CrossValidation, WithoutAnyHeldOutTestTheModelIsUntested) {
  sim::SimResult world = testing::PumaArcWorld(0.2, 3, 3);
  ObservationSet obs = world.observations;
  for (PoseObservation& pose : obs.poses) pose.role = PoseRole::kIdentification;
  CalibrateOptions options;
  options.cross_validation_folds = 0;
  const CalibrationReport report = Calibrate(obs, options);
  EXPECT_EQ(report.verdict, Verdict::kUntested) << report.message;
  EXPECT_STREQ(VerdictName(report.verdict), "untested");
  EXPECT_FALSE(report.accepted());
  EXPECT_TRUE(report.model.has_value());
  EXPECT_FALSE(report.acceptance.HeldOutTested());
  EXPECT_NE(report.message.find("the set names no verification pose"), std::string::npos) << report.message;
  EXPECT_NE(report.message.find("folds = 0"), std::string::npos) << report.message;
}

TEST(CrossValidation, TooFewPosesForTheFoldsIsNotRunWithTheReason) {
  sim::SimResult world = testing::PumaArcWorld(0.2, 3, 3);
  ObservationSet obs = world.observations;
  for (PoseObservation& pose : obs.poses) pose.role = PoseRole::kIdentification;
  const CrossValidationReport cv = CrossValidate(obs, BundleStageReport(), BundleStageOptions(), 1000, 1);
  EXPECT_FALSE(cv.ran);
  EXPECT_NE(cv.message.find("too few for 1000 folds"), std::string::npos) << cv.message;
}

}  // namespace
}  // namespace selfcal::calibration
