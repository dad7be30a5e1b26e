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
  EXPECT_GT(cv.rms_px, 0.2 * 0.8);
  EXPECT_LT(cv.rms_px, 0.2 * 1.3);
  EXPECT_GE(cv.folds_passed, 3);
  EXPECT_GT(cv.mm_per_px, 0);
  EXPECT_NEAR(cv.rms_mm, cv.rms_px * cv.mm_per_px, 1e-12);

  // The same seed, the same folds; a set with verification poses is not cross-validated.
  const CrossValidationReport again = CrossValidate(obs, *report.bundle, BundleStageOptions(), 4, 1);
  ASSERT_EQ(again.per_fold.size(), 4u);
  EXPECT_EQ(again.per_fold[0].held_out, cv.per_fold[0].held_out);
  const CrossValidationReport verified = CrossValidate(world.observations, *report.bundle, BundleStageOptions(), 4, 1);
  EXPECT_FALSE(verified.ran);
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
