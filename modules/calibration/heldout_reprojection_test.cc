#include "calibration/heldout_reprojection.h"

#include <cmath>
#include <iostream>
#include <vector>

#include <gtest/gtest.h>

#include "calibration/bundle_stage.h"
#include "calibration/paper_pipeline.h"
#include "sim/sim_world.h"
#include "support/sim_worlds.h"

namespace selfcal::calibration {
namespace {

// Tabulated 99 % quantiles of chi-square (e.g. Abramowitz & Stegun table 26.8; R qchisq(0.99, k)).
TEST(HeldOutReprojection, ChiSquareQuantileMatchesTheTable) {
  EXPECT_NEAR(ChiSquareQuantile(0.99, 10), 23.209, 23.209 * 2e-3);
  EXPECT_NEAR(ChiSquareQuantile(0.99, 100), 135.807, 135.807 * 1e-3);
  EXPECT_NEAR(ChiSquareQuantile(0.99, 1000), 1106.969, 1106.969 * 1e-3);
  EXPECT_NEAR(ChiSquareUpperTail(ChiSquareQuantile(0.99, 160), 160), 0.01, 1e-9);
  EXPECT_NEAR(ChiSquareUpperTail(100.0, 100), 0.4812, 2e-3);  // R: pchisq(100, 100, lower = FALSE)
}

// F quantiles (R qf; checked by numerical integration of the F density): the statistic with an estimated
// noise is dof F(dof, noise_dof).
TEST(HeldOutReprojection, FQuantileMatchesTheTable) {
  EXPECT_NEAR(ChiSquareQuantile(0.99, 100, 100) / 100, 1.5977, 1.5977 * 2e-3);
  EXPECT_NEAR(ChiSquareQuantile(0.99, 10, 20) / 10, 3.3682, 3.3682 * 5e-3);
  EXPECT_NEAR(ChiSquareQuantile(0.99, 1600, 2100), 1783.99, 1783.99 * 5e-4);
  EXPECT_NEAR(ChiSquareUpperTail(1.1 * 1600, 1600, 2100), 0.02084, 5e-4);
  EXPECT_NEAR(ChiSquareQuantile(0.99, 1000, 1 << 30), ChiSquareQuantile(0.99, 1000), 1e-3);
}

struct CalibratedCell {
  sim::SimResult world;
  BundleStageReport stage;
};

// Every pose i with i % 5 in {1, 3} becomes a verification pose (10 of the arc's 25, between identification
// poses) instead of the arc's last 10 (beyond them).
void Interleave(ObservationSet* obs) {
  for (size_t i = 0; i < obs->poses.size(); ++i) {
    obs->poses[i].role = (i % 5 == 1 || i % 5 == 3) ? PoseRole::kVerification : PoseRole::kIdentification;
  }
}

CalibratedCell Calibrated(const sim::SimOptions& sim_options, const BundleStageOptions& options, bool interleave,
                          bool from_paper = true, double prior_fx_factor = 0, bool drop_k1 = false) {
  CalibratedCell run{testing::PumaArcWorld(sim_options), {}};
  ObservationSet& obs = run.world.observations;
  if (interleave) Interleave(&obs);
  if (prior_fx_factor > 0) obs.camera.fx_px = run.world.truth.camera_true.fx_px * prior_fx_factor;
  if (drop_k1) obs.camera.k1 = 0;
  const PaperPipelineReport paper = from_paper ? RunPaperPipeline(obs, PaperPipelineOptions()) : PaperPipelineReport();
  run.stage = RunBundleStage(obs, paper, options);
  return run;
}

sim::SimOptions Cell(double noise_px, uint64_t seed) {
  sim::SimOptions options;
  options.pixel_noise_px = noise_px;
  options.world_seed = seed;
  options.noise_seed = seed;
  return options;
}

// (a) The correct model class, on the arc with its last 10 poses held out (beyond the identification
// poses: the prediction's own error, ~1 px, dominates) and with 10 poses between identification poses held
// out (the held-out RMS per coordinate is then the simulated noise: its relative std over ~1600 coordinates
// is ~2 %, the prediction adds a few %). The statistic is within 4 of its standard deviations of dof, both
// with the estimated noise (dof F: variance 2 dof (1 + dof / noise_dof)) and with the true one stated
// (chi-square: 2 dof); the bundle's noise estimate is the truth within 8 % (its relative std is ~1.5 %).
// The 99 % test passes in at least 9 of 10 worlds (fewer with probability ~4e-3 when it is right). The
// nominal model, whose errors are ~1 mm, does far worse on the same images and fails.
TEST(HeldOutReprojection, CorrectModelPassesAtTheSimulatedNoise) {
  const double noise = 0.3;
  int passed = 0;
  for (bool interleave : {true, false}) {
    for (uint64_t seed = 21; seed < 26; ++seed) {
      const CalibratedCell run = Calibrated(Cell(noise, seed), BundleStageOptions(), interleave);
      const BundleStageReport& s = run.stage;
      ASSERT_EQ(s.bundle.outcome, bundle::Outcome::kConverged) << s.bundle.message;
      ASSERT_TRUE(s.heldout.ok) << s.heldout.message;
      EXPECT_TRUE(s.heldout.prediction_uncertainty);
      const HeldOutFigure& f = s.heldout.overall;
      const HeldOutFigure& stated = s.heldout_at_stated_noise;
      std::cout << "[ figure ] interleaved " << interleave << ", seed " << seed << ": held-out RMS " << f.rms_px
                << " px (noise " << noise << ", estimate " << s.heldout.noise_px << " from " << f.noise_dof
                << " dof), statistic " << f.chi_square << " / dof " << f.dof << " (limit " << f.chi_square_limit
                << "); at the stated noise " << stated.chi_square << " (limit " << stated.chi_square_limit
                << "); nominal RMS " << s.heldout_nominal.overall.rms_px << " px\n";
      EXPECT_EQ(s.heldout.poses.size(), run.world.observations.PosesWithRole(PoseRole::kVerification).size());
      if (interleave) {
        EXPECT_NEAR(f.rms_px / noise, 1.0, 0.12);
      }
      EXPECT_GT(f.rms_px, noise * 0.9);
      EXPECT_NEAR(s.heldout.noise_px / noise, 1.0, 0.08);
      ASSERT_GT(f.noise_dof, 1000);
      EXPECT_NEAR(f.chi_square, f.dof, 4 * std::sqrt(2.0 * f.dof * (1.0 + double(f.dof) / f.noise_dof)));
      EXPECT_NEAR(stated.chi_square, stated.dof, 4 * std::sqrt(2.0 * stated.dof));
      EXPECT_GT(s.heldout_nominal.overall.rms_px, 5 * f.rms_px);
      EXPECT_FALSE(s.heldout_nominal.overall.test_passed);
      EXPECT_FALSE(s.heldout_nominal.prediction_uncertainty);
      passed += f.test_passed ? 1 : 0;
    }
  }
  // At the 95 % level, 7 or more of 10 pass with probability 0.999 (binomial).
  EXPECT_GE(passed, 7);
}

// (b) A wrong model: f_x held 2 % off the truth (fx held, prior 1.02 f_x, the bundle started from
// the nominal model so that the paper's f_x does not come in), the arc's last 10 poses held out. The
// held-out RMS is far above the noise (more than 8 times, 9.9-fold in the closest world since the pose
// error the wrong f_x leaves behind holds the weak joint parameters; the correct model's stays below 5 times in (a))
// and the test at the stated (true) noise fails in at least 2 of the 3 worlds. With the estimated noise the
// test is weaker (the identification residuals absorb part of the error), and the weak joint parameters the
// error leaves held carry their manufacturing tolerance (5 mm, 0.5 deg) into the test's covariance, so that
// part of it is explained: it fails in at least 1 (measured: statistics 1850, 1725 and 1568 against a limit of
// 1727). The score test of a held f_x (`--fix fx`) refuses it in every world
// (Calibrate.AWrongFocalLengthHeldFixedIsRejected).
TEST(HeldOutReprojection, FxHeldTwoPercentOffFails) {
  const double noise = 0.3;
  BundleStageOptions options;
  options.bundle.intrinsics[kFx] = false;
  int failed = 0, failed_at_stated = 0;
  for (uint64_t seed = 21; seed < 24; ++seed) {
    const CalibratedCell run = Calibrated(Cell(noise, seed), options, false, /*from_paper=*/false, 1.02);
    const BundleStageReport& s = run.stage;
    ASSERT_TRUE(s.heldout.ok) << s.heldout.message;
    const HeldOutFigure& f = s.heldout.overall;
    std::cout << "[ figure ] f_x 2 % off, seed " << seed << ": held-out RMS " << f.rms_px << " px, noise estimate "
              << s.heldout.noise_px << " px, statistic " << f.chi_square << " / dof " << f.dof << " (limit "
              << f.chi_square_limit << "); at the stated noise " << s.heldout_at_stated_noise.chi_square << "\n";
    EXPECT_GT(f.rms_px, 8 * noise);
    failed += f.test_passed ? 0 : 1;
    failed_at_stated += s.heldout_at_stated_noise.test_passed ? 0 : 1;
  }
  EXPECT_GE(failed, 1);
  EXPECT_GE(failed_at_stated, 2);
}

// (c) A lens the prior gets wrong (truth: principal point (328, 233) px, k2 = 0.4; prior: the image centre,
// k2 = 0), the arc's last 10 poses held out. With cx, cy and k2 freed, the predictions use the
// calibrated lens and the covariance of all four estimated intrinsics: the statistic at the stated (true)
// noise is within 4 of its standard deviations of dof, as for a correct model. With them held at the
// wrong prior the same test fails.
TEST(HeldOutReprojection, FreedLensIsPredictedWithItsUncertainty) {
  sim::SimOptions sim_options = Cell(0.3, 31);
  sim_options.camera.cx_px = 328.0;
  sim_options.camera.cy_px = 233.0;
  sim_options.camera.k2 = 0.4;
  sim::SimResult world = testing::PumaArcWorld(sim_options);
  ObservationSet& obs = world.observations;
  obs.camera.cx_px = 319.5;
  obs.camera.cy_px = 239.5;
  obs.camera.k2 = 0;
  BundleStageOptions options;
  options.bundle.intrinsics = {true, false, true, true, false, true, false, false, false};
  const BundleStageReport freed = RunBundleStage(obs, PaperPipelineReport(), options);
  ASSERT_EQ(freed.bundle.outcome, bundle::Outcome::kConverged) << freed.bundle.message;
  ASSERT_TRUE(freed.heldout.ok) << freed.heldout.message;
  EXPECT_TRUE(freed.heldout.prediction_uncertainty);
  EXPECT_EQ(freed.bundle.covariance_free.rows(), static_cast<int>(freed.bundle.free_indices.size()) + 4);
  EXPECT_EQ(freed.calibrated_camera.k2, freed.bundle.intrinsics[kK2]);
  const HeldOutFigure& stated = freed.heldout_at_stated_noise;
  EXPECT_NEAR(stated.chi_square, stated.dof, 4 * std::sqrt(2.0 * stated.dof));
  const BundleStageReport held = RunBundleStage(obs, PaperPipelineReport(), BundleStageOptions());
  ASSERT_TRUE(held.heldout.ok) << held.heldout.message;
  std::cout << "[ figure ] lens freed: held-out RMS " << freed.heldout.overall.rms_px << " px, statistic "
            << stated.chi_square << " / dof " << stated.dof << "; held at the prior: RMS " << held.heldout.overall.rms_px
            << " px, statistic " << held.heldout_at_stated_noise.chi_square << "\n";
  EXPECT_FALSE(held.heldout_at_stated_noise.test_passed);
  EXPECT_GT(held.heldout.overall.rms_px, freed.heldout.overall.rms_px);
}

}  // namespace
}  // namespace selfcal::calibration

namespace selfcal::calibration {
namespace {

// (d) One verification detection 20 px off (a misdetected corner) is left out of the test and named; the
// correct model then passes as without it. A wrong model (f_x held 2 % off, the arc's last 10 poses held
// out, as in (b)) moves every prediction: at most 5 % of the detections, its worst, are left out and it
// still fails.
TEST(HeldOutReprojection, AGrossDetectionErrorIsLeftOutAndNamedButAWrongModelIsNotExcused) {
  sim::SimResult world = testing::PumaArcWorld(Cell(0.3, 21));
  ObservationSet& obs = world.observations;
  Interleave(&obs);
  const int v = obs.PosesWithRole(PoseRole::kVerification).front();
  auto dot = obs.poses[v].dots_px.begin();
  dot->second += Eigen::Vector2d(12.0, -16.0);
  const BundleStageReport s = RunBundleStage(obs, RunPaperPipeline(obs, PaperPipelineOptions()), BundleStageOptions());
  ASSERT_TRUE(s.heldout.ok) << s.heldout.message;
  ASSERT_EQ(s.heldout.gross_errors.size(), 1u);
  EXPECT_EQ(s.heldout.gross_errors[0].pose_id, obs.poses[v].id);
  EXPECT_EQ(s.heldout.gross_errors[0].dot_id, dot->first);
  EXPECT_LT(s.heldout.overall.max_px, 5.0);
  EXPECT_TRUE(s.heldout_at_stated_noise.test_passed) << s.heldout_at_stated_noise.chi_square;

  BundleStageOptions fx_held;
  fx_held.bundle.intrinsics[kFx] = false;
  const CalibratedCell wrong = Calibrated(Cell(0.3, 21), fx_held, false, /*from_paper=*/false, 1.02);
  ASSERT_TRUE(wrong.stage.heldout.ok);
  const HeldOutReprojection& h = wrong.stage.heldout;
  EXPECT_LE(h.gross_errors.size(), kMaxGrossErrorShare * (h.overall.num_residuals + h.gross_errors.size()));
  EXPECT_FALSE(wrong.stage.heldout_at_stated_noise.test_passed);
}

// (d') The misdetected corner beside more detections just beyond the bound than the 5 % share (a real cell's
// unmodelled errors; kvasios s1's fold with a 6 px corner): the corner, the worst, is still left out, with
// no more than the share. All or nothing, nothing was, and the corner alone failed the test.
TEST(HeldOutReprojection, AMisdetectedCornerIsLeftOutBesideManyDetectionsJustBeyondTheBound) {
  sim::SimResult world = testing::PumaArcWorld(Cell(0.3, 21));
  ObservationSet& obs = world.observations;
  Interleave(&obs);
  const std::vector<int> verification = obs.PosesWithRole(PoseRole::kVerification);
  size_t detections = 0;
  for (int v : verification) detections += obs.poses[v].dots_px.size();
  const int share = static_cast<int>(std::floor(kMaxGrossErrorShare * detections));
  ASSERT_GE(share, 2);
  auto corner = obs.poses[verification.front()].dots_px.begin();
  corner->second += Eigen::Vector2d(12.0, -16.0);
  // 3 px (10 sigma at 0.3 px): beyond the bound, far below the corner; every 8th dot of the other poses,
  // in directions that no common motion of a pose explains.
  int moved = 0;
  for (size_t i = 1; i < verification.size(); ++i) {
    int k = 0;
    for (auto& [id, pixel] : obs.poses[verification[i]].dots_px) {
      if (k++ % 8 != 0 || moved > share) continue;
      pixel += Eigen::Vector2d(moved % 2 ? 3.0 : -3.0, moved % 3 ? 3.0 : -3.0);
      ++moved;
    }
  }
  ASSERT_GT(moved, share);
  const BundleStageReport s = RunBundleStage(obs, RunPaperPipeline(obs, PaperPipelineOptions()), BundleStageOptions());
  ASSERT_TRUE(s.heldout.ok) << s.heldout.message;
  EXPECT_LE(static_cast<int>(s.heldout.gross_errors.size()), share);
  bool named = false;
  for (const ObservedResidual& e : s.heldout.gross_errors) {
    named = named || (e.pose_id == obs.poses[verification.front()].id && e.dot_id == corner->first);
  }
  EXPECT_TRUE(named) << s.heldout.gross_errors.size() << " left out";
  EXPECT_LT(s.heldout.overall.max_px, 5.0);
}

// (e) A joint reading noise of 0.02 deg (the images taken at the true angles): with the error model
// estimated, each verification image's pose error is in the test and the correct model passes at the
// stated (true) pixel noise in at least 4 of 5 worlds; with pixel noise only the same test refuses it in
// most of them.
TEST(HeldOutReprojection, AJointReadingNoiseIsInTheTestWithTheEstimatedErrorModel) {
  int passed_model = 0, passed_pixel = 0;
  for (uint64_t seed = 21; seed < 26; ++seed) {
    sim::SimOptions cell = Cell(0.3, seed);
    cell.joint_noise_rad = 0.02 * M_PI / 180.0;
    BundleStageOptions pixel_only;
    pixel_only.bundle.estimate_pose_error = false;
    const CalibratedCell model = Calibrated(cell, BundleStageOptions(), true);
    const CalibratedCell pixel = Calibrated(cell, pixel_only, true);
    ASSERT_TRUE(model.stage.heldout.ok && pixel.stage.heldout.ok);
    std::cout << "[ figure ] 0.02 deg joint noise, seed " << seed << ": pose error "
              << model.stage.bundle.error_model.pose_translation_m * 1e3 << " mm / "
              << model.stage.bundle.error_model.pose_rotation_rad * 180 / M_PI << " deg; chi-square at the stated noise "
              << model.stage.heldout_at_stated_noise.chi_square << " with it, " << pixel.stage.heldout_at_stated_noise.chi_square
              << " without (limit " << model.stage.heldout_at_stated_noise.chi_square_limit << ")\n";
    passed_model += model.stage.heldout_at_stated_noise.test_passed;
    passed_pixel += pixel.stage.heldout_at_stated_noise.test_passed;
  }
  EXPECT_GE(passed_model, 4);
  EXPECT_LE(passed_pixel, 2);
}

// (f) The identification images' joint reading noise moves the yardstick's two dots, and through them the
// scale; the fit solved those dots together, and the test must carry that (heldout_dot_groups.h). At 0.04 deg
// (the images at the true angles) z = (chi-square - dof) / sqrt(2 dof) at the stated noise is 0 +- 1 per
// world with the right covariance: over 24 worlds its mean lies within 3 / sqrt(24) = 0.61 of 0 (fails with
// probability ~3e-3 when right; with each dot solved alone, as before, it is 1.03 in these worlds).
TEST(HeldOutReprojection, TheYardsticksDotsCarryTheScaleThePoseErrorsGaveThem) {
  double sum_z = 0;
  int worlds = 0;
  for (uint64_t seed = 31; seed < 55; ++seed) {
    sim::SimOptions cell = Cell(0.3, seed);
    cell.joint_noise_rad = 0.04 * M_PI / 180.0;
    const CalibratedCell run = Calibrated(cell, BundleStageOptions(), true);
    ASSERT_TRUE(run.stage.heldout.ok) << seed;
    const HeldOutFigure& f = run.stage.heldout_at_stated_noise;
    sum_z += (f.chi_square - f.dof) / std::sqrt(2.0 * f.dof);
    ++worlds;
  }
  std::cout << "[ figure ] 0.04 deg joint noise: mean z over " << worlds << " worlds " << sum_z / worlds << "\n";
  EXPECT_LT(std::abs(sum_z / worlds), 3.0 / std::sqrt(24.0));
}

}  // namespace
}  // namespace selfcal::calibration
