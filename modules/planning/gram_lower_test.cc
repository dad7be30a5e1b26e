#include "planning/gram_lower.h"

#include <cstring>
#include <random>

#include <Eigen/Core>
#include <gtest/gtest.h>

namespace selfcal::planning::internal {
namespace {

struct Case {
  Eigen::MatrixXd w;  // ld x cols, rows beyond `rows` zero
  Eigen::MatrixXd s;  // rows x rows
  int rows = 0;
};

Case MakeCase(int rows, int cols, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> gauss(0.0, 1.0);
  Case c;
  c.rows = rows;
  const int ld = (rows + 3) / 4 * 4;
  c.w = Eigen::MatrixXd::Zero(ld, cols);
  for (int k = 0; k < cols; ++k) {
    for (int r = 0; r < rows; ++r) c.w(r, k) = gauss(rng) * std::pow(10.0, (r + k) % 7 - 3);  // a spread of scales
  }
  c.s = Eigen::MatrixXd::NullaryExpr(rows, rows, [&]() { return gauss(rng); });
  return c;
}

// The portable path against Eigen's product: the lower triangle changed by sign w w^T, the upper untouched.
void ExpectAddsTheGramMatrix(double sign, int rows, int cols) {
  const Case c = MakeCase(rows, cols, 100 * rows + cols);
  Eigen::MatrixXd s = c.s;
  AddGramLowerPortable(sign, c.w.data(), static_cast<int>(c.w.rows()), rows, cols, s.data(), rows);
  const Eigen::MatrixXd top = c.w.topRows(rows);
  const Eigen::MatrixXd expected = c.s + sign * top * top.transpose();
  for (int j = 0; j < rows; ++j) {
    for (int i = 0; i < rows; ++i) {
      if (i < j) {
        EXPECT_EQ(s(i, j), c.s(i, j)) << rows << " x " << cols;
        continue;
      }
      // Sums of `cols` products of this size: round-off of a few ulps of the largest product.
      const double scale = top.row(i).cwiseAbs().dot(top.row(j).cwiseAbs()) + std::abs(c.s(i, j));
      EXPECT_NEAR(s(i, j), expected(i, j), 1e-14 * scale) << rows << " x " << cols << " at " << i << ", " << j;
    }
  }
}

TEST(GramLower, AddsTheLowerTriangleOfTheGramMatrixAndLeavesTheUpperAlone) {
  for (double sign : {1.0, -1.0}) {
    for (int rows : {1, 3, 4, 7, 8, 12, 25, 29}) {
      for (int cols : {0, 1, 3, 48, 234}) ExpectAddsTheGramMatrix(sign, rows, cols);
    }
  }
}

TEST(GramLower, AvxAndPortablePathsAgreeToTheBit) {
  int compared = 0;
  const double sign = -1.0;
  for (int rows : {1, 5, 8, 25, 29}) {
    for (int cols : {1, 48, 234}) {
      const Case c = MakeCase(rows, cols, 7 * rows + cols);
      Eigen::MatrixXd portable = c.s, avx = c.s;
      AddGramLowerPortable(sign, c.w.data(), static_cast<int>(c.w.rows()), rows, cols, portable.data(), rows);
      if (!AddGramLowerAvx(sign, c.w.data(), static_cast<int>(c.w.rows()), rows, cols, avx.data(), rows)) continue;
      ++compared;
      EXPECT_EQ(std::memcmp(portable.data(), avx.data(), sizeof(double) * rows * rows), 0) << rows << " x " << cols;
    }
  }
  if (compared == 0) GTEST_SKIP() << "this processor has no AVX: only the portable path runs here";
}

}  // namespace
}  // namespace selfcal::planning::internal
