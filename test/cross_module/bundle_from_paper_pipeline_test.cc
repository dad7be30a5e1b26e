// The bundle adjustment against the paper pipeline (a higher layer) on the same simulated data: started
// from its metric model, and beside it on a flat dot sheet.
#include <algorithm>
#include <cmath>
#include <iostream>
#include <map>

#include <gtest/gtest.h>

#include "bundle/bundle_adjustment.h"
#include "bundle/bundle_test_util.h"
#include "calibration/paper_pipeline.h"

namespace selfcal::bundle {
namespace {

using testing::FlatSheet;
using testing::VerificationPoseErrors;
using testing::World;

constexpr double kExact = 1e-9;

// The paper pipeline's metric model as the start: its fixed entries carry its yardstick scale, so the
// gauge differs from the truth's; gauge-invariant quantities must still be exact.
TEST(BundleAdjustment, NoiseFreeFromThePaperPipelineStart) {
  const sim::SimResult world = World(0.0);
  const ObservationSet& obs = world.observations;
  const calibration::PaperPipelineReport paper = calibration::RunPaperPipeline(obs, calibration::PaperPipelineOptions());
  ASSERT_EQ(paper.outcome, calibration::Outcome::kSuccess) << paper.message;
  const Eigen::VectorXd start = ExpressOnModel(obs.robot, paper.calibrated_robot, paper.calibrated_rho);
  const BundleReport r = RunBundleAdjustment(obs, start, paper.fx_px, {});
  ASSERT_EQ(r.outcome, Outcome::kConverged) << r.message;
  const testing::PoseErrors e = VerificationPoseErrors(world, obs, obs.robot, r.rho);
  EXPECT_LT(e.MaxPosition(), kExact);
  EXPECT_LT(e.MaxRotation(), kExact);
  EXPECT_NEAR(r.fx_px, world.truth.camera_true.fx_px, kExact * world.truth.camera_true.fx_px);
  // Dots in the reference camera frame: gauge-free.
  const int ref = obs.PosesWithRole(PoseRole::kIdentification).front();
  const Rigid3 model_ref_from_base = BaseFromCam(obs.robot, r.rho, obs.poses[ref].joints_rad).Inverse();
  const Rigid3 true_ref_from_base = world.truth.base_from_cam[ref].Inverse();
  double max_dot = 0;
  for (const auto& [id, p] : r.dots_in_base) {
    max_dot = std::max(max_dot, (model_ref_from_base * p - true_ref_from_base * world.truth.dots_in_base[id]).norm());
  }
  EXPECT_LT(max_dot, kExact);
  const testing::PoseErrors paper_e = VerificationPoseErrors(world, obs, paper.calibrated_robot, paper.calibrated_rho);
  std::cout << "[ figure ] noise 0, paper-pipeline start: verification pose error " << e.MaxPosition() << " m / "
            << e.MaxRotation() << " rad (paper pipeline alone: " << paper_e.MaxPosition() * 1e3 << " mm / "
            << paper_e.MaxRotation() << " rad), dots " << max_dot << " m, " << r.seconds * 1e3 << " ms\n";
}

// All dots on one plane: the factor method's 8-point estimate is degenerate there, the BA is not.
TEST(BundleAdjustment, FlatDotSheetConvergesFromTheNominalStart) {
  const sim::SimResult world = World(0.0, 5, 5);
  std::map<int, Eigen::Vector3d> flat;
  for (double noise : {0.0, 0.2}) {
    const ObservationSet obs = FlatSheet(world, noise, 9, &flat);
    const BundleReport r = RunBundleAdjustment(obs, KinematicParameters::Nominal(obs.robot), obs.camera.fx_px, {});
    ASSERT_EQ(r.outcome, Outcome::kConverged) << r.message;
    EXPECT_EQ(r.free_indices, world.truth.perturbed_indices);
    double max_z = 0, max_err = 0;
    int worst = -1;
    for (int i : r.free_indices) {
      const double error = std::abs(r.rho[i] - world.truth.rho_true[i]);
      max_err = std::max(max_err, error);
      if (error / r.stddev[i] > max_z) max_z = error / r.stddev[i], worst = i;
    }
    if (noise == 0) {
      EXPECT_LT(max_err, kExact);
      EXPECT_NEAR(r.fx_px, world.truth.camera_true.fx_px, kExact * world.truth.camera_true.fx_px);
      for (const auto& [id, p] : r.dots_in_base) EXPECT_LT((p - flat[id]).norm(), kExact) << id;
    } else {
      EXPECT_LT(max_z, 4.0) << KinematicParameters(6).name(worst);
      EXPECT_LT(std::abs(r.fx_px - world.truth.camera_true.fx_px), 4 * r.fx_stddev);
    }
    const testing::PoseErrors pose = VerificationPoseErrors(world, obs, obs.robot, r.rho);
    const calibration::PaperPipelineReport paper = calibration::RunPaperPipeline(obs, calibration::PaperPipelineOptions());
    std::cout << "[ figure ] flat sheet, noise " << noise << " px: BA " << OutcomeName(r.outcome) << ", "
              << r.num_observations << " observations, max parameter error " << max_err;
    if (noise > 0) std::cout << " (worst " << KinematicParameters(6).name(worst) << " at " << max_z << " sigma)";
    std::cout << ", f_x error " << std::abs(r.fx_px - world.truth.camera_true.fx_px) << " px, max verification pose error "
              << pose.MaxPosition() * 1e3 << " mm, " << r.seconds * 1e3 << " ms; paper pipeline: "
              << calibration::OutcomeName(paper.outcome);
    if (paper.calibrated_rho.size() == obs.robot.num_parameters()) {
      std::cout << ", verification pose error "
                << VerificationPoseErrors(world, obs, paper.calibrated_robot, paper.calibrated_rho).MaxPosition() * 1e3
                << " mm";
    } else {
      std::cout << " (" << paper.message.substr(0, 80) << ")";
    }
    std::cout << "\n";
  }
}

}  // namespace
}  // namespace selfcal::bundle
