// The held-out test's statistic r^T C^-1 r (heldout_reprojection.h) and, when parts of C are estimated
// variances, how much of C each part makes: an internal piece of heldout_reprojection.cc.
//
// A variance estimated from the fit's residuals (bundle/error_model.h) is itself uncertain, and a statistic
// normalised with it scatters more than chi-square. The pose error moves all of an image's dots together, so
// its part of C has a rank of at most 6 per image and its share of the statistic, s = tr(C^-1 C_pose), is a
// few tens of the statistic's degrees of freedom; but its size rests on a few tens of residual degrees of
// freedom (a joint reading error of 0.01 deg is known to 40 % in variance from 40 images), and where it was
// underestimated by half, that share counts double. With C = sigma^2 I + U U^T and M = U^T U + sigma^2 I,
// the share of U's columns c is tr(C^-1 U_c U_c^T) = sum over c of (1 - sigma^2 (M^-1)_cc); an image's
// pose-error columns are X R with Theta = R R^T, so component k's share is tr(E_k (I - sigma^2 (M^-1)_bb)),
// E_k = R^+ Theta_k R^+T. The test's distribution (ChiSquareQuantile) takes the pose part's share and the
// degrees of freedom of its size's estimate, 2 / (relative variance of the share-weighted components).
#pragma once

#include <array>
#include <vector>

#include <Eigen/Core>

namespace selfcal::calibration {

// One verification residual: detection - prediction, and its rows of U (C = sigma^2 I + U U^T, U in px):
// U = [G | D] with G (2 x theta) dense, its two rows at 2 k and 2 k + 1 of Residuals::g for residual k,
// and D zero except the 2 x 3 block of its dot.
struct Residual {
  int slot = -1;  // index into HeldOutReprojection::poses
  Eigen::Vector2d r = Eigen::Vector2d::Zero();
  Eigen::Matrix<double, 2, 3> d = Eigen::Matrix<double, 2, 3>::Zero();
  int dot = -1;                                // index of its dot's block
};
using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
struct Residuals {
  int num_theta = 0;
  std::vector<Residual> rows;
  std::vector<double> g;  // 2 x num_theta per residual, row by row
};

// One image's pose-error columns of U (6 from `column`) and E_k per component (translation, rotation, joint).
struct VarianceBlock {
  int column = 0;
  std::array<Eigen::Matrix<double, 6, 6>, 3> e;
};
struct VarianceParts {
  std::vector<VarianceBlock> blocks;
};

struct ChiSquare {
  double value = 0;                  // r^T C^-1 r
  std::array<double, 3> share{};     // tr(C^-1 C_k): translation, rotation, joint
};

// Over the residuals [begin, end) with `sigma` the pixel noise; parts: fill ChiSquare::share (null: not).
ChiSquare ChiSquareOf(int begin, int end, const Residuals& residuals, int num_dots, double sigma,
                      const VarianceParts* parts = nullptr);

// The degrees of freedom of an estimated variance whose relative variance is `relative_variance`
// (chi-square: 2 / dof), rounded, at least 1 and at most 1e8 (as good as known); 0 (known) when it is not
// positive.
int DegreesOfFreedomOf(double relative_variance);

// The degrees of freedom of the pose part's size: DegreesOfFreedomOf(s^T V s / (sum s)^2) over the
// components' shares s, V = relative_covariance's pose block (translation, rotation, joint); 0 (known) when
// V or s is zero.
int PoseNoiseDof(const ChiSquare& chi_square, const Eigen::Matrix4d& relative_covariance);

}  // namespace selfcal::calibration
