#include "calibration/bundle_stage.h"

#include <algorithm>
#include <cmath>
#include <iostream>
#include <vector>

#include <gtest/gtest.h>

#include "sim/sim_world.h"
#include "sim/trajectory_generator.h"
#include "support/sim_worlds.h"
#include "support/test_robots.h"

namespace selfcal::calibration {
namespace {

constexpr double kExact = 1e-9;

sim::SimResult World(double noise_px, uint64_t seed, bool flat_sheet = false) {
  return testing::PumaArcWorld(noise_px, seed, seed, flat_sheet);
}

// Largest error of the predicted cam_ref_from_cam_v over the verification poses (gauge-free).
PoseDifference MaxVerificationPoseError(const sim::SimResult& world, const ObservationSet& obs, const RobotModel& robot,
                                        const Eigen::VectorXd& rho) {
  const int ref = obs.PosesWithRole(PoseRole::kIdentification).front();
  const Rigid3 model_ref_from_base = BaseFromCam(robot, rho, obs.poses[ref].joints_rad).Inverse();
  const Rigid3 true_ref_from_base = world.truth.base_from_cam[ref].Inverse();
  PoseDifference worst;
  for (int v : obs.PosesWithRole(PoseRole::kVerification)) {
    const PoseDifference d = ComparePoses(model_ref_from_base * BaseFromCam(robot, rho, obs.poses[v].joints_rad),
                                          true_ref_from_base * world.truth.base_from_cam[v]);
    worst.position_m = std::max(worst.position_m, d.position_m);
    worst.rotation_rad = std::max(worst.rotation_rad, d.rotation_rad);
  }
  return worst;
}

// Noise-free, started from the paper pipeline: the held-out distances come out exact, and since the start
// puts the paper's gauge back to nominal, so does every free parameter against the simulator's truth.
TEST(BundleStage, NoiseFreeFromThePaperPipelineIsExact) {
  const sim::SimResult world = World(0.0, 1);
  const ObservationSet& obs = world.observations;
  const PaperPipelineReport paper = RunPaperPipeline(obs, PaperPipelineOptions());
  ASSERT_EQ(paper.outcome, Outcome::kSuccess) << paper.message;
  const BundleStageReport r = RunBundleStage(obs, paper, BundleStageOptions());
  ASSERT_EQ(r.bundle.outcome, bundle::Outcome::kConverged) << r.bundle.message;
  EXPECT_EQ(r.start, BundleStart::kPaperPipeline) << r.start_note;
  ASSERT_EQ(r.verification.num_ok, static_cast<int>(obs.check_distances.size()));
  EXPECT_LT(r.verification.max_error_m * 1e3, 1e-6);  // mm
  EXPECT_GT(r.verification_nominal.rms_error_m, 1e-4);  // the nominal model is visibly wrong
  for (int i : r.bundle.free_indices) {
    EXPECT_NEAR(r.bundle.rho[i], world.truth.rho_true[i], kExact) << KinematicParameters(6).name(i);
  }
  EXPECT_EQ(r.bundle.free_indices, world.truth.perturbed_indices);
  EXPECT_NEAR(r.bundle.fx_px, world.truth.camera_true.fx_px, kExact * world.truth.camera_true.fx_px);
  // The model to write predicts the same camera poses as the bundle's rho on the nominal model.
  for (int p : {0, 7, 20}) {
    EXPECT_TRUE(testing::RigidNear(BaseFromCam(obs.robot, r.bundle.rho, obs.poses[p].joints_rad),
                                   BaseFromCam(r.calibrated_robot, r.calibrated_rho, obs.poses[p].joints_rad), 1e-12, 1e-12));
  }
  std::cout << "[ figure ] noise 0: held-out 3-D error paper " << paper.verification_calibrated.max_error_m * 1e3
            << " mm (eq. (21) bias), bundle " << r.verification.max_error_m * 1e3 << " mm (max)\n";
}

// A flat dot sheet: the factor method has no unique solution, the paper pipeline refuses (kDegenerate);
// the bundle adjustment from the nominal model recovers everything the images determine.
TEST(BundleStage, FlatSheetNoiseFreeIsExactWhereThePaperPipelineIsDegenerate) {
  const sim::SimResult world = World(0.0, 2, /*flat_sheet=*/true);
  const ObservationSet& obs = world.observations;
  const PaperPipelineReport paper = RunPaperPipeline(obs, PaperPipelineOptions());
  EXPECT_EQ(paper.outcome, Outcome::kDegenerate) << paper.message;
  const BundleStageReport r = RunBundleStage(obs, paper, BundleStageOptions());
  ASSERT_EQ(r.bundle.outcome, bundle::Outcome::kConverged) << r.bundle.message;
  EXPECT_EQ(r.start, BundleStart::kNominal);
  EXPECT_EQ(r.fx_start_px, obs.camera.fx_px);
  const PoseDifference worst = MaxVerificationPoseError(world, obs, obs.robot, r.bundle.rho);
  EXPECT_LT(worst.position_m, kExact);
  EXPECT_LT(worst.rotation_rad, kExact);
  EXPECT_NEAR(r.bundle.fx_px, world.truth.camera_true.fx_px, kExact * world.truth.camera_true.fx_px);
  EXPECT_LT(r.verification.max_error_m, kExact);
  // The dots in the reference camera frame: gauge-free.
  const int ref = obs.PosesWithRole(PoseRole::kIdentification).front();
  const Rigid3 model_ref_from_base = BaseFromCam(obs.robot, r.bundle.rho, obs.poses[ref].joints_rad).Inverse();
  const Rigid3 true_ref_from_base = world.truth.base_from_cam[ref].Inverse();
  for (const auto& [id, p] : r.bundle.dots_in_base) {
    EXPECT_LT((model_ref_from_base * p - true_ref_from_base * world.truth.dots_in_base[id]).norm(), kExact) << id;
  }
  std::cout << "[ figure ] flat sheet, noise 0: paper pipeline " << OutcomeName(paper.outcome) << "; bundle "
            << bundle::OutcomeName(r.bundle.outcome) << ", max verification pose error " << worst.position_m
            << " m, 3-D error " << r.verification.max_error_m << " m\n";
}

// 0.2 px: the bundle's held-out 3-D error against the paper pipeline's on the same data. Medians over
// five worlds, so that one unlucky draw cannot decide.
TEST(BundleStage, HeldOutErrorBelowThePaperPipelinesAtAFifthOfAPixel) {
  std::vector<double> paper_rms, bundle_rms, paper_pose, bundle_pose;
  for (uint64_t seed = 11; seed < 16; ++seed) {
    const sim::SimResult world = World(0.2, seed);
    const ObservationSet& obs = world.observations;
    const PaperPipelineReport paper = RunPaperPipeline(obs, PaperPipelineOptions());
    ASSERT_EQ(paper.outcome, Outcome::kSuccess) << paper.message;
    const BundleStageReport r = RunBundleStage(obs, paper, BundleStageOptions());
    ASSERT_EQ(r.bundle.outcome, bundle::Outcome::kConverged) << r.bundle.message;
    paper_rms.push_back(paper.verification_calibrated.rms_error_m);
    bundle_rms.push_back(r.verification.rms_error_m);
    paper_pose.push_back(MaxVerificationPoseError(world, obs, paper.calibrated_robot, paper.calibrated_rho).position_m);
    bundle_pose.push_back(MaxVerificationPoseError(world, obs, obs.robot, r.bundle.rho).position_m);
  }
  auto median = [](std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
  };
  std::cout << "[ figure ] noise 0.2 px, 5 worlds, medians: held-out 3-D RMS error paper " << median(paper_rms) * 1e3
            << " mm, bundle " << median(bundle_rms) * 1e3 << " mm; worst verification pose error paper "
            << median(paper_pose) * 1e3 << " mm, bundle " << median(bundle_pose) * 1e3 << " mm\n";
  EXPECT_LT(median(bundle_rms), median(paper_rms));
  EXPECT_LT(median(bundle_pose), 0.5 * median(paper_pose));
}

// A parameter held by request keeps the robot description's value, not the paper pipeline's estimate of
// it (`--fix j3`, `--fix kinematics`: the user trusts the nominal values).
TEST(BundleStage, HeldParametersStayAtTheirNominalValuesNotThePaperPipelines) {
  const sim::SimResult world = World(0.2, 3);
  const ObservationSet& obs = world.observations;
  const PaperPipelineReport paper = RunPaperPipeline(obs, PaperPipelineOptions());
  ASSERT_EQ(paper.outcome, Outcome::kSuccess) << paper.message;
  BundleStageOptions options;
  options.bundle.held_parameters = {"j3"};
  const BundleStageReport r = RunBundleStage(obs, paper, options);
  ASSERT_EQ(r.bundle.outcome, bundle::Outcome::kConverged) << r.bundle.message;
  ASSERT_EQ(r.start, BundleStart::kPaperPipeline) << r.start_note;
  const KinematicParameters names(6);
  const Eigen::VectorXd nominal = KinematicParameters::Nominal(obs.robot);
  const Eigen::VectorXd from_paper = bundle::ExpressOnModel(obs.robot, paper.calibrated_robot, paper.calibrated_rho);
  int moved_by_paper = 0;
  for (int i = 0; i < names.size(); ++i) {
    if (names.name(i).rfind("j3.", 0) != 0) continue;
    EXPECT_EQ(r.bundle.rho[i], nominal[i]) << names.name(i);
    moved_by_paper += from_paper[i] != nominal[i] ? 1 : 0;
  }
  EXPECT_GT(moved_by_paper, 0) << "the paper pipeline estimated none of j3's parameters: the test shows nothing";
  EXPECT_NE(r.start_note.find("held parameters at nominal"), std::string::npos) << r.start_note;
}

TEST(BundleStage, FailedPaperPipelineStartsFromTheNominalModelWithThePrior) {
  const sim::SimResult world = World(0.2, 1);
  PaperPipelineReport failed;
  failed.outcome = Outcome::kDegenerate;
  failed.fx_px = 1234;
  double fx = 0;
  BundleStart start = BundleStart::kNotRun;
  const Eigen::VectorXd rho = BundleStartFromPaper(world.observations, failed, &fx, &start);
  EXPECT_EQ(start, BundleStart::kNominal);
  EXPECT_EQ(fx, world.observations.camera.fx_px);
  EXPECT_EQ(rho, KinematicParameters::Nominal(world.observations.robot));
}

}  // namespace
}  // namespace selfcal::calibration
