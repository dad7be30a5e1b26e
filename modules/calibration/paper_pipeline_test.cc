#include "calibration/paper_pipeline.h"

#include <gtest/gtest.h>

#include "identification/identification.h"
#include "sim/sim_world.h"
#include "sim/trajectory_generator.h"
#include "support/sim_worlds.h"
#include "support/test_robots.h"

namespace selfcal::calibration {
namespace {

sim::SimResult World(double noise_px, uint64_t seed = 1) { return testing::PumaArcWorld(noise_px, seed, seed); }

// Noise-free: the factor method is exact, and the only error left in the measured relative poses is the
// bias of eq. (21) (nominal position ratios standing in for the true ones), which we can predict exactly.
TEST(PaperPipeline, NoiseFreeTwoViewIsExactAndPositionErrorIsTheEq21Bias) {
  const sim::SimResult world = World(0.0);
  const PaperPipelineReport report = RunPaperPipeline(world.observations, PaperPipelineOptions());
  ASSERT_EQ(report.outcome, Outcome::kSuccess) << report.message;
  ASSERT_EQ(report.measurements.size(), 14u);
  const Rigid3 ref_from_base = world.truth.base_from_cam[report.reference_pose].Inverse();
  const double fx_true = world.truth.camera_true.fx_px;
  double first_true_norm = 0, first_nominal_norm = 0;
  double max_bias_m = 0;
  int fx_pairs = 0;
  for (const PoseMeasurement& m : report.measurements) {
    ASSERT_TRUE(m.used) << m.pose_id << ": " << m.two_view.message;
    const Rigid3 truth = ref_from_base * world.truth.base_from_cam[m.pose_index];
    EXPECT_LT(RotationAngle(m.measured_cam_ref_from_cam.rotation.transpose() * truth.rotation), 1e-9) << m.pose_id;
    const Eigen::Vector3d direction = m.measured_cam_ref_from_cam.translation.normalized();
    EXPECT_LT((direction - truth.translation.normalized()).norm(), 1e-9) << m.pose_id;
    // Exact either from this pair or, where its optical axes nearly intersect, from the other pairs.
    EXPECT_LT(std::abs(m.two_view.fx_px - fx_true), 1e-9 * fx_true) << m.pose_id;
    EXPECT_NE(m.two_view.fx_observable, m.fx_from_other_pairs) << m.pose_id;
    if (m.two_view.fx_observable) ++fx_pairs;
    if (first_true_norm == 0) {
      first_true_norm = truth.translation.norm();
      first_nominal_norm = m.nominal_translation.norm();
    }
    // With k_1 from the true first motion, eq. (21) predicts ||t_i|| * (nominal ratio / true ratio).
    const double predicted_norm = m.nominal_translation.norm() / first_nominal_norm * first_true_norm;
    const Eigen::Vector3d t_meas = (first_true_norm / first_nominal_norm) * m.measured_cam_ref_from_cam.translation;
    EXPECT_NEAR(t_meas.norm(), predicted_norm, 1e-12);
    EXPECT_NEAR((t_meas - truth.translation).norm(), std::abs(predicted_norm - truth.translation.norm()), 1e-9);
    max_bias_m = std::max(max_bias_m, (t_meas - truth.translation).norm());
  }
  EXPECT_GE(fx_pairs, 3);
  EXPECT_NEAR(report.fx_px, fx_true, 1e-9 * fx_true);
  // The nominal model is wrong by about a millimetre per link: the bias is there and measurable.
  EXPECT_GT(max_bias_m, 1e-5);
  std::cout << "[ figure ] eq. (21) bias on the arc trajectory, noise 0: max position error " << max_bias_m * 1e3
            << " mm\n";
}

TEST(PaperPipeline, CalibrationBeatsTheNominalModelOnHeldOutDistancesWithoutNoise) {
  const sim::SimResult world = World(0.0);
  const PaperPipelineReport report = RunPaperPipeline(world.observations, PaperPipelineOptions());
  ASSERT_EQ(report.outcome, Outcome::kSuccess) << report.message;
  ASSERT_EQ(report.verification_calibrated.num_ok, 40);
  std::cout << "[ figure ] 3-D error, noise 0: nominal " << report.verification_nominal.rms_error_m * 1e3
            << " mm RMS, calibrated " << report.verification_calibrated.rms_error_m * 1e3 << " mm RMS\n";
  EXPECT_LT(report.verification_calibrated.rms_error_m, report.verification_nominal.rms_error_m);
}

TEST(PaperPipeline, InvalidInputNamesThePose) {
  sim::SimResult world = World(0.2);
  world.observations.poses[3].dots_px[5] = Eigen::Vector2d(std::nan(""), 1.0);
  const PaperPipelineReport report = RunPaperPipeline(world.observations, PaperPipelineOptions());
  EXPECT_EQ(report.outcome, Outcome::kInvalidInput);
  EXPECT_NE(report.message.find("pose p03, dot 5"), std::string::npos) << report.message;
}

TEST(PaperPipeline, TooFewPosesIsDegenerate) {
  sim::SimResult world = World(0.2);
  world.observations.poses.resize(4);  // 4 identification poses: 3 measurements < 6
  const PaperPipelineReport report = RunPaperPipeline(world.observations, PaperPipelineOptions());
  EXPECT_EQ(report.outcome, Outcome::kDegenerate) << report.message;
}

TEST(PaperPipeline, YardstickSeenOnceLeavesScaleUnresolved) {
  sim::SimResult world = World(0.2);
  // S1: keep yardstick end 1 in a single identification view (and in the verification views).
  for (int i = 1; i < 15; ++i) world.observations.poses[i].dots_px.erase(1);
  const PaperPipelineReport report = RunPaperPipeline(world.observations, PaperPipelineOptions());
  EXPECT_EQ(report.outcome, Outcome::kScaleUnresolved) << report.message;
  EXPECT_FALSE(report.yardstick.ok);
}

// Identification from exact metric relative poses, then the section 4.1 step 5 verification: with the
// truth's f_x and noise-free pixels the held-out 3-D error vanishes.
TEST(PaperPipeline, ExactMetricRelativePosesGiveZeroThreeDError) {
  const sim::SimResult world = World(0.0);
  const ObservationSet& obs = world.observations;
  const std::vector<int> id_poses = obs.PosesWithRole(PoseRole::kIdentification);
  std::vector<Eigen::VectorXd> joints;
  std::vector<identification::RelativePoseMeasurement> measurements;
  for (int i : id_poses) {
    joints.push_back(obs.poses[i].joints_rad);
    if (i == id_poses.front()) continue;
    measurements.push_back({static_cast<int>(joints.size()) - 1,
                            world.truth.base_from_cam[id_poses.front()].Inverse() * world.truth.base_from_cam[i], true});
  }
  const Eigen::VectorXd rho0 = KinematicParameters::Nominal(obs.robot);
  const auto free = identification::AnalyzeIdentifiability(obs.robot, rho0, joints, 0, {}).free_indices;
  const identification::IdentificationReport id = identification::IdentifyFromRelativePoses(
      obs.robot, rho0, free, joints, 0, measurements, identification::IdentificationOptions());
  ASSERT_EQ(id.outcome, identification::Outcome::kConverged) << id.message;
  for (int i : free) EXPECT_NEAR(id.rho[i], world.truth.rho_true[i], 1e-9) << KinematicParameters(6).name(i);
  const RobotModel calibrated = ApplyParameters(obs.robot, id.rho);
  const VerificationSummary v =
      VerifyDistances(obs, obs.PosesWithRole(PoseRole::kVerification), calibrated,
                      KinematicParameters::Nominal(calibrated), world.truth.camera_true.fx_px, obs.check_distances);
  ASSERT_EQ(v.num_ok, 40);
  EXPECT_LT(v.max_error_m, 1e-9);  // below 1e-6 mm
  std::cout << "[ figure ] exact metric relative poses: max 3-D error " << v.max_error_m * 1e3 << " mm\n";
}

TEST(PaperPipeline, ClusteredPosesAreRefusedAsInsufficientExcitation) {
  sim::SimResult world = World(0.2);
  // K3: every identification pose within half a degree of the first one.
  for (int i = 1; i < 15; ++i) {
    world.observations.poses[i].joints_rad =
        world.observations.poses[0].joints_rad + Eigen::VectorXd::Constant(6, DegToRad(0.03 * i));
  }
  const PaperPipelineReport report = RunPaperPipeline(world.observations, PaperPipelineOptions());
  EXPECT_EQ(report.outcome, Outcome::kDegenerate);
  EXPECT_NE(report.message.find("insufficient excitation"), std::string::npos) << report.message;
  EXPECT_TRUE(report.measurements.empty());  // refused before any image was used
}

}  // namespace
}  // namespace selfcal::calibration
