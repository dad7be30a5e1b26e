// Compensation against a known calibrated arm: the compensated joints reach the targets on it to the solver's
// tolerance where the nominal joints miss by millimetres; a solution beyond the limits is named.
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "compensation/compensation.h"
#include "support/perturbed_model.h"
#include "support/test_robots.h"

namespace selfcal::compensation {
namespace {

using testing::Puma560;

RobotModel Calibrated(const RobotModel& nominal, std::uint64_t seed) {
  return testing::PerturbedModel(nominal, 1e-3, DegToRad(0.1), /*with_beta=*/true, seed);
}

Eigen::VectorXd RandomJoints(const RobotModel& model, std::mt19937_64* rng, double margin) {
  Eigen::VectorXd q(model.num_joints());
  for (int j = 0; j < q.size(); ++j) {
    q[j] = std::uniform_real_distribution<double>(model.limits[j].min_rad + margin, model.limits[j].max_rad - margin)(*rng);
  }
  return q;
}

TEST(Compensation, CompensatedJointsReachTheTargetsOnTheCalibratedArm) {
  const RobotModel nominal = Puma560();
  const RobotModel calibrated = Calibrated(nominal, 1);
  std::mt19937_64 rng(2);
  std::vector<Target> targets;
  const Eigen::VectorXd rho_nominal = KinematicParameters::Nominal(nominal);
  while (targets.size() < 20) {
    const Eigen::VectorXd q = RandomJoints(nominal, &rng, 0.3);
    // Away from the PUMA's singularities: the stretched elbow (q3 near -90 deg, where a target of the
    // nominal arm may lie beyond the calibrated arm's reach) and the wrist (q5 near 0).
    if (std::abs(q[2] + kPi / 2) < DegToRad(15) || std::abs(q[4]) < DegToRad(10)) continue;
    targets.push_back({BaseFromCam(nominal, rho_nominal, q), q});  // a pose the nominal model reaches at q
  }
  const CompensationReport report = Compensate(nominal, calibrated, TargetFrame::kCamera, targets);
  ASSERT_EQ(report.targets.size(), targets.size());
  EXPECT_TRUE(report.ok());
  const Eigen::VectorXd rho_cal = KinematicParameters::Nominal(calibrated);
  double missed_sq = 0;
  for (size_t k = 0; k < targets.size(); ++k) {
    const TargetSolution& s = report.targets[k];
    EXPECT_TRUE(s.nominal.converged) << k;
    EXPECT_LE((s.nominal.q - *targets[k].seed).norm(), 1e-8) << k;  // the nominal solution is the seed itself
    EXPECT_TRUE(s.compensated.converged) << k;
    // Checked independently of the solver's own measure.
    const PoseDifference reached = ComparePoses(targets[k].base_from_target, BaseFromCam(calibrated, rho_cal, s.compensated.q));
    EXPECT_LE(reached.position_m, 1e-9) << k;
    EXPECT_LE(reached.rotation_rad, 1e-9) << k;
    const PoseDifference missed = ComparePoses(targets[k].base_from_target, BaseFromCam(calibrated, rho_cal, s.nominal.q));
    missed_sq += missed.position_m * missed.position_m;
  }
  // The nominal joints on the calibrated arm miss by about the size of the perturbation (1 mm, 0.1 deg),
  // RMS over the targets (one target may be missed by less where errors cancel).
  EXPECT_GT(std::sqrt(missed_sq / static_cast<double>(targets.size())), 5e-4);
}

TEST(Compensation, FlangeTargetsWithoutSeedsStartFromThePreviousSolution) {
  const RobotModel nominal = Puma560();
  const RobotModel calibrated = Calibrated(nominal, 3);
  const Eigen::VectorXd rho_nominal = KinematicParameters::Nominal(nominal);
  Eigen::VectorXd q(6);
  q << 0.2, 0.5, -0.9, 0.3, 0.6, -0.4;
  std::vector<Target> targets = {{BaseFromFlange(nominal, rho_nominal, q), q}};
  for (int k = 1; k <= 5; ++k) {  // small steps from the first pose, no seeds
    targets.push_back({BaseFromFlange(nominal, rho_nominal, q + Eigen::VectorXd::Constant(6, 0.03 * k)), std::nullopt});
  }
  const CompensationReport report = Compensate(nominal, calibrated, TargetFrame::kFlange, targets);
  EXPECT_TRUE(report.ok());
  for (size_t k = 0; k < targets.size(); ++k) {
    EXPECT_LE((report.targets[k].nominal.q - (q + Eigen::VectorXd::Constant(6, 0.03 * k))).norm(), 1e-7) << k;
    EXPECT_LE(report.targets[k].compensated.position_residual_m, 1e-9) << k;
  }
}

TEST(Compensation, ASolutionBeyondTheLimitsIsNamed) {
  const RobotModel nominal = Puma560();
  const RobotModel calibrated = Calibrated(nominal, 4);
  Eigen::VectorXd q(6);
  q << 0.2, 0.5, -0.9, 0.3, nominal.limits[4].max_rad + 0.01, -0.4;  // joint 5 just past its maximum
  const Target target{BaseFromFlange(nominal, KinematicParameters::Nominal(nominal), q), q};
  const CompensationReport report = Compensate(nominal, calibrated, TargetFrame::kFlange, {target});
  ASSERT_EQ(report.targets.size(), 1u);
  EXPECT_TRUE(report.targets[0].compensated.converged);
  EXPECT_EQ(report.targets[0].joints_outside_limits, std::vector<int>{5});
  EXPECT_EQ(report.outside_limits, 1);
  EXPECT_FALSE(report.ok());
}

TEST(Compensation, AnUnreachableTargetDoesNotConverge) {
  const RobotModel nominal = Puma560();
  const Target far{Rigid3::FromTranslation(Eigen::Vector3d(5, 0, 0)), Eigen::VectorXd::Zero(6)};
  const CompensationReport report = Compensate(nominal, Calibrated(nominal, 5), TargetFrame::kFlange, {far});
  EXPECT_FALSE(report.targets[0].compensated.converged);
  EXPECT_GT(report.targets[0].compensated.position_residual_m, 3.0);  // the PUMA reaches under 1 m
  EXPECT_EQ(report.not_converged, 1);
}

}  // namespace
}  // namespace selfcal::compensation
