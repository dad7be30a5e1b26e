#include <random>

#include <gtest/gtest.h>

#include "kinematics/autodiff_jacobian.h"
#include "kinematics/robot_model.h"
#include "support/test_robots.h"

namespace selfcal {
namespace {

using testing::Puma560;
using testing::RigidNear;
using testing::Ur5e;

// Plain standard-DH chain, written independently of the model's regrouping.
Rigid3 StandardDhChain(const std::vector<DhRow>& rows, const Eigen::VectorXd& q) {
  Rigid3 t;
  for (size_t i = 0; i < rows.size(); ++i) {
    t = t * Rigid3(RotZ(q[i] + rows[i].theta), Eigen::Vector3d::Zero()) *
        Rigid3(Eigen::Matrix3d::Identity(), Eigen::Vector3d(0, 0, rows[i].d)) *
        Rigid3(Eigen::Matrix3d::Identity(), Eigen::Vector3d(rows[i].a, 0, 0)) *
        Rigid3(RotX(rows[i].alpha), Eigen::Vector3d::Zero());
  }
  return t;
}

TEST(Kinematics, PumaZeroPoseMatchesCorke) {
  // Corke, p560.fkine(qz): translation (0.4521, -0.15005, 0.4318), identity rotation.
  const RobotModel puma = Puma560();
  const Eigen::VectorXd rho = KinematicParameters::Nominal(puma);
  const Rigid3 flange = BaseFromFlange(puma, rho, Eigen::VectorXd::Zero(6));
  EXPECT_TRUE(RigidNear(Rigid3(Eigen::Matrix3d::Identity(), Eigen::Vector3d(0.4521, -0.15005, 0.4318)), flange,
                        1e-15, 1e-15));
}

TEST(Kinematics, StandardDhRegroupingIsExact) {
  const double h = kPi / 2;
  const std::vector<DhRow> rows = {{0.0, h, 0.1625, 0.1}, {-0.425, 0.0, 0.0, -0.2}, {-0.3922, 0.0, 0.0, 0.0},
                                   {0.0, h, 0.1333, 0.3}, {0.0, -h, 0.0997, 0.0},   {0.01, 0.2, 0.0996, 0.0}};
  const RobotModel model = RobotModel::FromDh("t", DhConvention::kStandard, rows,
                                              std::vector<JointLimits>(6), Rigid3(), Rigid3());
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-3.0, 3.0);
  for (int k = 0; k < 50; ++k) {
    Eigen::VectorXd q(6);
    for (int i = 0; i < 6; ++i) q[i] = u(rng);
    EXPECT_TRUE(RigidNear(StandardDhChain(rows, q), BaseFromFlange(model, KinematicParameters::Nominal(model), q),
                          1e-14, 1e-14));
  }
}

TEST(Kinematics, ParameterNamesAndParallelAxes) {
  const RobotModel puma = Puma560();
  const KinematicParameters params(puma.num_joints());
  EXPECT_EQ(params.size(), 42);
  EXPECT_EQ(params.name(0), "base.tx");
  EXPECT_EQ(params.name(KinematicParameters::JointOffset(2) + 4), "j3.d");
  EXPECT_EQ(params.name(params.CamOffset() + 5), "cam.rz");
  EXPECT_EQ(params.IndexOf("j2.beta"), KinematicParameters::JointOffset(1) + 2);
  EXPECT_EQ(params.IndexOf("nope"), -1);
  EXPECT_EQ(ParallelAxisPairs(puma), (std::vector<int>{2}));     // joints 2-3
  EXPECT_EQ(ParallelAxisPairs(Ur5e()), (std::vector<int>{2, 3}));  // joints 2-3 and 3-4
}

TEST(Kinematics, AutodiffJacobianMatchesNumeric) {
  for (const RobotModel& model : {Puma560(), Ur5e()}) {
    std::mt19937 rng(3);
    std::normal_distribution<double> g(0.0, 0.01);
    Eigen::VectorXd rho = KinematicParameters::Nominal(model);
    for (int i = 0; i < rho.size(); ++i) rho[i] += g(rng);
    const Eigen::VectorXd q = (Eigen::VectorXd(6) << 0.3, -0.7, 0.9, 0.2, -0.5, 1.1).finished();
    // Output: camera position and the columns of the rotation, 12 numbers.
    auto fk = [&](const auto* x, auto* y) {
      using T = std::remove_const_t<std::remove_pointer_t<decltype(x)>>;
      std::vector<T> qt(6);
      for (int i = 0; i < 6; ++i) qt[i] = T(q[i]);
      const Rigid3T<T> pose = BaseFromCam<T>(model, x, qt.data());
      for (int k = 0; k < 3; ++k) y[k] = pose.translation[k];
      for (int k = 0; k < 9; ++k) y[3 + k] = pose.rotation(k % 3, k / 3);
    };
    const Eigen::MatrixXd analytic = AutodiffJacobian(fk, rho, 12);
    const Eigen::MatrixXd numeric = NumericJacobian(fk, rho, 12, 1e-6);
    EXPECT_LT((analytic - numeric).cwiseAbs().maxCoeff(), 1e-8) << model.name;
  }
}

TEST(Kinematics, ApplyParametersRoundTrip) {
  const RobotModel puma = Puma560();
  Eigen::VectorXd rho = KinematicParameters::Nominal(puma);
  std::mt19937 rng(5);
  std::normal_distribution<double> g(0.0, 0.01);
  for (int i = 0; i < rho.size(); ++i) rho[i] += g(rng);
  const RobotModel applied = ApplyParameters(puma, rho);
  const Eigen::VectorXd q = (Eigen::VectorXd(6) << 0.1, -0.4, 0.5, 0.7, -0.3, 0.2).finished();
  EXPECT_TRUE(RigidNear(BaseFromCam(puma, rho, q), BaseFromCam(applied, KinematicParameters::Nominal(applied), q),
                        1e-14, 1e-14));
}

TEST(Kinematics, InverseKinematicsReachesTarget) {
  const RobotModel puma = Puma560();
  const Eigen::VectorXd rho = KinematicParameters::Nominal(puma);
  const Eigen::VectorXd q_true = (Eigen::VectorXd(6) << 0.2, -0.6, -0.8, 0.3, -0.6, 0.4).finished();
  const Rigid3 target = BaseFromCam(puma, rho, q_true);
  Eigen::VectorXd seed = q_true + Eigen::VectorXd::Constant(6, 0.1);
  Eigen::VectorXd q;
  ASSERT_TRUE(SolveCameraIk(puma, rho, target, seed, &q));
  EXPECT_TRUE(RigidNear(target, BaseFromCam(puma, rho, q), 1e-10, 1e-10));
  EXPECT_TRUE(WithinLimits(puma, q));
}

}  // namespace
}  // namespace selfcal

namespace selfcal {
namespace {
TEST(Kinematics, ScaleLengthsScalesTranslationsOnly) {
  RobotModel puma = testing::Puma560();
  Eigen::VectorXd rho = KinematicParameters::Nominal(puma);
  rho[KinematicParameters(6).CamOffset()] = 0.01;
  const Eigen::VectorXd q = (Eigen::VectorXd(6) << 0.1, -0.4, 0.5, 0.7, -0.3, 0.2).finished();
  const Rigid3 before = BaseFromCam(puma, rho, q);
  ScaleLengths(1.25, &puma, &rho);
  const Rigid3 after = BaseFromCam(puma, rho, q);
  EXPECT_TRUE(testing::RigidNear(Rigid3(before.rotation, 1.25 * before.translation), after, 1e-14, 1e-14));
}
}  // namespace
}  // namespace selfcal
