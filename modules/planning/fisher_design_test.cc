// The Fisher design's information (planning/fisher_design.h) against its definition computed the slow way:
// every pixel's derivatives by central differences of the pinhole projection through the whole model, the
// dense information of (free rho, f_x, every dot) with the yardstick term, inverted.
#include <algorithm>
#include <cmath>
#include <iostream>
#include <vector>

#include <Eigen/Cholesky>
#include <gtest/gtest.h>

#include "planning/fisher_design.h"
#include "planning/planning_test_util.h"

namespace selfcal::planning {
namespace {

using testing::FreeColumns;
using testing::MakeWorld;
using testing::World;

struct DenseReference {
  double log_det = 0;          // of the (free rho, f_x) information, as FisherValue::log_det
  Eigen::VectorXd stddev;      // as FisherValue::stddev
};

// The pinhole pixel of dot x at joints q for kinematic parameters rho and focal length fx (k1 not modelled,
// as in the design).
Eigen::Vector2d Pixel(const PlanningProblem& problem, const Eigen::VectorXd& rho, double fx, const Eigen::Vector3d& x,
                      const Eigen::VectorXd& q) {
  const Eigen::Vector3d p = BaseFromCam(problem.robot, rho, q).Inverse() * x;
  const CameraIntrinsics& cam = problem.camera;
  return {cam.cx_px + fx * p.x() / p.z(), cam.cy_px + fx * cam.mu * p.y() / p.z()};
}

DenseReference Dense(const PlanningProblem& problem, const std::vector<int>& free, const std::vector<Eigen::VectorXd>& poses,
                     const FisherDesignOptions& options) {
  const int nf = static_cast<int>(free.size()), g = nf + 1;
  const std::vector<Eigen::Vector3d>& dots = problem.scene.dots_in_base;
  const int cols = g + 3 * static_cast<int>(dots.size());
  const Eigen::VectorXd rho = KinematicParameters::Nominal(problem.robot);
  const double fx = problem.camera.fx_px;
  Eigen::MatrixXd h = Eigen::MatrixXd::Zero(cols, cols);
  for (const Eigen::VectorXd& q : poses) {
    for (size_t j = 0; j < dots.size(); ++j) {
      const Eigen::Vector2d uv = Pixel(problem, rho, fx, dots[j], q);
      EXPECT_TRUE(uv.x() >= 0 && uv.y() >= 0 && uv.x() <= problem.camera.width_px - 1 &&
                  uv.y() <= problem.camera.height_px - 1);  // every dot seen: the design counts them all
      Eigen::MatrixXd a = Eigen::MatrixXd::Zero(2, cols);
      const double step = 1e-6;  // m, rad and px
      for (int c = 0; c < nf; ++c) {
        Eigen::VectorXd plus = rho, minus = rho;
        plus[free[c]] += step;
        minus[free[c]] -= step;
        a.col(c) = (Pixel(problem, plus, fx, dots[j], q) - Pixel(problem, minus, fx, dots[j], q)) / (2 * step);
      }
      a.col(nf) = (Pixel(problem, rho, fx + step, dots[j], q) - Pixel(problem, rho, fx - step, dots[j], q)) / (2 * step);
      for (int k = 0; k < 3; ++k) {
        const Eigen::Vector3d e = Eigen::Vector3d::Unit(k) * step;
        a.col(g + 3 * static_cast<int>(j) + k) =
            (Pixel(problem, rho, fx, dots[j] + e, q) - Pixel(problem, rho, fx, dots[j] - e, q)) / (2 * step);
      }
      h += a.transpose() * a;
    }
  }
  // The yardstick between dots 0 and 1, weighted as one pixel residual of noise sigma_px.
  Eigen::VectorXd y = Eigen::VectorXd::Zero(cols);
  const Eigen::Vector3d d = (dots[0] - dots[1]).normalized();
  y.segment<3>(g) = d;
  y.segment<3>(g + 3) = -d;
  const double w = options.pixel_noise_px / options.yardstick_sigma_m;
  h += (w * w) * y * y.transpose();
  // (free rho, f_x) covariance in pixel-noise units: the top-left block of h^-1.
  const Eigen::MatrixXd block = h.ldlt().solve(Eigen::MatrixXd::Identity(cols, cols)).topLeftCorner(g, g);
  const double sigma2 = options.pixel_noise_px * options.pixel_noise_px;
  DenseReference out;
  const Eigen::LLT<Eigen::MatrixXd> llt(block);
  out.log_det = -2.0 * llt.matrixL().toDenseMatrix().diagonal().array().log().sum() - g * std::log(sigma2);
  out.stddev = (sigma2 * block.diagonal()).cwiseSqrt();
  return out;
}

TEST(FisherDesign, InformationEqualsTheDenseDefinitionByCentralDifferences) {
  const World w = MakeWorld();
  const std::vector<int> free = FreeColumns(w);
  const FisherDesignOptions options;
  FisherDesign design(w.problem, free, options);
  std::vector<int> all;
  for (int i = 0; i < 15; ++i) all.push_back(design.AddCandidate(w.start[i]));
  const DenseReference reference = Dense(w.problem, free, testing::Head(w.start, 15), options);
  const FisherValue v = design.Evaluate(all);
  ASSERT_TRUE(v.ok);
  // Central differences at a 1e-6 step agree with the design to about 6e-8 (log det) and 5e-8 (relative
  // std); a wrong term (a dot, the yardstick, one parameter's derivative) moves them by far more.
  ASSERT_EQ(v.stddev.size(), reference.stddev.size());
  std::cout << "[ figures  ] log det " << v.log_det << ", dense " << reference.log_det << "; largest relative std difference "
            << (v.stddev - reference.stddev).cwiseQuotient(reference.stddev).cwiseAbs().maxCoeff() << "\n";
  EXPECT_NEAR(v.log_det, reference.log_det, 1e-6);
  for (int k = 0; k < v.stddev.size(); ++k) EXPECT_NEAR(v.stddev[k], reference.stddev[k], 1e-6 * reference.stddev[k]) << k;
  // The exchange's unit: every pose but one summed, the one added back, gives the same design.
  for (int skip : {0, 7, 14}) {
    const FisherValue again = design.EvaluateSums(design.Sum(all, skip), all[skip], true);
    ASSERT_TRUE(again.ok);
    EXPECT_NEAR(again.log_det, v.log_det, 1e-9 * std::abs(v.log_det)) << skip;
    EXPECT_NEAR(again.a_value, v.a_value, 1e-9 * v.a_value) << skip;
    const FisherValue log_det_only = design.EvaluateSums(design.Sum(all, skip), all[skip], false);
    EXPECT_EQ(log_det_only.log_det, again.log_det) << skip;
  }
}

TEST(FisherDesign, TheExchangesRankTwoUpdateEqualsEliminatingEveryDotAgain) {
  const World w = MakeWorld();
  const std::vector<int> free = FreeColumns(w);
  FisherDesign design(w.problem, free, FisherDesignOptions());
  std::vector<int> all;
  for (int i = 0; i < 15; ++i) all.push_back(design.AddCandidate(w.start[i]));
  std::vector<int> others;  // the verification poses as candidates from outside the design
  for (int i = 15; i < 25; ++i) others.push_back(design.AddCandidate(w.start[i]));
  double largest = 0;
  for (int skip : {1, 7, 14}) {
    const FisherDesign::Rest rest = design.PrepareRest(design.Sum(all, skip));
    ASSERT_TRUE(rest.every_dot_determined) << skip;  // every dot is seen from the other 14 poses
    for (int extra : {all[skip], others[0], others[4], others[9]}) {
      const FisherValue direct = design.EvaluateSums(rest.sums, extra, true);
      const FisherValue fast = design.EvaluateWithRest(rest, extra, true);
      ASSERT_TRUE(direct.ok && fast.ok) << skip << " " << extra;
      EXPECT_NEAR(fast.log_det, direct.log_det, 1e-11 * std::abs(direct.log_det)) << skip << " " << extra;
      EXPECT_NEAR(fast.a_value, direct.a_value, 1e-9 * direct.a_value) << skip << " " << extra;
      for (int k = 0; k < direct.stddev.size(); ++k) {
        EXPECT_NEAR(fast.stddev[k], direct.stddev[k], 1e-9 * direct.stddev[k]) << skip << " " << extra << " " << k;
      }
      largest = std::max(largest, std::abs(fast.a_value / direct.a_value - 1));
      EXPECT_EQ(design.EvaluateWithRest(rest, extra, false).log_det, fast.log_det);
    }
  }
  std::cout << "[ figures  ] largest relative difference of A between the two evaluations " << largest << "\n";
  // A rest of one pose determines no dot: the candidate is evaluated with every dot eliminated again.
  const FisherDesign::Rest one = design.PrepareRest(design.Sum({all[0], all[1]}, 1));
  EXPECT_FALSE(one.every_dot_determined);
  const FisherValue two = design.EvaluateWithRest(one, all[1], true);
  const FisherValue expected = design.Evaluate({all[0], all[1]});
  ASSERT_EQ(two.ok, expected.ok);
  EXPECT_EQ(two.log_det, expected.log_det);  // the same evaluation
}

}  // namespace
}  // namespace selfcal::planning
