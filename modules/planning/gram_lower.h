// The inner loop of the exchange designs (planning/fisher_design.h): the dots' part of the information is a
// rank update of a few hundred columns into a matrix of about 25 rows, which Eigen's blocked product spends
// most of its time packing for. Tiles of the result are summed over every column in registers instead, with
// AVX when the processor has it. Both paths do the same operations in the same order on every element (a
// multiply, then an add; no fused multiply-add), so their results are the same to the bit
// (gram_lower_test.cc).
#pragma once

namespace selfcal::planning::internal {

// Lower triangle of s += sign w w^T (sign +1 or -1). w: rows x cols, column-major with leading dimension ld
// (a multiple of 4; rows `rows` .. ld - 1 zero). s: rows x rows, column-major with leading dimension lds; its
// strict upper triangle is not touched.
void AddGramLower(double sign, const double* w, int ld, int rows, int cols, double* s, int lds);

// The two paths, for the test: the portable one (SSE2 on x86-64), and the AVX one, which returns false
// without doing anything when the processor has no AVX (or is not x86-64).
void AddGramLowerPortable(double sign, const double* w, int ld, int rows, int cols, double* s, int lds);
bool AddGramLowerAvx(double sign, const double* w, int ld, int rows, int cols, double* s, int lds);

}  // namespace selfcal::planning::internal
