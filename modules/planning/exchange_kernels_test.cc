#include "planning/exchange_kernels.h"

#include <cstring>
#include <random>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Dense>
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

// Dots with random rows, factors and rest columns; the columns written into w (n x 2 per dot).
struct MarginalCase {
  Eigen::MatrixXd zt, p, w;
  std::vector<MarginalDot> dots;
};

MarginalCase MakeMarginalCase(int n, int count, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> gauss(0.0, 1.0);
  MarginalCase c;
  c.zt = Eigen::MatrixXd::NullaryExpr(n, 7, [&]() { return gauss(rng); });
  c.p = Eigen::MatrixXd::NullaryExpr(n, 3 * count, [&]() { return gauss(rng); });
  c.w = Eigen::MatrixXd::Zero(n, 2 * count);
  for (int i = 0; i < count; ++i) {
    MarginalDot d;
    for (int r = 0; r < 2; ++r) {
      for (int m = 0; m < 7; ++m) d.f[r][m] = 100 * gauss(rng);
      for (int m = 0; m < 3; ++m) d.b[r][m] = 1000 * gauss(rng);
    }
    d.l00 = 1 + std::abs(gauss(rng));
    d.l10 = gauss(rng);
    d.l11 = 1 + std::abs(gauss(rng));
    d.p = c.p.col(3 * i).data();
    d.w0 = c.w.col(2 * i).data();
    d.w1 = c.w.col(2 * i + 1).data();
    c.dots.push_back(d);
  }
  return c;
}

TEST(MarginalColumns, AreTheFactorsInverseTimesTheRowsLessTheRestsPart) {
  for (int n : {1, 3, 4, 25, 29}) {
    MarginalCase c = MakeMarginalCase(n, 5, 31 * n);
    MarginalColumnsPortable(c.dots.data(), 5, c.zt.data(), n);
    for (int i = 0; i < 5; ++i) {
      const MarginalDot& d = c.dots[i];
      const Eigen::Matrix<double, 2, 7> f = Eigen::Map<const Eigen::Matrix<double, 2, 7, Eigen::RowMajor>>(&d.f[0][0]);
      const Eigen::Matrix<double, 2, 3> b = Eigen::Map<const Eigen::Matrix<double, 2, 3, Eigen::RowMajor>>(&d.b[0][0]);
      const Eigen::MatrixXd atilde = f * c.zt.transpose() - b * c.p.middleCols(3 * i, 3).transpose();
      Eigen::Matrix2d l;
      l << d.l00, 0, d.l10, d.l11;
      const Eigen::MatrixXd expected = l.triangularView<Eigen::Lower>().solve(atilde);
      for (int r = 0; r < n; ++r) {
        for (int k = 0; k < 2; ++k) {
          const double scale = (f.row(k).cwiseAbs() * c.zt.row(r).transpose().cwiseAbs()).sum() +
                               (b.row(k).cwiseAbs() * c.p.middleCols(3 * i, 3).row(r).transpose().cwiseAbs()).sum();
          EXPECT_NEAR(c.w(r, 2 * i + k), expected(k, r), 1e-14 * scale) << n << " " << i << " " << r << " " << k;
        }
      }
    }
  }
}

TEST(MarginalColumns, AvxAndPortablePathsAgreeToTheBit) {
  int compared = 0;
  for (int n : {1, 5, 8, 25, 29}) {
    MarginalCase portable = MakeMarginalCase(n, 7, 17 * n), avx = MakeMarginalCase(n, 7, 17 * n);
    MarginalColumnsPortable(portable.dots.data(), 7, portable.zt.data(), n);
    if (!MarginalColumnsAvx(avx.dots.data(), 7, avx.zt.data(), n)) continue;
    ++compared;
    EXPECT_EQ(std::memcmp(portable.w.data(), avx.w.data(), sizeof(double) * portable.w.size()), 0) << n;
  }
  if (compared == 0) GTEST_SKIP() << "this processor has no AVX: only the portable path runs here";
}

}  // namespace
}  // namespace selfcal::planning::internal
