// AnalyticEpipolarCost against automatic differentiation of EpipolarCost, the definition of eq. (13)'s
// residuals: same residuals and the same Jacobian to round-off, inside and beyond the Huber threshold.
#include "twoview/epipolar_cost.h"

#include <cmath>
#include <cstdio>
#include <memory>
#include <random>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <ceres/autodiff_cost_function.h>
#include <gtest/gtest.h>

namespace selfcal::twoview::internal {
namespace {

using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

struct Evaluation {
  Eigen::VectorXd residuals;
  RowMajor jacobian;  // columns: 1/f_x, q (x, y, z, w), t
};

Evaluation Evaluate(const ceres::CostFunction& cost, double s, const Eigen::Vector4d& q, const Eigen::Vector3d& t) {
  const int n = cost.num_residuals();
  Evaluation out;
  out.residuals.resize(n);
  RowMajor j0(n, 1), j1(n, 4), j2(n, 3);
  const double* parameters[3] = {&s, q.data(), t.data()};
  double* jacobians[3] = {j0.data(), j1.data(), j2.data()};
  EXPECT_TRUE(cost.Evaluate(parameters, out.residuals.data(), jacobians));
  out.jacobian.resize(n, 8);
  out.jacobian << j0, j1, j2;
  // Residuals alone must not need the Jacobian's storage.
  Eigen::VectorXd alone(n);
  EXPECT_TRUE(cost.Evaluate(parameters, alone.data(), nullptr));
  // (Automatic differentiation evaluates plain doubles and Jets differently: equal to round-off.)
  EXPECT_LE((alone - out.residuals).cwiseAbs().maxCoeff(), 1e-13 * out.residuals.cwiseAbs().maxCoeff());
  return out;
}

// Correspondences of a random scene seen by two cameras f = 1/s apart by (R, t): most with sub-pixel
// noise, every fifth moved by up to 30 px so that it lies beyond the Huber threshold.
Correspondences RandomScene(std::mt19937* rng, double s, const Eigen::Matrix3d& r, const Eigen::Vector3d& t, double mu,
                            int n) {
  std::uniform_real_distribution<double> unit(-1, 1);
  std::normal_distribution<double> noise(0, 0.5);
  Correspondences data;
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d p1(0.3 * unit(*rng), 0.3 * unit(*rng), 1.0 + 0.3 * unit(*rng));
    const Eigen::Vector3d p2 = r * p1 + t;
    // Centred coordinates: (u - c_x, (v - c_y) / mu) = f (x / z, y / z).
    Eigen::Vector2d m1 = p1.head<2>() / (p1.z() * s), m2 = p2.head<2>() / (p2.z() * s);
    const double outlier = i % 5 == 0 ? 30.0 : 0.0;
    m1 += Eigen::Vector2d(noise(*rng), noise(*rng) / mu);
    m2 += Eigen::Vector2d(noise(*rng) + outlier * unit(*rng), (noise(*rng) + outlier * unit(*rng)) / mu);
    data.centred1.push_back(m1);
    data.centred2.push_back(m2);
    data.pixels1.push_back(m1);
    data.pixels2.push_back(m2);
  }
  return data;
}

TEST(EpipolarCostTest, AnalyticJacobianMatchesAutodiff) {
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> unit(-1, 1);
  int beyond_huber = 0, within_huber = 0;
  for (int trial = 0; trial < 20; ++trial) {
    const double s = 1.0 / (600 + 400 * (unit(rng) + 1));
    const double mu = 1 + 0.05 * unit(rng);
    const double huber_px = 2.0;
    const Eigen::Vector3d axis = Eigen::Vector3d(unit(rng), unit(rng), unit(rng)).normalized();
    const Eigen::Matrix3d r = Eigen::AngleAxisd(0.3 * unit(rng), axis).toRotationMatrix();
    const Eigen::Vector3d t(0.2 * unit(rng), 0.2 * unit(rng), 0.1 * unit(rng));
    const Correspondences data = RandomScene(&rng, s, r, t, mu, 40);
    std::vector<int> indices(40);
    for (int i = 0; i < 40; ++i) indices[i] = i;
    // Evaluate away from the truth and with an unnormalised quaternion, as LM's trial steps do.
    Eigen::Quaterniond q(r);
    Eigen::Vector4d qc = q.coeffs() * (1 + 0.1 * unit(rng));
    qc += 2e-4 * Eigen::Vector4d(unit(rng), unit(rng), unit(rng), unit(rng));
    const Eigen::Vector3d tc = t.normalized() + 2e-3 * Eigen::Vector3d(unit(rng), unit(rng), unit(rng));
    const double sc = s * (1 + 0.01 * unit(rng));

    const AnalyticEpipolarCost analytic(data, indices, mu, huber_px);
    auto* functor = new EpipolarCost(data, indices, mu, huber_px);
    const ceres::AutoDiffCostFunction<EpipolarCost, ceres::DYNAMIC, 1, 4, 3> autodiff(functor,
                                                                                      functor->num_residuals());
    ASSERT_EQ(analytic.num_residuals(), autodiff.num_residuals());
    ASSERT_EQ(analytic.parameter_block_sizes(), autodiff.parameter_block_sizes());
    const Evaluation a = Evaluate(analytic, sc, qc, tc);
    const Evaluation b = Evaluate(autodiff, sc, qc, tc);
    for (int k = 0; k < 40; ++k) {
      const double sum_sq = a.residuals.segment<2>(2 * k).squaredNorm();
      // rho(S) = 2 a sqrt(S) - a^2 >= a^2 beyond the threshold, S itself below it.
      (sum_sq > huber_px * huber_px * (1 + 1e-9) ? beyond_huber : within_huber) += 1;
    }
    const double residual_scale = b.residuals.cwiseAbs().maxCoeff();
    EXPECT_LE((a.residuals - b.residuals).cwiseAbs().maxCoeff(), 1e-13 * residual_scale) << "trial " << trial;
    for (int c = 0; c < 8; ++c) {
      const double column_scale = b.jacobian.col(c).cwiseAbs().maxCoeff();
      ASSERT_GT(column_scale, 0);
      const double error = (a.jacobian.col(c) - b.jacobian.col(c)).cwiseAbs().maxCoeff();
      EXPECT_LE(error, 1e-12 * column_scale) << "trial " << trial << " column " << c;
    }
  }
  std::printf("%d correspondences beyond the Huber threshold, %d within\n", beyond_huber, within_huber);
  EXPECT_GT(beyond_huber, 100);
  EXPECT_GT(within_huber, 100);
}

TEST(EpipolarCostTest, PartialJacobiansAndEpipole) {
  std::mt19937 rng(4);
  const double s = 1.0 / 900;
  const Eigen::Matrix3d r = Eigen::AngleAxisd(0.1, Eigen::Vector3d::UnitY()).toRotationMatrix();
  const Eigen::Vector3d t(0.2, 0.01, 0.05);
  Correspondences data = RandomScene(&rng, s, r, t, 1.0, 10);
  std::vector<int> indices(10);
  for (int i = 0; i < 10; ++i) indices[i] = i;
  const Eigen::Vector4d qc = Eigen::Quaterniond(r).coeffs();
  const AnalyticEpipolarCost cost(data, indices, 1.0, 2.0);
  const Evaluation full = Evaluate(cost, s, qc, t);
  // 1/f_x held constant: Ceres passes no storage for its block; the others are unchanged.
  Eigen::VectorXd residuals(20);
  RowMajor j1(20, 4), j2(20, 3);
  const double* parameters[3] = {&s, qc.data(), t.data()};
  double* jacobians[3] = {nullptr, j1.data(), j2.data()};
  ASSERT_TRUE(cost.Evaluate(parameters, residuals.data(), jacobians));
  EXPECT_EQ(j1, full.jacobian.middleCols(1, 4));
  EXPECT_EQ(j2, full.jacobian.rightCols(3));
  // Forward motion: the epipoles are the principal points, and a correspondence there has no epipolar
  // line; the evaluation fails as the automatic one does.
  const double forward_t[3] = {0, 0, 1};
  const double identity_q[4] = {0, 0, 0, 1};
  const double* forward[3] = {&s, identity_q, forward_t};
  data.centred1[3] = Eigen::Vector2d::Zero();
  const AnalyticEpipolarCost at_epipole(data, indices, 1.0, 2.0);
  EXPECT_FALSE(at_epipole.Evaluate(forward, residuals.data(), nullptr));
  auto* functor = new EpipolarCost(data, indices, 1.0, 2.0);
  const ceres::AutoDiffCostFunction<EpipolarCost, ceres::DYNAMIC, 1, 4, 3> autodiff(functor, 20);
  EXPECT_FALSE(autodiff.Evaluate(forward, residuals.data(), nullptr));
}

}  // namespace
}  // namespace selfcal::twoview::internal
