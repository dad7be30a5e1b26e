#include "identification/identification.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iostream>
#include <limits>
#include <random>

#include <gtest/gtest.h>

#include "identification/identifiability.h"
#include "identification/relative_pose_residual.h"
#include "identification/test_util.h"
#include "kinematics/autodiff_jacobian.h"
#include "support/test_robots.h"

namespace selfcal::identification {
namespace {

using selfcal::testing::Puma560;
using selfcal::testing::RigidNear;
using selfcal::testing::Ur5e;

// Kinematic errors of a real arm: lengths N(0, 1 mm), angles N(0, 0.2 deg), on the listed entries.
Eigen::VectorXd Perturb(const RobotModel& model, const std::vector<int>& indices, double factor, std::mt19937* rng) {
  const KinematicParameters params(model.num_joints());
  std::normal_distribution<double> g(0.0, 1.0);
  Eigen::VectorXd rho = KinematicParameters::Nominal(model);
  for (int i : indices) {
    rho[i] += factor * g(*rng) * (params.kind(i) == ParameterKind::kLength ? 1e-3 : DegToRad(0.2));
  }
  return rho;
}

std::vector<int> AllIndices(const RobotModel& model) {
  std::vector<int> all(model.num_parameters());
  for (int i = 0; i < model.num_parameters(); ++i) all[i] = i;
  return all;
}

std::vector<int> FreeSet(const RobotModel& model, const std::vector<Eigen::VectorXd>& poses) {
  return AnalyzeIdentifiability(model, KinematicParameters::Nominal(model), poses, 0, IdentifiabilityOptions())
      .free_indices;
}

// Predicted relative poses of the identified model against the truth at poses it has not seen.
void ExpectHeldOutPosesMatch(const RobotModel& model, const Eigen::VectorXd& truth, const Eigen::VectorXd& estimate,
                             unsigned seed, double tol) {
  std::mt19937 rng(seed);
  const auto held_out = testing::RandomPoses(model, 11, &rng);
  for (size_t i = 1; i < held_out.size(); ++i) {
    EXPECT_TRUE(RigidNear(testing::TrueRelativePose(model, truth, held_out[0], held_out[i]),
                          testing::TrueRelativePose(model, estimate, held_out[0], held_out[i]), tol, tol))
        << model.name << " held-out pose " << i;
  }
}

double MillisecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

void CheckExactRecovery(const RobotModel& model, unsigned seed) {
  std::mt19937 rng(seed);
  const auto poses = testing::RandomPoses(model, 15, &rng);
  const std::vector<int> free = FreeSet(model, poses);
  const Eigen::VectorXd truth = Perturb(model, free, 1.0, &rng);
  const auto measurements = testing::ExactMeasurements(model, truth, poses, 0);

  const auto start = std::chrono::steady_clock::now();
  const IdentificationReport report = IdentifyFromRelativePoses(model, KinematicParameters::Nominal(model), free, poses,
                                                                0, measurements, IdentificationOptions());
  const double ms = MillisecondsSince(start);
  std::cout << model.name << ": " << free.size() << " free parameters, " << measurements.size() << " measurements, "
            << report.iterations << " iterations, " << ms << " ms, " << report.termination << "\n";
  ASSERT_EQ(report.outcome, Outcome::kConverged) << report.message;
  EXPECT_LT(report.final_cost, 1e-16);
  EXPECT_GT(report.initial_cost, 1.0);
  const KinematicParameters params(model.num_joints());
  for (int i = 0; i < model.num_parameters(); ++i) {
    EXPECT_NEAR(report.rho[i], truth[i], 1e-9) << params.name(i);
  }
  EXPECT_LT(report.rms_position_m, 1e-9);
  EXPECT_LT(report.rms_rotation_rad, 1e-9);
  EXPECT_TRUE(report.covariance_available) << report.covariance_message;
  ExpectHeldOutPosesMatch(model, truth, report.rho, seed + 100, 1e-9);
}

// The solver's Jacobian (factor-wise derivatives) against the autodiff identification Jacobian at
// measurements equal to the model, and against central differences away from them.
TEST(Identification, SolverJacobianMatchesAutodiffAndNumeric) {
  for (const RobotModel& model : {Puma560(), Ur5e()}) {
    std::mt19937 rng(13);
    const Eigen::VectorXd rho = Perturb(model, AllIndices(model), 20.0, &rng);  // corrections away from zero
    const auto poses = testing::RandomPoses(model, 5, &rng);
    const int n = model.num_parameters(), reference = 1;
    const double sp = 1e-3, sr = 1e-4;
    const Eigen::MatrixXd autodiff = RelativePoseJacobian(model, rho, poses, reference, sp, sr);
    std::vector<int> all = AllIndices(model), some = {3, 8, 9, 20, 37, 41};
    int row = 0;
    for (int i = 0; i < static_cast<int>(poses.size()); ++i) {
      if (i == reference) continue;
      const Rigid3 exact = testing::TrueRelativePose(model, rho, poses[reference], poses[i]);
      Eigen::Matrix<double, 6, Eigen::Dynamic, Eigen::RowMajor> jac(6, n);
      Eigen::Matrix<double, 6, 1> r;
      ASSERT_TRUE(internal::EvaluateRelativePoseResidual(model, rho.data(), poses[reference], poses[i], exact, true,
                                                         1 / sp, 1 / sr, all, r.data(), jac.data()));
      EXPECT_LT(r.cwiseAbs().maxCoeff(), 1e-9);
      const Eigen::MatrixXd expected = autodiff.middleRows(row, 6);
      EXPECT_LT((jac - expected).cwiseAbs().maxCoeff(), 1e-10 * expected.cwiseAbs().maxCoeff()) << model.name;
      row += 6;

      // Away from the solution, rotation-only and translation rows, only some columns requested.
      const Rigid3 measured(exact.rotation * ExpSO3<double>(Eigen::Vector3d(0.2, -0.3, 0.1)),
                            exact.translation + Eigen::Vector3d(0.05, 0.02, -0.04));
      for (bool translation_valid : {true, false}) {
        const int m = translation_valid ? 6 : 3;
        Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> partial(m, n);
        Eigen::VectorXd value(m);
        ASSERT_TRUE(internal::EvaluateRelativePoseResidual(model, rho.data(), poses[reference], poses[i], measured,
                                                           translation_valid, 1 / sp, 1 / sr, some, value.data(),
                                                           partial.data()));
        auto f = [&](const double* x, double* y) {
          internal::EvaluateRelativePoseResidual(model, x, poses[reference], poses[i], measured, translation_valid,
                                                 1 / sp, 1 / sr, some, y, nullptr);
        };
        const Eigen::MatrixXd numeric = NumericJacobian(f, rho, m);
        for (int c = 0; c < n; ++c) {
          const bool requested = std::find(some.begin(), some.end(), c) != some.end();
          for (int k = 0; k < m; ++k) {
            EXPECT_NEAR(partial(k, c), requested ? numeric(k, c) : 0.0, 1e-7 * numeric.cwiseAbs().maxCoeff())
                << model.name << " row " << k << " column " << c;
          }
        }
      }
    }
  }
}

TEST(Identification, ExactRecoveryPuma560) { CheckExactRecovery(Puma560(), 21); }

TEST(Identification, ExactRecoveryUr5e) { CheckExactRecovery(Ur5e(), 22); }

TEST(Identification, GaugeInvarianceWithErrorsOnEveryParameter) {
  for (const RobotModel& model : {Puma560(), Ur5e()}) {
    std::mt19937 rng(31);
    const auto poses = testing::RandomPoses(model, 15, &rng);
    const std::vector<int> free = FreeSet(model, poses);
    const Eigen::VectorXd truth = Perturb(model, AllIndices(model), 1.0, &rng);
    const IdentificationReport report =
        IdentifyFromRelativePoses(model, KinematicParameters::Nominal(model), free, poses, 0,
                                  testing::ExactMeasurements(model, truth, poses, 0), IdentificationOptions());
    ASSERT_EQ(report.outcome, Outcome::kConverged) << report.message;
    EXPECT_LT(report.final_cost, 1e-16) << model.name;
    // The unidentifiable directions are a gauge: individual parameters differ from the truth (the base
    // correction stays at zero, the truth's is not) but every relative pose is reproduced.
    const int base_tx = KinematicParameters(model.num_joints()).IndexOf("base.tx");
    EXPECT_EQ(report.rho[base_tx], 0.0);
    EXPECT_GT(std::abs(truth[base_tx]), 1e-6);
    EXPECT_GT((report.rho - truth).cwiseAbs().maxCoeff(), 1e-4);
    ExpectHeldOutPosesMatch(model, truth, report.rho, 131, 1e-9);
  }
}

TEST(Identification, RotationOnlyMeasurementsStillRecover) {
  const RobotModel model = Puma560();
  std::mt19937 rng(41);
  const auto poses = testing::RandomPoses(model, 20, &rng);
  const std::vector<int> free = FreeSet(model, poses);
  const Eigen::VectorXd truth = Perturb(model, free, 1.0, &rng);
  auto measurements = testing::ExactMeasurements(model, truth, poses, 0);
  for (size_t k = 0; k < measurements.size(); k += 3) {
    measurements[k].translation_valid = false;
    measurements[k].cam_ref_from_cam_i.translation = Eigen::Vector3d(7, 7, 7);  // must be ignored
  }
  const IdentificationReport report = IdentifyFromRelativePoses(model, KinematicParameters::Nominal(model), free, poses,
                                                                0, measurements, IdentificationOptions());
  ASSERT_EQ(report.outcome, Outcome::kConverged) << report.message;
  for (int i : free) EXPECT_NEAR(report.rho[i], truth[i], 1e-9) << i;
}

TEST(Identification, NoisyErrorsAgreeWithReportedStddev) {
  // Measurement noise at the sigmas; over seeded trials the parameter errors must fall within 2 reported
  // sigma about 95% of the time (pooled over all free parameters).
  const RobotModel model = Puma560();
  const IdentificationOptions options;
  std::mt19937 rng(51);
  const auto poses = testing::RandomPoses(model, 15, &rng);
  const std::vector<int> free = FreeSet(model, poses);
  std::normal_distribution<double> g(0.0, 1.0);
  int inside = 0, total = 0;
  double chi2 = 0;
  const int kTrials = 100;
  for (int trial = 0; trial < kTrials; ++trial) {
    const Eigen::VectorXd truth = Perturb(model, free, 1.0, &rng);
    auto measurements = testing::ExactMeasurements(model, truth, poses, 0);
    for (RelativePoseMeasurement& m : measurements) {
      const Eigen::Vector3d w(g(rng), g(rng), g(rng));
      const Eigen::Vector3d t(g(rng), g(rng), g(rng));
      m.cam_ref_from_cam_i.rotation = m.cam_ref_from_cam_i.rotation * ExpSO3<double>(options.sigma_rotation_rad * w);
      m.cam_ref_from_cam_i.translation += options.sigma_position_m * t;
    }
    const IdentificationReport report =
        IdentifyFromRelativePoses(model, KinematicParameters::Nominal(model), free, poses, 0, measurements, options);
    ASSERT_EQ(report.outcome, Outcome::kConverged) << report.message;
    ASSERT_TRUE(report.covariance_available) << report.covariance_message;
    EXPECT_LT(report.rms_position_m, 3 * options.sigma_position_m);
    chi2 += 2 * report.final_cost;
    for (int i : free) {
      ASSERT_TRUE(std::isfinite(report.stddev[i]));
      inside += std::abs(report.rho[i] - truth[i]) < 2 * report.stddev[i] ? 1 : 0;
      ++total;
    }
  }
  const double fraction = static_cast<double>(inside) / total;
  std::cout << "fraction of |error| < 2 sigma: " << fraction << " over " << total << "\n";
  EXPECT_GT(fraction, 0.9);
  EXPECT_LT(fraction, 0.99);
  // The weighted residual sum is chi-square with (84 - free) degrees of freedom per trial.
  const double dof = 6.0 * 14 - static_cast<double>(free.size());
  EXPECT_NEAR(chi2 / (kTrials * dof), 1.0, 0.1);
}

TEST(Identification, NonFiniteMeasurementFailsNamingThePose) {  // K5
  const RobotModel model = Puma560();
  std::mt19937 rng(61);
  const auto poses = testing::RandomPoses(model, 8, &rng);
  auto measurements = testing::ExactMeasurements(model, KinematicParameters::Nominal(model), poses, 0);
  measurements[3].cam_ref_from_cam_i.translation.y() = std::numeric_limits<double>::quiet_NaN();
  const IdentificationReport report =
      IdentifyFromRelativePoses(model, KinematicParameters::Nominal(model), FreeSet(model, poses), poses, 0,
                                measurements, IdentificationOptions());
  std::cout << report.message << "\n";
  EXPECT_EQ(report.outcome, Outcome::kFailure);
  EXPECT_NE(report.message.find("pose 4"), std::string::npos) << report.message;
  EXPECT_FALSE(report.covariance_available);
}

TEST(Identification, RankDeficientFreeSetReportsNoUncertainty) {  // K1, K8
  const RobotModel model = Puma560();
  std::mt19937 rng(71);
  const auto poses = testing::RandomPoses(model, 15, &rng);
  std::vector<int> free = FreeSet(model, poses);
  const KinematicParameters params(model.num_joints());
  free.push_back(params.IndexOf("base.tx"));
  free.push_back(params.IndexOf("j3.d"));  // with j2.d: one more exact null direction
  const Eigen::VectorXd truth = Perturb(model, FreeSet(model, poses), 1.0, &rng);
  auto measurements = testing::ExactMeasurements(model, truth, poses, 0);
  std::normal_distribution<double> g(0.0, 1e-4);
  for (RelativePoseMeasurement& m : measurements) m.cam_ref_from_cam_i.translation.x() += g(rng);
  const IdentificationReport report = IdentifyFromRelativePoses(model, KinematicParameters::Nominal(model), free, poses,
                                                                0, measurements, IdentificationOptions());
  std::cout << report.covariance_message << "\n";
  EXPECT_NE(report.outcome, Outcome::kFailure) << report.message;
  EXPECT_FALSE(report.covariance_available);
  EXPECT_NE(report.covariance_message.find("rank deficient"), std::string::npos) << report.covariance_message;
  EXPECT_NE(report.covariance_message.find("base.tx"), std::string::npos) << report.covariance_message;
  EXPECT_NE(report.covariance_message.find("j3.d"), std::string::npos) << report.covariance_message;
  EXPECT_EQ(report.covariance_message.find("j3.a"), std::string::npos) << report.covariance_message;
  for (int i = 0; i < report.stddev.size(); ++i) EXPECT_TRUE(std::isnan(report.stddev[i]));
}

TEST(Identification, OneIterationFromFarIsNotConverged) {  // K4
  const RobotModel model = Ur5e();
  std::mt19937 rng(81);
  const auto poses = testing::RandomPoses(model, 15, &rng);
  const std::vector<int> free = FreeSet(model, poses);
  const Eigen::VectorXd truth = Perturb(model, free, 50.0, &rng);  // 5 cm, 10 deg
  IdentificationOptions options;
  options.max_iterations = 1;
  const IdentificationReport report =
      IdentifyFromRelativePoses(model, KinematicParameters::Nominal(model), free, poses, 0,
                                testing::ExactMeasurements(model, truth, poses, 0), options);
  std::cout << report.termination << "\n";
  EXPECT_EQ(report.outcome, Outcome::kNoConvergence) << report.termination;
  EXPECT_STREQ(OutcomeName(report.outcome), "unconverged");
  EXPECT_LT(report.final_cost, report.initial_cost);
}

TEST(Identification, InvalidInputIsReportedNotThrown) {
  const RobotModel model = Puma560();
  std::mt19937 rng(91);
  const auto poses = testing::RandomPoses(model, 5, &rng);
  auto measurements = testing::ExactMeasurements(model, KinematicParameters::Nominal(model), poses, 0);
  measurements[0].pose_index = 17;
  IdentificationOptions options;
  options.sigma_position_m = -1;
  const IdentificationReport report =
      IdentifyFromRelativePoses(model, KinematicParameters::Nominal(model), {8, 9}, poses, 0, measurements, options);
  EXPECT_EQ(report.outcome, Outcome::kInvalidInput);
  EXPECT_NE(report.message.find("sigma_position_m"), std::string::npos) << report.message;
  EXPECT_NE(report.message.find("pose index 17"), std::string::npos) << report.message;
}

}  // namespace
}  // namespace selfcal::identification
