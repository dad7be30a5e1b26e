// The inner loops of the exchange designs (planning/fisher_design.h), with AVX when the processor has it:
// - AddGramLower: the dots' part of the information is a rank update of a few hundred columns into a matrix
//   of about 25 rows, which Eigen's blocked product spends most of its time packing for; tiles of the result
//   are summed over every column in registers instead.
// - MarginalColumns: a candidate's two columns of that update per dot.
// Both paths do the same operations in the same order on every element (a multiply, then an add; no fused
// multiply-add), so their results are the same to the bit (exchange_kernels_test.cc).
#pragma once

namespace selfcal::planning::internal {

// Lower triangle of s += sign w w^T (sign +1 or -1). w: rows x cols, column-major with leading dimension ld
// (a multiple of 4; rows `rows` .. ld - 1 zero). s: rows x rows, column-major with leading dimension lds; its
// strict upper triangle is not touched.
void AddGramLower(double sign, const double* w, int ld, int rows, int cols, double* s, int lds);

// One dot seen by a candidate pose: f, its two pixel rows' derivatives with respect to the pose's 7 camera
// directions (twist in the camera frame and f_x), b with respect to the dot, (l00, l10, l11) the Cholesky
// factor L of I + b k b^T (k: the inverse of the rest's information on the dot), p: the rest's k h_gj^T as 3
// columns of n, and where the two columns go.
struct MarginalDot {
  double f[2][7];
  double b[2][3];
  double l00, l10, l11;
  const double* p;
  double* w0;
  double* w1;
};
// For each dot: a = f zt^T (two n-vectors; zt: n x 7, column-major), then (w0, w1) = L^-1 (a - b p).
void MarginalColumns(const MarginalDot* dots, int count, const double* zt, int n);

// The two paths of each, for the test: the portable one (SSE2 on x86-64), and the AVX one, which returns
// false without doing anything when the processor has no AVX (or is not x86-64).
void AddGramLowerPortable(double sign, const double* w, int ld, int rows, int cols, double* s, int lds);
bool AddGramLowerAvx(double sign, const double* w, int ld, int rows, int cols, double* s, int lds);
void MarginalColumnsPortable(const MarginalDot* dots, int count, const double* zt, int n);
bool MarginalColumnsAvx(const MarginalDot* dots, int count, const double* zt, int n);

}  // namespace selfcal::planning::internal
